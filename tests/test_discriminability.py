"""``python -m sumo_ayss.discriminability``: real SUMO on a coarse grid of the AYSS box."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path
from typing import Any

import pytest
import yaml

from sumo_ayss import discriminability as disc
from sumo_ayss.analysis.discriminability import BoxGrid
from sumo_ayss.config import PROJECT_ROOT
from sumo_ayss.run_folder import CaseFolder
from sumo_ayss.util.errors import ConfigError

pytestmark = pytest.mark.sumo

IDM = {"accel": 3.0, "decel": 5.0, "emergencyDecel": 6.0, "tau": 1.5, "delta": 4.0,
       "length": 5.0, "speedDev": 0.0, "maxSpeed": 40.0}  # fmt: skip

#: A coarse grid: 11 x 11 speeds x 20 headways, ~1,900 states (well under a second per VUT).
COARSE = ["--speed-step", "3", "--headway-step", "0.25"]


def _pipeline_yaml(tmp_path: Path) -> Path:
    data = {
        "grid": {"cases": ["car_following"], "vuts": ["pi1", "pi2", "twin", "sharp"]},
        "experiments": {"car_following": str(PROJECT_ROOT / "configs" / "car_following.yaml")},
        "vuts": {
            # pi1 under another name: the same VUT.
            "twin": {"model": "IDM", "params": {**IDM, "minGap": 5.0}},
            # A very different VUT: short time gap, no standstill gap, hard brakes.
            "sharp": {
                "model": "IDM",
                "params": {**IDM, "tau": 0.5, "minGap": 0.5, "decel": 9.0, "emergencyDecel": 9.0},
            },
        },
    }
    path = tmp_path / "pipe.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


@pytest.fixture(scope="module")
def record(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict[str, Any], Path, str]:
    tmp = tmp_path_factory.mktemp("disc")
    out = tmp / "out"
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        disc.main([str(_pipeline_yaml(tmp)), "--out", str(out), *COARSE])
    return json.loads((CaseFolder(out).discriminability_json).read_text()), out, buf.getvalue()


def _pair(rec: dict[str, Any], a: str, b: str) -> dict[str, Any]:
    return next(p for p in rec["pairs"] if (p["a"], p["b"]) == (a, b))


def test_pi1_pi2_differ_only_at_larger_headways(record: tuple[dict, Path, str]) -> None:
    """The research note (idm-signal.md): SUMO's pi1 and pi2 respond alike below h ≈ 2.95 m."""
    rec, _, _ = record
    p = _pair(rec, "pi1", "pi2")
    assert 0.05 < p["share"] < 0.25
    assert p["lowest_h_m"] >= 2.5
    edges = rec["h_edges_m"]
    below = [s for lo, s in zip(edges[:-1], p["share_by_h"], strict=True) if lo < 2.5]
    assert below and all(s == 0.0 for s in below)
    assert rec["mean_response_mps2"]["pi2"] < rec["mean_response_mps2"]["pi1"]


def test_a_vut_and_its_twin_differ_nowhere(record: tuple[dict, Path, str]) -> None:
    rec, _, _ = record
    p = _pair(rec, "pi1", "twin")
    assert p["share"] == 0.0 and p["max_abs_diff_mps2"] == 0.0 and p["lowest_h_m"] is None


def test_very_different_vuts_differ_almost_everywhere(record: tuple[dict, Path, str]) -> None:
    rec, _, _ = record
    p = _pair(rec, "pi2", "sharp")
    assert p["share"] > 0.5
    assert p["lowest_h_m"] <= 0.25  # down to the smallest headway of the grid


def test_outputs_and_summary(record: tuple[dict, Path, str]) -> None:
    rec, out, printed = record
    assert rec["n_states"] == len(BoxGrid(speed_step_mps=3, headway_step_m=0.25).states())
    assert len(rec["pairs"]) == 6 and rec["case"] == "car_following"
    assert (CaseFolder(out).discriminability_png).stat().st_size > 10_000
    lines = (CaseFolder(out).discriminability_csv).read_text().splitlines()
    assert lines[0] == "pair,dimension,bin_low,bin_high,share"
    assert sum(line.startswith("pi1 vs pi2,all,") for line in lines) == 1
    assert "pi1 vs twin: no difference anywhere in the AYSS box" in printed
    assert "pi1 vs pi2 differ in " in printed and "none below h ≈ " in printed


def test_ensure_reuses_a_record_made_from_the_same_inputs(
    record: tuple[dict, Path, str], monkeypatch: pytest.MonkeyPatch
) -> None:
    rec, out, _ = record
    target = disc.load_target(_pipeline_yaml(out.parent), None, None)
    grid = BoxGrid(speed_step_mps=3, headway_step_m=0.25)

    def boom(*a: Any, **k: Any) -> Any:
        raise AssertionError("recomputed")

    monkeypatch.setattr(disc, "compute", boom)
    again = disc.ensure(target.env, target.vuts, out, grid=grid)
    assert again["fingerprint"] == rec["fingerprint"]
    with pytest.raises(AssertionError, match="recomputed"):  # another threshold: stale
        disc.ensure(target.env, target.vuts, out, grid=grid, threshold_mps2=0.2)


@pytest.mark.parametrize(
    ("args", "match"),
    [
        ([], r"--vuts: an experiment YAML needs the VUTs"),
        (["--vuts", "pi1"], r"--vuts needs at least 2 VUTs"),
        (["--vuts", "pi1", "pi1"], r"--vuts has duplicates"),
        (["--vuts", "pi1", "pi9"], r"unknown VUT\(s\) \['pi9'\]; allowed: \[.*'pi1', 'pi2'"),
    ],
)
def test_bad_vut_lists_are_refused(args: list[str], match: str) -> None:
    with pytest.raises(ConfigError, match=match):
        disc.load_target(PROJECT_ROOT / "configs" / "car_following.yaml", args[1:] or None, None)
    with pytest.raises(SystemExit, match=r"^error: --vuts"):
        disc.main([str(PROJECT_ROOT / "configs" / "car_following.yaml"), *args])
