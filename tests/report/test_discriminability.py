"""Report section "Discriminability before training" from a record (no SUMO)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from sumo_ayss.analysis.discriminability import BoxGrid, BoxStates, compare_responses
from sumo_ayss.discriminability import write_outputs
from sumo_ayss.report import write_report
from sumo_ayss.report.blocks import FigureBlock, Table
from sumo_ayss.report.sections.discriminability import (
    discriminability_blocks,
    pair_summary,
    read_record,
)
from sumo_ayss.run_folder import CaseFolder
from tests.report.test_report import FAST, make_run


def _record(vuts: tuple[str, ...] = ("pi1", "pi2")) -> dict:
    """A record as the CLI writes it, from synthetic responses: pi2 brakes harder at h > 3 m."""
    states = BoxGrid(speed_step_mps=5.0, headway_step_m=0.5).states()
    base = -6.0 + 0.3 * np.clip(states.h_m - 3.0, 0.0, None) * 4
    responses = {v: base - (0.5 * (states.h_m > 3.0) if v == "pi2" else 0.0) for v in vuts}
    result = compare_responses(responses, states)
    return {
        "case": "car_following",
        "vuts": list(vuts),
        "settings": {"grid": BoxGrid(speed_step_mps=5.0, headway_step_m=0.5).to_dict()},
        "collisions": {v: 0 for v in vuts},
        "summary": [pair_summary(p, 0.1) for p in result.pairs],
        **result.to_dict(),
    }


def test_pair_summary_golden() -> None:
    """The record's summary lines, on the analysis's hand-computed case."""
    h = np.array([0.5, 1.5, 2.5, 3.5, 4.5, 4.5])
    v = np.array([5.0, 5.0, 15.0, 15.0, 25.0, 25.0])
    a = np.array([-6.0, -6.0, -6.0, -5.0, -4.0, -4.0])
    b = np.array([-6.0, -6.0, -6.0, -6.0, -6.0, -4.05])
    res = compare_responses(
        {"a": a, "b": b, "a2": a.copy()},
        BoxStates(v_pov_mps=v.copy(), v_vut_mps=v, h_m=h),
        threshold_mps2=0.1,
        h_edges_m=[0, 1, 2, 3, 4, 5],
        v_edges_mps=[0, 10, 20, 30],
    )
    ab, aa, _ = res.pairs
    assert pair_summary(ab, 0.1) == "a vs b differ in 33.3 % of the AYSS box; none below h ≈ 3.50 m"
    assert pair_summary(ab, 0.1, h_step_m=3.5).endswith("down to the smallest headway (h = 3.5 m)")
    assert pair_summary(aa, 0.1).startswith("a vs a2: no difference anywhere")


def test_blocks_from_a_record(tmp_path: Path) -> None:
    case_dir = tmp_path / "out" / "car_following"
    write_outputs(_record(), case_dir)
    rec = read_record(CaseFolder(case_dir).discriminability_json)
    assert rec is not None and rec["pairs"][0]["lowest_h_m"] == 3.5
    blocks = discriminability_blocks("car_following", ["pi1", "pi2"], [case_dir], tmp_path / "r")
    figs = [b for b in blocks if isinstance(b, FigureBlock)]
    assert len(figs) == 1 and figs[0].path.is_file()
    table = next(b for b in blocks if isinstance(b, Table))
    assert table.rows[0][0] == "pi1 vs pi2" and table.rows[0][2] == "3.50"
    responses = [b for b in blocks if isinstance(b, Table)][-1]
    assert all(row[1].startswith("−") for row in responses.rows)  # the report's minus sign
    # One VUT: no section; no record: a paragraph saying how to make one.
    assert discriminability_blocks("car_following", ["pi1"], [case_dir], tmp_path) == []
    empty = discriminability_blocks("car_following", ["pi1", "pi2"], [tmp_path], tmp_path)
    assert "python -m sumo_ayss.discriminability" in empty[1].text  # type: ignore[union-attr]
    # A record of other VUTs is not used.
    other = discriminability_blocks("car_following", ["a", "b"], [case_dir], tmp_path)
    assert not any(isinstance(b, FigureBlock) for b in other)


def test_report_shows_the_section_when_a_record_is_beside_the_runs(tmp_path: Path) -> None:
    root = tmp_path / "runs"
    for vut in ("pi1", "pi2"):
        for seed in range(2):
            make_run(root, "car_following", vut, seed, n_samples=60)
    html_path = write_report([root], tmp_path / "r0", options=FAST)
    assert "not computed for these vuts" in html_path.read_text(encoding="utf-8").lower()
    (CaseFolder(root / "car_following").discriminability_json).write_text(json.dumps(_record()))
    html_path = write_report([root], tmp_path / "r1", options=FAST)
    html = html_path.read_text(encoding="utf-8")
    assert "(h) Discriminability before training" in html
    assert "pi1 vs pi2 differ in" in html
    assert (tmp_path / "r1" / "car_following_discriminability.png").is_file()
