"""The reference-driver settings: named fields, allowed values, and grids that name one."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from sumo_ayss.config.pipeline import EvaluateConfig
from sumo_ayss.pipeline import load_pipeline, plan_jobs
from sumo_ayss.util.errors import ConfigError


def test_defaults_label_with_the_careful_human_and_drive_all_three() -> None:
    ev = EvaluateConfig()
    assert ev.reference == "cc_driver"
    assert ev.reference_rows == ("cc_driver", "fsm", "rss")
    assert EvaluateConfig(reference=None, reference_rows=()).reference is None


@pytest.mark.parametrize(
    ("field", "value", "match"),
    [
        ("reference", "superhuman", r"evaluate\.reference must be one of"),
        ("reference_rows", ["cc_driver", "tesla"], r"evaluate\.reference_rows\[1\] must be"),
    ],
)
def test_bad_reference_settings_name_the_field(
    tmp_path: Path, field: str, value: object, match: str
) -> None:
    path = tmp_path / "p.yaml"
    path.write_text(yaml.safe_dump({"evaluate": {field: value}}))
    with pytest.raises(ConfigError, match=match):
        load_pipeline(path)


def test_a_grid_may_name_a_reference_driver(tmp_path: Path) -> None:
    path = tmp_path / "p.yaml"
    grid = {"cases": ["car_following"], "vuts": ["pi1", "cc_driver"], "seeds": [0]}
    path.write_text(yaml.safe_dump({"grid": grid, "out": "runs"}))
    jobs = plan_jobs(load_pipeline(path))
    cc = [j for j in jobs if j.vut == "cc_driver"]
    assert cc and cc[0].experiment.env.vut_type.controller is not None
    assert cc[0].experiment.env.vut_type.controller.target == "careful_driver"
