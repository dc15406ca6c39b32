"""A generated report, scanned whole: no interval past what its quantity can take, none
where the seeds cannot support one, and each table once (issue 35)."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import pytest

from sumo_ayss.report import write_report
from tests.report.report_scan import INTERVAL, bounds, seed_level, tables, value
from tests.report.test_report import FAST, make_crossplay, make_run

VUTS = ("pi1", "pi2", "pi1_again")


def _report(root: Path, seeds: int) -> str:
    for vut in VUTS:
        for seed in range(seeds):
            make_run(root, "car_following", vut, seed)
    make_crossplay(root / "car_following", list(VUTS), range(seeds))
    write_report([root], options=FAST)
    return (root / "report" / "summary.md").read_text(encoding="utf-8")


@pytest.fixture(scope="module")
def reports(tmp_path_factory: pytest.TempPathFactory) -> dict[int, str]:
    return {n: _report(tmp_path_factory.mktemp(f"runs{n}"), n) for n in (2, 4)}


@pytest.mark.parametrize("seeds", [2, 4])
def test_no_interval_past_what_the_quantity_can_take(reports: dict[int, str], seeds: int) -> None:
    checked = 0
    for caption, header, rows in tables(reports[seeds]):
        for row in rows:
            for col, cell in zip(header, row, strict=False):
                for lo, hi in INTERVAL.findall(cell):
                    lo_v, hi_v = value(lo), value(hi)
                    assert lo_v <= hi_v, (caption, col, cell)
                    b = bounds(col, row[0])
                    if b is not None:
                        checked += 1
                        assert b[0] <= lo_v and hi_v <= b[1], (caption, col, cell)
    assert checked > 10  # the scan saw the report's intervals


def test_two_seeds_print_no_interval_over_seeds(reports: dict[int, str]) -> None:
    md = reports[2]
    seen = 0
    for caption, header, rows in tables(md):
        for row in rows:
            for col, cell in zip(header, row, strict=False):
                if seed_level(col, caption) and INTERVAL.search(cell) and col != "seed":
                    pytest.fail(f"an interval over 2 seeds: {caption} / {col}: {cell}")
                seen += "no interval" in cell
    assert seen >= 6
    # ... nor in the verdict sentences: a difference over 2 seed blocks has no interval.
    for line in md.splitlines():
        if "training seeds (blocks of opponents" in line or "shared seeds" in line:
            assert "% CI" not in line, line


def test_four_seeds_print_the_intervals(reports: dict[int, str]) -> None:
    board = reports[4].split("## Leaderboard")[1].split("## Verdicts")[0]
    assert INTERVAL.search(board)
    assert "no interval" not in board


@pytest.mark.parametrize("seeds", [2, 4])
def test_each_table_appears_once(reports: dict[int, str], seeds: int) -> None:
    bodies = Counter(
        "\n".join(" | ".join(r) for r in rows) for _, _, rows in tables(reports[seeds]) if rows
    )
    repeated = [b.splitlines()[0] for b, n in bodies.items() if n > 1]
    assert not repeated, repeated


def test_ties_read_as_ties_and_the_first_vut_is_named_the_same_everywhere(
    reports: dict[int, str],
) -> None:
    md = reports[2]
    found = tables(md)
    board = next(rows for cap, head, rows in found if "leaderboard" in cap)
    ranks = [r[0] for r in board]
    first = board[0][1]
    line = next(
        ln.split("safest first: ")[1]
        for ln in md.splitlines()
        if ln.startswith("> Ranking (crossplay mode), safest first: ")
    )
    assert line.split(" ")[0] == first  # the verdict box names the leaderboard's first VUT
    if "≈" in line:  # a tie in the line is a shared rank on the board, and vice versa
        assert any("–" in r for r in ranks)
    else:
        assert not any("–" in r for r in ranks)
    primary = next(rows for cap, head, rows in found if "beside the primary one" in cap)[0]
    assert primary[2] == line  # the measures' primary row: the same line, ties and all
