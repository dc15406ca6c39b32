"""The leaderboard: per case, rank, VUT, score with its interval, crash rate, verdict vs next.

One table per case at the top of the report (:func:`leaderboard_table`) and the same rows
as plain text at the end of ``pipeline`` and ``rank`` (:func:`leaderboard_text`), so the
terminal and the report say the same thing. The rows come from the mode the case's
headline comes from (``CaseAnalysis.ranking_mode``, its :attr:`~sumo_ayss.modes.Mode.standings`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from sumo_ayss.analysis.case import CaseAnalysis
from sumo_ayss.modes import EXPOSURE, get_mode, headline_text
from sumo_ayss.modes.formatting import fmt_p
from sumo_ayss.report.blocks import Table
from sumo_ayss.report.sections.common import crash_cell

__all__ = ["LeaderRow", "leaderboard_rows", "leaderboard_table", "leaderboard_text"]


@dataclass(frozen=True)
class LeaderRow:
    """One row of a case's leaderboard, every cell as text.

    Attributes:
        rank: 1 for the safest.
        vut: VUT name.
        score: Score with its interval, e.g. ``"0.335 (0.21–0.46)"``.
        crash_rate: Crash rate with its Wilson interval over the pooled episodes, or "—".
        vs_next: The verdict against the next VUT, e.g. ``"safer than pi1 (p = 0.002)"``;
            "—" for the last.
    """

    rank: int
    vut: str
    score: str
    crash_rate: str
    vs_next: str


def _vs_next(significant: bool | None, nxt: str | None, p: str) -> str:
    if nxt is None:
        return "—"
    if significant:
        return f"safer than {nxt} ({p})"
    return f"not significantly safer than {nxt} ({p})"


def leaderboard_rows(a: CaseAnalysis) -> list[LeaderRow]:
    """The leaderboard of one case in its ranking mode, safest first (empty without one).

    The crash rates are the ranking mode's outcomes, else the VUTs' own SPCPs' (exposure).
    """
    mode = get_mode(a.ranking_mode)
    outcomes = a.outcomes.get(a.ranking_mode) or a.outcomes.get(EXPOSURE.name, {})
    rows: list[LeaderRow] = []
    for s in mode.standings(a):
        p = f"{s.test}, p {fmt_p(s.p)}" if s.p is not None else "not comparable"
        verdict = _vs_next(s.significant, s.next_vut, p)
        if s.test == "none":
            verdict = f"no test against {s.next_vut}: {s.n_a} vs {s.n_b} seed(s), a test needs 2"
        rows.append(
            LeaderRow(
                s.rank, s.vut, mode.score_text(a, s), crash_cell(outcomes.get(s.vut)), verdict
            )
        )
    return rows


def leaderboard_table(a: CaseAnalysis, level: float) -> Table | None:
    """The case's leaderboard as a report table, or None without a ranking."""
    rows = leaderboard_rows(a)
    if not rows:
        return None
    pct = f"{100 * level:g} %"
    mode = get_mode(a.ranking_mode)
    interval = mode.interval_name
    return Table(
        f"{a.info.title}: leaderboard ({a.ranking_mode} mode), safest first",
        ("rank", "VUT", f"{mode.score_name} ({pct} CI)", "crash rate", "vs next"),
        tuple((str(r.rank), r.vut, r.score, r.crash_rate, r.vs_next) for r in rows),
        (True, False, True, True, False),
        f"Score: {pct} {interval} (none with fewer than three seeds). Crash rate: episodes "
        "pooled over the SPCPs this mode drives, with its Wilson 95 % interval. vs next: the "
        "mode's significance test against the VUT ranked next.",
    )


def leaderboard_text(analyses: Sequence[CaseAnalysis]) -> str:
    """Every case's leaderboard as plain text that fits 80 columns (VUT names permitting).

    A case takes a title line and a line naming its score; each VUT two lines: rank, name,
    score and crash rate; then its verdict against the next VUT, indented.
    """
    lines: list[str] = []
    for a in analyses:
        rows = leaderboard_rows(a)
        lines.append(f"{a.case}: leaderboard ({a.ranking_mode} mode), safest first")
        lines.append(f"  score: {get_mode(a.ranking_mode).score_name}")
        if not rows:
            lines.append(f"  no ranking: {headline_text(a)}")
        width = max((len(r.vut) for r in rows), default=0)
        for r in rows:
            lines.append(f"  {r.rank:>2}. {r.vut:<{width}}  {r.score}   crashes {r.crash_rate}")
            if r.vs_next != "—":
                lines.append(f"      {r.vs_next}")
    return "\n".join(lines)
