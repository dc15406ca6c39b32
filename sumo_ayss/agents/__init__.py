"""DQN learner of the adversarial agents: SB3 DQN plus double, dueling and prioritized replay.

Build a model from hyper-parameters and an env::

    from sumo_ayss.agents import AyssDQN, DQNHyperParams

    model = AyssDQN(env, DQNHyperParams(gamma=0.8), seed=0)
    model.learn(total_timesteps=100_000)
    model.save("run/model.zip")
    model = AyssDQN.load("run/model.zip", env=env)

The names load lazily (PEP 562): importing :mod:`sumo_ayss.agents.hparams` (configuration
does) imports neither torch nor stable-baselines3.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from sumo_ayss.agents.dqn import AyssDQN
    from sumo_ayss.agents.hparams import DQNHyperParams
    from sumo_ayss.agents.policies import AyssDQNPolicy, DuelingQNetwork
    from sumo_ayss.agents.replay import (
        PrioritizedReplayBuffer,
        PrioritizedReplayBufferSamples,
        SumTree,
    )

_LAZY = {
    "AyssDQN": "sumo_ayss.agents.dqn",
    "AyssDQNPolicy": "sumo_ayss.agents.policies",
    "DQNHyperParams": "sumo_ayss.agents.hparams",
    "DuelingQNetwork": "sumo_ayss.agents.policies",
    "PrioritizedReplayBuffer": "sumo_ayss.agents.replay",
    "PrioritizedReplayBufferSamples": "sumo_ayss.agents.replay",
    "SumTree": "sumo_ayss.agents.replay",
}

__all__ = [
    "AyssDQN",
    "AyssDQNPolicy",
    "DQNHyperParams",
    "DuelingQNetwork",
    "PrioritizedReplayBuffer",
    "PrioritizedReplayBufferSamples",
    "SumTree",
]


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
