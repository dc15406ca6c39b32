"""DQN learner of the adversarial agents: SB3 DQN plus double, dueling and prioritized replay.

Build a model from hyper-parameters and an env::

    from sumo_ayss.agents import AyssDQN, DQNHyperParams

    model = AyssDQN(env, DQNHyperParams(gamma=0.8), seed=0)
    model.learn(total_timesteps=100_000)
    model.save("run/model.zip")
    model = AyssDQN.load("run/model.zip", env=env)
"""

from sumo_ayss.agents.dqn import AyssDQN
from sumo_ayss.agents.hparams import DQNHyperParams
from sumo_ayss.agents.policies import AyssDQNPolicy, DuelingQNetwork
from sumo_ayss.agents.replay import (
    PrioritizedReplayBuffer,
    PrioritizedReplayBufferSamples,
    SumTree,
)

__all__ = [
    "AyssDQN",
    "AyssDQNPolicy",
    "DQNHyperParams",
    "DuelingQNetwork",
    "PrioritizedReplayBuffer",
    "PrioritizedReplayBufferSamples",
    "SumTree",
]
