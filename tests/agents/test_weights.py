"""Weights-only loading of a saved policy equals SB3's full (unpickling) load."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from sumo_ayss.agents.dqn import AyssDQN
from sumo_ayss.agents.greedy import GreedyPolicy
from sumo_ayss.agents.hparams import DQNHyperParams
from sumo_ayss.agents.weights import load_greedy_policy
from sumo_ayss.envs.cut_in import CutInEnv
from sumo_ayss.util.errors import CheckpointError


@pytest.mark.parametrize("dueling", [True, False], ids=["dueling", "plain"])
def test_weights_only_policy_equals_the_sb3_loaded_one(tmp_path: Path, dueling: bool) -> None:
    hp = DQNHyperParams(
        feature_net_arch=(16,), value_net_arch=(8,), advantage_net_arch=(8, 8), dueling=dueling
    )
    env = CutInEnv()  # spaces only: SUMO never starts
    model = AyssDQN(env, hp, seed=3)
    model.save(tmp_path / "model.zip")
    obs = np.random.default_rng(0).uniform(0, 30, size=(64, 4)).astype(np.float32)
    full = GreedyPolicy.load(tmp_path / "model.zip")
    safe = load_greedy_policy(tmp_path / "model.zip", hp, env.observation_space, env.action_space)
    np.testing.assert_array_equal(safe.q_values(obs), full.q_values(obs))
    np.testing.assert_array_equal(safe(obs), full(obs))
    other = DQNHyperParams(feature_net_arch=(32,), dueling=dueling)
    with pytest.raises(CheckpointError, match="weights do not fit the run's network"):
        load_greedy_policy(tmp_path / "model.zip", other, env.observation_space, env.action_space)
    env.close()
