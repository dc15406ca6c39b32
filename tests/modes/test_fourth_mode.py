"""A fourth ranking mode, added in this test alone (no edit outside ``modes/``'s registry):
it computes its own result from the case's data, gets ranking rows and a report section."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from sumo_ayss.analysis.case_verdict import CaseVerdict
from sumo_ayss.config.report import ReportOptions
from sumo_ayss.modes import Mode, Standing, mode_names, register_mode, unregister_mode
from sumo_ayss.rank import analyse, ranking_rows
from sumo_ayss.report.blocks import Heading, Paragraph
from sumo_ayss.report.document import build_report
from sumo_ayss.run_folder import read_run
from tests.report.test_report import make_run

TITLE = "Crash count (toy mode)"


@dataclass(frozen=True)
class CrashCount(Mode):
    """Ranks VUTs by the crashes of their own outcome episodes; no test."""

    def compute(self, a: Any) -> dict[str, int]:
        return {
            vut: sum(r.episodes.crashes for r in runs if r.episodes is not None)
            for vut, runs in a.runs.items()
        }

    def available(self, a: Any) -> bool:
        return self.name in a.results

    def standings(self, a: Any) -> list[Standing]:
        counts = a.results[self.name]
        order = sorted(counts, key=lambda v: (counts[v], v))
        return [
            Standing(
                rank=i + 1,
                vut=v,
                score=float(counts[v]),
                lo=math.nan,
                hi=math.nan,
                n_seeds=len(a.runs[v]),
                next_vut=order[i + 1] if i + 1 < len(order) else None,
                significant=None,
                ranked_apart=False,
            )
            for i, v in enumerate(order)
        ]

    def verdict(self, a: Any) -> CaseVerdict:
        return CaseVerdict(self.name, "warning", missing="not_comparable")

    def headline(self, a: Any, v: CaseVerdict) -> str:
        return f"[{self.name} mode] crash counts, no test."

    def unit(self, a: Any) -> str:
        return "crashes (lower = safer)"

    def ends(self, a: Any, safest: str, least: str) -> tuple[bool, float]:
        return False, math.nan

    def score_text(self, a: Any, s: Standing) -> str:
        return f"{s.score:g}"

    def interval_text(self, lo: float, hi: float, n_seeds: int, digits: int) -> str:
        return ""

    def section(self, a: Any) -> tuple[str, list[str]]:
        counts = a.results[self.name]
        return TITLE, [", ".join(f"{v}: {n} crashes" for v, n in sorted(counts.items()))]


def test_a_fourth_mode_gets_ranking_rows_and_a_report_section(tmp_path) -> None:
    mode = register_mode(
        CrashCount(
            name="crash_count",
            description="Crash count (toy).",
            score_name="crashes of own SPCPs (lower = safer)",
            interval_name="none",
            digits=0,
        )
    )
    try:
        dirs = [make_run(tmp_path, "car_following", v, s) for v in ("pi1", "pi2") for s in (0, 1)]
        options = ReportOptions(n_boot=50)
        analyses = analyse(dirs, options)
        counts = analyses[0].results["crash_count"]
        assert set(counts) == {"pi1", "pi2"}
        rows = [r for r in ranking_rows(analyses) if r["mode"] == "crash_count"]
        assert [r["vut"] for r in rows] == sorted(counts, key=lambda v: (counts[v], v))
        assert {r["unit"] for r in rows} == {mode.unit(analyses[0])}
        report = build_report(
            [read_run(d) for d in dirs], tmp_path / "report", options=options, analyses=analyses
        )
        blocks = list(report.blocks)
        heading = next(
            i for i, b in enumerate(blocks) if isinstance(b, Heading) and b.text == TITLE
        )
        after = blocks[heading + 1]
        assert isinstance(after, Paragraph) and "pi1:" in after.text and "pi2:" in after.text
    finally:
        unregister_mode("crash_count")
    assert "crash_count" not in mode_names()
