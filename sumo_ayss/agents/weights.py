"""Load a saved policy's weights without unpickling anything (the run-folder trust model).

SB3's ``DQN.load`` unpickles parts of a ``.zip`` (its ``data`` entry holds cloudpickled
objects), so opening someone else's ``spcp.zip`` with it could run their code. Here only the
zip's ``policy.pth`` is read, with ``torch.load(weights_only=True)`` (tensors and plain
containers only), and the Q-network is rebuilt from the run's own ``config.yaml`` settings
(:class:`~sumo_ayss.agents.hparams.DQNHyperParams`) and the case's spaces.
"""

from __future__ import annotations

import io
import zipfile
from dataclasses import dataclass
from pathlib import Path
from types import SimpleNamespace
from typing import Any, Protocol

import gymnasium as gym
import torch as th
from gymnasium import spaces
from stable_baselines3.common.torch_layers import FlattenExtractor

from sumo_ayss.agents.greedy import GreedyPolicy
from sumo_ayss.agents.hparams import DQNHyperParams
from sumo_ayss.agents.policies import DuelingQNetwork
from sumo_ayss.util.errors import CheckpointError

#: The state dict entry of SB3's saved zip, and the online network's prefix in it.
POLICY_ENTRY = "policy.pth"
_ONLINE_PREFIX = "q_net."


def read_policy_state(path: str | Path) -> dict[str, th.Tensor]:
    """The policy's state dict from an SB3 ``.zip`` (``policy.pth``), tensors only.

    Raises:
        CheckpointError: The file is missing, not a zip, has no ``policy.pth``, or that
            entry is not a plain state dict of tensors.
    """
    path = Path(path)
    try:
        with zipfile.ZipFile(path) as archive:
            raw = archive.read(POLICY_ENTRY)
    except FileNotFoundError:
        raise CheckpointError(f"{path}: file not found") from None
    except (zipfile.BadZipFile, KeyError, OSError, EOFError) as e:
        raise CheckpointError(
            f"{path}: not a saved policy (an SB3 .zip with {POLICY_ENTRY}): {e}"
        ) from e
    try:
        state = th.load(io.BytesIO(raw), map_location="cpu", weights_only=True)
    except Exception as e:  # torch raises several types on corrupt or unsafe data
        raise CheckpointError(
            f"{path}: {POLICY_ENTRY} is not a plain tensor state dict ({type(e).__name__}: "
            f"{str(e).splitlines()[0] if str(e) else ''})"
        ) from e
    if not isinstance(state, dict) or not all(isinstance(v, th.Tensor) for v in state.values()):
        raise CheckpointError(f"{path}: {POLICY_ENTRY} is not a state dict of tensors")
    return state


def load_greedy_policy(
    path: str | Path,
    hparams: DQNHyperParams,
    observation_space: spaces.Box,
    action_space: spaces.Discrete,
) -> GreedyPolicy:
    """The greedy policy of the online Q-network saved in ``path``, without unpickling.

    Args:
        path: An ``spcp.zip`` or candidate ``model.zip`` written by training.
        hparams: The run's learner settings (network layout: arch widths, dueling).
        observation_space: The case's observation space (its size sets the input layer).
        action_space: The case's action space.

    Raises:
        CheckpointError: The file cannot be read or its weights do not fit the layout.
    """
    state = read_policy_state(path)
    online = {k[len(_ONLINE_PREFIX) :]: v for k, v in state.items() if k.startswith(_ONLINE_PREFIX)}
    extractor = FlattenExtractor(observation_space)
    net = DuelingQNetwork(
        observation_space,
        action_space,
        features_extractor=extractor,
        features_dim=extractor.features_dim,
        feature_net_arch=hparams.feature_net_arch,
        value_net_arch=hparams.value_net_arch,
        advantage_net_arch=hparams.advantage_net_arch,
        dueling=hparams.dueling,
    )
    try:
        net.load_state_dict(online, strict=True)
    except RuntimeError as e:
        raise CheckpointError(
            f"{path}: weights do not fit the run's network (agent.*_net_arch, agent.dueling "
            f"in config.yaml): {str(e).splitlines()[0]}"
        ) from e
    return GreedyPolicy(SimpleNamespace(q_net=net, device=th.device("cpu")))  # type: ignore[arg-type]


class _SpcpFiles(Protocol):
    @property
    def spcp_zip(self) -> Path: ...


class _LearnerSettings(Protocol):
    @property
    def agent(self) -> DQNHyperParams: ...


class SpcpRun(Protocol):
    """What loading a run's SPCP asks of the run (a :class:`~sumo_ayss.run_folder.RunRecord`:
    its folder, the ``spcp.zip`` in it and the learner settings of its ``config.yaml``)."""

    @property
    def path(self) -> Path: ...

    @property
    def folder(self) -> _SpcpFiles: ...

    @property
    def experiment(self) -> _LearnerSettings: ...


def load_spcp(run: SpcpRun, env: gym.Env[Any, Any]) -> GreedyPolicy:
    """The run's SPCP as a greedy policy, its weights read without unpickling (trust model).

    Args:
        run: The run whose ``spcp.zip`` is loaded.
        env: An env of the run's case (its spaces set the network's input and output).

    Raises:
        CheckpointError: If the run has no ``spcp.zip`` or no readable ``config.yaml``.
    """
    path = run.folder.spcp_zip
    if not path.is_file():
        raise CheckpointError(f"{run.path}: no {path.name} (was the SPCP selected?)")
    return load_greedy_policy(
        path,
        run.experiment.agent,
        env.observation_space,  # type: ignore[arg-type]
        env.action_space,  # type: ignore[arg-type]
    )


@dataclass(frozen=True)
class SpcpFile:
    """A run's SPCP as what loading it needs (:func:`load_spcp` without the run's record):
    small and picklable, so that a worker process loads it (cross-play's cells on the worker
    pool, :mod:`sumo_ayss.grid.cells`). Called with an env, it returns the greedy policy.

    Attributes:
        run_path: The run folder (named in the error of a missing SPCP).
        spcp_zip: Its ``spcp.zip``.
        agent: The run's learner settings (its ``config.yaml``).
    """

    run_path: Path
    spcp_zip: Path
    agent: DQNHyperParams

    @classmethod
    def of(cls, run: SpcpRun) -> SpcpFile:
        """The SPCP of ``run`` (reads the run's learner settings now)."""
        return cls(run.path, run.folder.spcp_zip, run.experiment.agent)

    def __call__(self, env: gym.Env[Any, Any]) -> GreedyPolicy:
        """The greedy policy, as :func:`load_spcp` gives it.

        Raises:
            CheckpointError: If the ``spcp.zip`` is missing or unreadable.
        """
        if not self.spcp_zip.is_file():
            raise CheckpointError(
                f"{self.run_path}: no {self.spcp_zip.name} (was the SPCP selected?)"
            )
        return load_greedy_policy(
            self.spcp_zip,
            self.agent,
            env.observation_space,  # type: ignore[arg-type]
            env.action_space,  # type: ignore[arg-type]
        )
