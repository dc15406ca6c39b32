"""Slow (``make test-slow``): a short real training beats the random policy."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from sumo_ayss.config import load_experiment
from sumo_ayss.envs import make_env
from sumo_ayss.envs.odd import sample_initial_conditions
from sumo_ayss.run_folder import read_eval_table
from sumo_ayss.scenarios.rollout import run_episodes, summarize
from sumo_ayss.train import train

pytestmark = [pytest.mark.slow, pytest.mark.sumo, pytest.mark.timeout(1800)]


def test_short_car_following_training_beats_random_policy(tmp_path: Path) -> None:
    cfg = load_experiment(Path(__file__).parents[1] / "configs" / "car_following.yaml")
    import dataclasses

    cfg = dataclasses.replace(
        cfg,
        train=dataclasses.replace(
            cfg.train, total_timesteps=20_000, eval_every=10_000, progress_bar=False
        ),
    )
    run = train(cfg, seed=0, out=tmp_path)
    best = max(r["mean_return"] for r in read_eval_table(run / "eval.csv"))

    rng = np.random.default_rng(0)
    env = make_env(cfg.env, sumo_seed=0)
    try:
        scenarios = sample_initial_conditions(
            cfg.env.odd, cfg.train.n_eval_scenarios, cfg.train.eval_seed
        )
        random_policy = lambda obs: rng.integers(0, 21, size=len(obs))  # noqa: E731
        random_return = summarize(run_episodes(env, random_policy, scenarios)).mean_return
    finally:
        env.close()
    assert best > random_return + 1.0, (best, random_return)
