"""Section (j) and ``measures.csv``: the safety measures of the cross-play pool (no SUMO)."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from sumo_ayss.analysis.safety_measures import MEASURE_NAMES
from sumo_ayss.rank import analyse
from sumo_ayss.records.table import Table, read_table, write_table
from sumo_ayss.report import write_report
from sumo_ayss.report.measures import write_measures
from sumo_ayss.run_folder import CROSSPLAY_SCHEMA, OUTCOME_SCHEMA, StudyFolder
from tests.report.test_report import FAST, make_crossplay, make_run


def _study(root: Path, *, measures: bool) -> Path:
    """pi2 (safer by construction in the helpers) also keeps the larger TTC here."""
    for vut in ("pi1", "pi2"):
        for seed in range(3):
            make_run(root, "car_following", vut, seed)
    path = make_crossplay(root / "car_following", ["pi1", "pi2"], range(3))
    t = read_table(path, CROSSPLAY_SCHEMA)
    rng = np.random.default_rng(5)
    n, safer = len(t), t["vut"] == "pi2"
    cols = {c: t[c] for c in CROSSPLAY_SCHEMA.names}
    for name in MEASURE_NAMES:
        cols[name] = np.full(n, np.nan)
    if measures:
        cols["min_ttc_s"] = np.where(safer, 3.0, 1.0) + rng.uniform(0, 0.5, n)
        cols["min_ttc_s"][::7] = np.inf  # nobody closed in
        cols["max_drac_mps2"] = np.where(safer, 1.0, 2.0) + rng.uniform(0, 0.1, n)
        cols["vut_max_braking_mps2"] = np.where(safer, 6.0, 4.5)  # the safer one brakes harder
    write_table(path, Table(CROSSPLAY_SCHEMA, cols))
    return root


def test_section_j_shows_distributions_and_each_measures_ranking(tmp_path: Path) -> None:
    root = _study(tmp_path / "runs", measures=True)
    html = write_report([root], options=FAST)
    md = (html.parent / "summary.md").read_text(encoding="utf-8")
    section = md.split("### (j) Surrogate safety measures")[1]
    assert "| min TTC (1-D) | higher = safer | pi2 > pi1 | 1.00 |" in section
    assert "| max DRAC | lower = safer | pi2 > pi1 | 1.00 |" in section
    assert "| VUT max braking | lower = safer | pi1 > pi2 | −1.00 |" in section
    assert "| primary | crossplay | pi2 > pi1 | 1 |" in section
    assert "post-encroachment" not in section  # never defined in car-following: not shown
    assert (html.parent / "car_following_safety_measures.png").is_file()


def test_tables_without_measures_say_so(tmp_path: Path) -> None:
    root = _study(tmp_path / "runs", measures=False)
    md = (write_report([root], options=FAST).parent / "summary.md").read_text(encoding="utf-8")
    assert "No safety measures: the cross-play tables were written before the measures" in md


def test_measures_csv(tmp_path: Path) -> None:
    root = _study(tmp_path / "runs", measures=True)
    analyses = analyse(sorted(root.glob("car_following/*/seed_*")), FAST)
    path = write_measures(tmp_path, analyses)
    assert path == StudyFolder(tmp_path).measures_csv
    rows = list(csv.DictReader(path.open()))
    ttc = {r["vut"]: r for r in rows if r["measure"] == "min_ttc_s"}
    assert (ttc["pi2"]["rank"], ttc["pi1"]["rank"]) == ("1", "2")
    assert ttc["pi2"]["primary_rank"] == "1" and ttc["pi2"]["tau_vs_primary"] == "1.0"
    assert float(ttc["pi1"]["share_inf"]) > 0 and ttc["pi1"]["pool"] == "cross-play"
    assert ttc["pi2"]["n"] == ttc["pi2"]["n_total"]
    # nothing recorded: no file
    bare = _study(tmp_path / "bare", measures=False)
    assert write_measures(tmp_path / "bare", analyse(sorted(bare.glob("*/*/seed_*")), FAST)) is None


def test_without_cross_play_the_pool_is_each_vuts_own_spcps(tmp_path: Path) -> None:
    root = tmp_path / "runs"
    for vut in ("pi1", "pi2"):
        for seed in range(3):
            run = make_run(root, "car_following", vut, seed)
            path = run / "outcome.csv"
            t = read_table(path, OUTCOME_SCHEMA)
            cols = {c: t[c] for c in OUTCOME_SCHEMA.names}
            cols["min_thw_s"] = np.full(len(t), 1.5 if vut == "pi2" else 0.5)
            write_table(path, Table(OUTCOME_SCHEMA, cols))
    md = (write_report([root], options=FAST).parent / "summary.md").read_text(encoding="utf-8")
    section = md.split("### (j) Surrogate safety measures")[1]
    assert "Every episode of the own SPCPs pool" in section and "training seed resampled" in section
    assert "| min time headway | higher = safer | pi2 > pi1 |" in section
