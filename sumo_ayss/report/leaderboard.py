"""The leaderboard: per case, rank, VUT, score with its interval, crash rate, verdict vs next.

One table per case at the top of the report (:func:`leaderboard_table`) and the same rows
as plain text at the end of ``pipeline`` and ``rank`` (:func:`leaderboard_text`), so the
terminal and the report say the same thing. The rows come from the mode the case's
headline comes from (``CaseAnalysis.ranking_mode``): cross-play, exposure or paper.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from sumo_ayss.analysis.case import CaseAnalysis
from sumo_ayss.analysis.formatting import fmt_interval, fmt_num, fmt_p
from sumo_ayss.analysis.seed_intervals import seed_interval_text
from sumo_ayss.report.blocks import Table
from sumo_ayss.report.sections.common import crash_cell

__all__ = ["LeaderRow", "leaderboard_rows", "leaderboard_table", "leaderboard_text"]

#: What the score column holds per mode, with its orientation.
SCORE_NAMES = {
    "crossplay": "cross-play harm H per episode (lower = safer)",
    "exposure": "exposure harm per episode (lower = safer)",
    "paper": "safety index (higher = safer)",
}


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
    """The leaderboard of one case in its ranking mode, safest first (empty without one)."""
    outcomes = a.outcomes.get(a.ranking_mode) or a.outcomes.get("exposure", {})
    rows: list[LeaderRow] = []
    if a.ranking_mode in ("crossplay", "exposure"):
        seed_rows = a.crossplay_rows if a.ranking_mode == "crossplay" else a.exposure_rows
        for i, r in enumerate(seed_rows):
            nxt = seed_rows[i + 1].name if i + 1 < len(seed_rows) else None
            c = r.vs_next
            p = f"{c.test}, p {fmt_p(c.p)}" if c is not None else ""
            score = f"{fmt_num(r.mean, 3)} ({seed_interval_text(r.lo, r.hi, r.n_seeds, 3)})"
            verdict = _vs_next(c.significant if c else None, nxt, p)
            if c is not None and c.test == "none":
                verdict = f"no test against {nxt}: {c.n_a} vs {c.n_b} seed(s), a test needs 2"
            rows.append(LeaderRow(r.rank, r.name, score, crash_cell(outcomes.get(r.name)), verdict))
        return rows
    pairs = {(p.verdict.name_a, p.verdict.name_b): p for p in a.pairs}
    for i, ranked in enumerate(a.ranking):
        nxt = a.ranking[i + 1].name if i + 1 < len(a.ranking) else None
        pair = pairs.get((ranked.name, nxt)) if nxt else None
        p = f"Welch t, p {fmt_p(pair.verdict.p_seed_welch)}" if pair else "not comparable"
        ci = fmt_interval(ranked.lo, ranked.hi)
        unit = a.info.indicator.unit
        score = f"{fmt_num(ranked.point)} {unit}" + (f" ({ci})" if ci else "")
        rows.append(
            LeaderRow(
                ranked.rank,
                ranked.name,
                score,
                crash_cell(outcomes.get(ranked.name)),
                _vs_next(pair.significant if pair else None, nxt, p),
            )
        )
    return rows


def leaderboard_table(a: CaseAnalysis, level: float) -> Table | None:
    """The case's leaderboard as a report table, or None without a ranking."""
    rows = leaderboard_rows(a)
    if not rows:
        return None
    pct = f"{100 * level:g} %"
    interval = "bootstrap interval" if a.ranking_mode == "paper" else "t-interval over seeds"
    return Table(
        f"{a.info.title}: leaderboard ({a.ranking_mode} mode), safest first",
        ("rank", "VUT", f"{SCORE_NAMES[a.ranking_mode]} ({pct} CI)", "crash rate", "vs next"),
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
        lines.append(f"  score: {SCORE_NAMES[a.ranking_mode]}")
        if not rows:
            lines.append(f"  no ranking: {a.headline}")
        width = max((len(r.vut) for r in rows), default=0)
        for r in rows:
            lines.append(f"  {r.rank:>2}. {r.vut:<{width}}  {r.score}   crashes {r.crash_rate}")
            if r.vs_next != "—":
                lines.append(f"      {r.vs_next}")
    return "\n".join(lines)
