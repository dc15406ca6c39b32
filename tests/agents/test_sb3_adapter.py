"""The SB3 internals of :mod:`sumo_ayss.agents.sb3_adapter` behave as the adapter assumes.

Each test drives the installed stable-baselines3 through one adapter function and checks the
effect SB3 has on its replay buffer or counters, so an SB3 upgrade that changes one of them
fails here, by name, rather than as an inexact resume far away.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import stable_baselines3
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.env_util import make_vec_env
from stable_baselines3.common.logger import Logger

from sumo_ayss.agents import AyssDQN, DQNHyperParams
from sumo_ayss.agents import sb3_adapter as sb3
from tests.agents.test_dqn import TINY, TinyEnv


class _AtStep(BaseCallback):
    """Runs ``action(locals)`` once, at the ``at``-th collected step (1-based)."""

    def __init__(self, at: int, action: Any) -> None:
        super().__init__()
        self.at, self.action, self.seen = at, action, 0

    def _on_step(self) -> bool:
        self.seen += 1
        if self.seen == self.at:
            self.action(self.locals)
        return True


def _model(n_envs: int = 2) -> AyssDQN:
    env = make_vec_env(TinyEnv, n_envs=n_envs, seed=0)
    hp = DQNHyperParams(**{**TINY, "learning_starts": 1000, "prioritized": False})
    return AyssDQN(env, hp, seed=0)


def test_written_against_the_installed_major_version() -> None:
    assert stable_baselines3.__version__.split(".")[:1] == sb3.SB3_VERSION.split(".")[:1]


def test_set_rollout_start_is_the_next_stored_observation() -> None:
    model = _model()
    model.learn(total_timesteps=4)  # set up: the envs are running
    row = model.replay_buffer.pos
    start = np.array([[3.5], [0.25]], dtype=np.float32)
    sb3.set_rollout_start(model, start, np.ones((2,), dtype=bool))
    model.learn(total_timesteps=2, reset_num_timesteps=False)
    np.testing.assert_array_equal(model.replay_buffer.observations[row], start)


def test_rollout_locals_and_truncation_reach_the_buffer() -> None:
    model = _model()
    fresh = np.array([[1.5], [2.5]], dtype=np.float32)
    seen: dict[str, Any] = {}

    def cut(rollout: dict[str, Any]) -> None:
        seen["actions"] = np.array(sb3.rollout_actions(rollout))
        seen["ended"] = sb3.rollout_episode_ended(rollout, 0)
        seen["last"] = rollout["new_obs"].copy()
        sb3.truncate_rollout_step(rollout, fresh)

    model.learn(total_timesteps=6, callback=_AtStep(2, cut))
    buffer = model.replay_buffer
    assert seen["actions"].shape == (2,) and seen["ended"] is False
    np.testing.assert_array_equal(buffer.actions[1, :, 0], seen["actions"])
    assert buffer.dones[1].all() and buffer.timeouts[1].all()  # truncations, bootstrapped
    np.testing.assert_array_equal(buffer.next_observations[1], seen["last"])
    np.testing.assert_array_equal(buffer.observations[2], fresh)  # SB3 continued from it


def test_progress_learning_rate_and_update_count() -> None:
    model = _model(1)
    model.learn(total_timesteps=8)
    assert sb3.progress_remaining(model) == 0.0  # the learn call has ended
    assert sb3.vec_normalize_env(model) is None
    model.set_logger(Logger(folder=None, output_formats=[]))
    optimizer = model.policy.optimizer
    optimizer.param_groups[0]["lr"] = 123.0
    sb3.update_learning_rate(model, optimizer)
    assert optimizer.param_groups[0]["lr"] == TINY["learning_rate"]
    before = model._n_updates
    assert sb3.add_gradient_updates(model, 3) == before + 3 == model._n_updates
