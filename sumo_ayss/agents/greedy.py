"""Greedy (argmax-Q) policy of a trained model, batched, for evaluation and Monte Carlo."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import numpy.typing as npt
import torch as th

from sumo_ayss.agents.dqn import AyssDQN


class GreedyPolicy:
    """``obs (N, d) float32 -> actions (N,) int64``: argmax of the online Q network.

    One batched forward pass per call, without SB3's ``predict`` bookkeeping, so a Monte
    Carlo stage can evaluate many thousands of observations at once. Runs on the model's
    device (observations in and actions out are numpy arrays on the host).
    """

    def __init__(self, model: AyssDQN) -> None:
        self.q_net = model.q_net
        self.q_net.set_training_mode(False)
        self.device = model.device

    @classmethod
    def load(cls, path: str | Path) -> GreedyPolicy:
        return cls(AyssDQN.load(str(path), device="cpu"))

    def q_values(self, obs: npt.NDArray[np.float32]) -> npt.NDArray[np.float32]:
        with th.no_grad():
            obs_t = th.as_tensor(np.asarray(obs, dtype=np.float32), device=self.device)
            q: npt.NDArray[np.float32] = self.q_net(obs_t).cpu().numpy()
            return q

    def __call__(self, obs: npt.NDArray[np.float32]) -> npt.NDArray[np.int64]:
        actions: npt.NDArray[np.int64] = self.q_values(obs).argmax(axis=1).astype(np.int64)
        return actions
