"""Where the follower is on (issue 33): the shipped case configs turn it on, the paper's
protocol keeps none, the pipeline's switch overrides every experiment; the over-braker is a
VUT a grid can name."""

from __future__ import annotations

import dataclasses

from sumo_ayss.config import PROJECT_ROOT, load_pipeline
from sumo_ayss.grid.plan import case_experiment
from sumo_ayss.vuts.reference_types import OVERBRAKER_VUT


def test_shipped_configs_on_paper_protocol_off() -> None:
    demo = load_pipeline(PROJECT_ROOT / "configs" / "demo.yaml")
    paper = load_pipeline(PROJECT_ROOT / "configs" / "paper.yaml")
    for case in ("car_following", "cut_in"):
        assert case_experiment(demo, case).env.follower.enabled
        assert not case_experiment(paper, case).env.follower.enabled
    off = dataclasses.replace(demo, follower=False)
    assert not case_experiment(off, "car_following").env.follower.enabled


def test_the_overbraker_is_a_vut_a_grid_can_name() -> None:
    cfg = load_pipeline(PROJECT_ROOT / "configs" / "overbraking.yaml")
    exp = case_experiment(cfg, "car_following")
    assert exp.env.vuts["overbraker"] == OVERBRAKER_VUT
    assert exp.env.follower.enabled
