"""Every shipped YAML under configs/ loads through the loader that the README uses for it."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from sumo_ayss.config import PROJECT_ROOT, load_experiment
from sumo_ayss.config.budget import BUDGETS
from sumo_ayss.pipeline import load_pipeline, plan_jobs

CONFIGS = sorted((PROJECT_ROOT / "configs").rglob("*.yaml"))


def _is_pipeline(path: Path) -> bool:
    return "grid" in (yaml.safe_load(path.read_text()) or {})


def test_configs_are_found() -> None:
    names = {p.relative_to(PROJECT_ROOT / "configs").as_posix() for p in CONFIGS}
    assert {"paper.yaml", "demo.yaml", "car_following.yaml", "ladders/min_gap.yaml"} <= names


@pytest.mark.parametrize("path", CONFIGS, ids=lambda p: p.relative_to(PROJECT_ROOT).as_posix())
def test_config_loads(path: Path) -> None:
    if _is_pipeline(path):
        cfg = load_pipeline(path)
        jobs = plan_jobs(cfg)  # resolves every job's experiment, VUT and seed
        assert len(jobs) == len(cfg.grid.cases) * len(cfg.grid.vuts) * len(cfg.grid.seeds)
    else:
        exp = load_experiment(path)
        assert exp.env.vut in exp.env.vuts


def test_the_shipped_experiments_train_the_paper_budget() -> None:
    for name in ("car_following.yaml", "cut_in.yaml"):
        exp = load_experiment(PROJECT_ROOT / "configs" / name)
        assert exp.train.total_timesteps == BUDGETS["paper"].total_timesteps
