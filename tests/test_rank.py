"""Leaderboard rows: ordered by safety index, with intervals and verdicts against the next."""

from __future__ import annotations

from pathlib import Path

from sumo_ayss.rank import ranking_rows, write_ranking
from tests.report.test_report import OFFSET, make_run


def test_ranking_of_three_vuts_is_ordered_with_intervals(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setitem(OFFSET, "cautious", -3.0)  # its SPCPs brake hardest: safest VUT
    dirs = [
        make_run(tmp_path, "car_following", vut, seed)
        for vut in ("pi1", "pi2", "cautious")
        for seed in range(3)
    ]
    rows = ranking_rows(dirs)
    assert [r["vut"] for r in rows] == ["cautious", "pi2", "pi1"]
    assert [r["rank"] for r in rows] == [1, 2, 3]
    for r in rows:
        assert r["lo"] <= r["safety_index"] <= r["hi"] and r["n_seeds"] == 3
    points = [r["safety_index"] for r in rows]
    assert points == sorted(points, reverse=True)
    assert rows[0]["significant_vs_next"] is True
    assert rows[-1]["vs_next"] == ""
    csv_path, md_path = write_ranking(rows, tmp_path)
    assert csv_path.read_text().splitlines()[0].startswith("case,rank,vut,safety_index")
    assert "| car_following | 1 | cautious |" in md_path.read_text()
