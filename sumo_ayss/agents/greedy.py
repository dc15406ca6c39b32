"""Greedy (argmax-Q) policy of a trained model, batched, for evaluation and Monte Carlo."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import numpy.typing as npt
import torch as th
from stable_baselines3.common.torch_layers import FlattenExtractor
from torch import nn

from sumo_ayss.agents.dqn import AyssDQN
from sumo_ayss.agents.policies import DuelingQNetwork

#: One MLP layer on the host: ``(weight (out, in), bias (out,))`` of a ``Linear``, or None
#: for a ``ReLU``. The arrays are views of the layer's parameters (``Tensor.numpy()`` shares
#: the memory), so in-place updates of the network (an optimizer step) are seen.
_Layer = tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]] | None

HOST_MAX_BATCH = 4
"""The most observations per call that the NumPy forward takes (an episode's one at a time);
a larger batch (a vec env's evaluation, Monte Carlo) runs through torch, as fast from 8
observations on (0.22 ms each at 8, one thread; ``benchmarks/greedy_forward.py``)."""


class GreedyPolicy:
    """``obs (N, d) float32 -> actions (N,) int64``: argmax of the online Q network.

    One batched forward pass per call, without SB3's ``predict`` bookkeeping, so a Monte
    Carlo stage can evaluate many thousands of observations at once. Observations in and
    actions out are numpy arrays on the host.

    On the CPU, a network of :class:`~sumo_ayss.agents.policies.DuelingQNetwork`'s usual
    layout (flattened observations, ``Linear``/``ReLU`` MLPs, float32) runs in NumPy on views
    of its weights for up to :data:`HOST_MAX_BATCH` observations: an episode asks for one at
    a time, and there torch's per-operator overhead makes a forward 0.14-0.22 ms against
    NumPy's 0.06-0.11 ms (one thread, 256-wide layers; ``benchmarks/greedy_forward.py``),
    which halved a cross-play cell (1.8 s -> 0.95 s, 200 episodes). The result is the same
    function of the weights in float32; the last bit of a Q-value may differ from torch's
    (another summation order), which decides an argmax only on an exact near-tie. Any other
    network, or one on a GPU, runs through torch.
    """

    def __init__(self, model: AyssDQN) -> None:
        self.q_net = model.q_net
        self.q_net.set_training_mode(False)
        self.device = model.device
        self._host = _host_layers(self.q_net) if self.device.type == "cpu" else None

    @classmethod
    def load(cls, path: str | Path) -> GreedyPolicy:
        return cls(AyssDQN.load(str(path), device="cpu"))

    def q_values(self, obs: npt.NDArray[np.float32]) -> npt.NDArray[np.float32]:
        x = np.asarray(obs, dtype=np.float32)
        if self._host is not None and x.shape[0] <= HOST_MAX_BATCH:
            return _host_q(self._host, x.reshape(x.shape[0], -1))
        with th.no_grad():
            obs_t = th.as_tensor(x, device=self.device)
            q: npt.NDArray[np.float32] = self.q_net(obs_t).cpu().numpy()
            return q

    def __call__(self, obs: npt.NDArray[np.float32]) -> npt.NDArray[np.int64]:
        actions: npt.NDArray[np.int64] = self.q_values(obs).argmax(axis=1).astype(np.int64)
        return actions


#: ``(feature net, value net or None, advantage net or Q head)`` on the host.
_HostNet = tuple[list[_Layer], list[_Layer] | None, list[_Layer]]


def _host_layers(q_net: object) -> _HostNet | None:
    """The network as host layers, or None when it is not of the layout the NumPy forward
    computes (then torch runs it)."""
    if not isinstance(q_net, DuelingQNetwork) or type(q_net.features_extractor) is not (
        FlattenExtractor
    ):
        return None
    if any(p.dtype != th.float32 or p.device.type != "cpu" for p in q_net.parameters()):
        return None
    feature = _mlp_layers(q_net.feature_net)
    head = _mlp_layers(q_net.advantage_net if q_net.dueling else q_net.q_head)
    value = _mlp_layers(q_net.value_net) if q_net.dueling else None
    if feature is None or head is None or (q_net.dueling and value is None):
        return None
    return feature, value, head


def _mlp_layers(mlp: nn.Sequential) -> list[_Layer] | None:
    layers: list[_Layer] = []
    for layer in mlp:
        if type(layer) is nn.Linear:
            w, b = layer.weight.detach().numpy(), layer.bias
            if b is None:
                return None
            layers.append((w, b.detach().numpy()))
        elif type(layer) is nn.ReLU:
            layers.append(None)
        else:
            return None
    return layers


def _run(layers: Sequence[_Layer], x: npt.NDArray[np.float32]) -> npt.NDArray[np.float32]:
    for layer in layers:
        if layer is None:
            x = np.maximum(x, np.float32(0.0))
        else:
            w, b = layer
            x = x @ w.T + b
    return x


def _host_q(net: _HostNet, x: npt.NDArray[np.float32]) -> npt.NDArray[np.float32]:
    feature, value, head = net
    hidden = _run(feature, x)
    out = _run(head, hidden)
    if value is None:
        return out
    v = _run(value, hidden)
    q: npt.NDArray[np.float32] = v + out - out.mean(axis=1, keepdims=True, dtype=np.float32)
    return q
