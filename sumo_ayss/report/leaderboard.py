"""The leaderboard: per case, rank, VUT, margin and verdict against the next VUT, score,
crash rate and mobility.

One table per case at the top of the report (:func:`leaderboard_table`) and the same rows
as plain text at the end of ``pipeline`` and ``rank`` (:func:`leaderboard_text`), so the
terminal and the report say the same thing. The rows come from the mode the case's
headline comes from (``CaseAnalysis.ranking_mode``, its :attr:`~sumo_ayss.modes.Mode.standings`).

What the eye compares first is the margin against the next VUT with *its* interval: the
paired difference the test is about. The per-VUT score intervals (t-intervals over seeds)
stay in the mode's own section: two of them overlapping says nothing about the paired test.
A tie (neighbours the family-adjusted test does not separate) shares one rank, ``"1–2"``.

Adding a column: a field on :class:`LeaderRow`, filled in :func:`leaderboard_rows`, and a
:class:`LeaderColumn` in :data:`COLUMNS` (the table and the terminal follow).
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from sumo_ayss.analysis.case import CaseAnalysis
from sumo_ayss.analysis.reference import CAREFUL_HUMAN, ReferenceComparison
from sumo_ayss.modes import (
    CROSSPLAY,
    EXPOSURE,
    Standing,
    get_mode,
    headline_text,
    missing_rows_line,
)
from sumo_ayss.modes.crossplay import crossplay_result
from sumo_ayss.modes.formatting import fmt_interval, fmt_num, fmt_p, rank_labels
from sumo_ayss.report.blocks import Table
from sumo_ayss.report.sections.common import (
    crash_cell,
    hazards_cell,
    mobility_cell,
    unjustified_cell,
)
from sumo_ayss.report.sections.reference import preventable_text
from sumo_ayss.run_folder import RunRecord

__all__ = [
    "COLUMNS",
    "LeaderColumn",
    "LeaderRow",
    "leaderboard_rows",
    "leaderboard_table",
    "leaderboard_text",
]


@dataclass(frozen=True)
class LeaderRow:
    """One row of a case's leaderboard, every cell as text.

    Attributes:
        rank: ``"1"`` for the safest; ``"2–3"`` for each VUT of a tie spanning ranks 2-3.
        vut: VUT name.
        vs_next: The margin against the next VUT with its interval and the verdict, e.g.
            ``"safer than pi1 by 0.067 (0.062–0.072); paired t, p = 0.002, Holm p = 0.004"``;
            "—" for the last.
        score: The mode's score (its point estimate; the interval is in the mode's section).
        crash_rate: Crash rate with its Wilson interval over the pooled episodes, or "—".
        mobility: Mean VUT speed over the same episodes (TIMID flagged), or "—".
        preventable: Crashes a careful human avoided when replaying them (cross-play), with
            the Wilson interval of their rate, or "—" (no labels, or not cross-play).
        vs_human: The verdict against the careful human (cross-play's reference row), e.g.
            ``"less safe (Holm p = 0.025)"``, or "—".
        hazards: The hazards it caused to the follower behind it (rear-ends, the share it
            caused by braking for nothing, the follower's braking), or "—" (no follower).
        unjustified: Its unjustified hard braking, OVER-BRAKING flagged, or "—".
    """

    rank: str
    vut: str
    vs_next: str
    score: str
    crash_rate: str
    mobility: str
    preventable: str = "—"
    vs_human: str = "—"
    hazards: str = "—"
    unjustified: str = "—"


@dataclass(frozen=True)
class LeaderColumn:
    """One column of the leaderboard.

    Attributes:
        header: The column's header (``{score}`` is replaced by the mode's score name).
        numeric: Right-aligned.
        cell: The row's cell.
    """

    header: str
    numeric: bool
    cell: Callable[[LeaderRow], str]
    optional: bool = False
    """Left out of a table whose every row has "—" there (e.g. no reference row)."""


COLUMNS: tuple[LeaderColumn, ...] = (
    LeaderColumn("rank", True, lambda r: r.rank),
    LeaderColumn("VUT", False, lambda r: r.vut),
    LeaderColumn("vs next: margin (95 % CI) and verdict", False, lambda r: r.vs_next),
    LeaderColumn("{score}", True, lambda r: r.score),
    LeaderColumn("crash rate", True, lambda r: r.crash_rate),
    LeaderColumn("mean speed", True, lambda r: r.mobility),
    LeaderColumn("preventable crashes", True, lambda r: r.preventable, optional=True),
    LeaderColumn("vs the careful human", False, lambda r: r.vs_human, optional=True),
    LeaderColumn("hazards caused", False, lambda r: r.hazards, optional=True),
    LeaderColumn("unjustified braking", False, lambda r: r.unjustified, optional=True),
)
"""The leaderboard's columns, in order."""


def _vs_next(s: Standing, digits: int) -> str:
    """The margin against the next VUT, its interval and the family-adjusted verdict."""
    if s.next_vut is None:
        return "—"
    if s.test == "none":
        return f"no test against {s.next_vut}: {s.n_a} vs {s.n_b} seed(s), a test needs 2"
    if s.p is None:
        return f"not comparable with {s.next_vut}"
    ci = fmt_interval(s.margin_lo, s.margin_hi, digits)
    n = min(s.n_a, s.n_b) if s.n_a and s.n_b else 0
    ci = f" ({ci})" if ci else (f" (no interval with {n} seeds)" if n else "")
    margin = f"by {fmt_num(s.margin, digits)}{ci}" if math.isfinite(s.margin) else ""
    p = f"{s.test}, p {fmt_p(s.p)}"
    if s.p_adjusted is not None and s.p_adjusted != s.p:
        p += f", Holm p {fmt_p(s.p_adjusted)}"
    head = f"safer than {s.next_vut}" if s.significant else f"tied with {s.next_vut}"
    return f"{head} {margin}; {p}" if margin else f"{head}; {p}"


def leaderboard_rows(a: CaseAnalysis[RunRecord]) -> list[LeaderRow]:
    """The leaderboard of one case in its ranking mode, safest first (empty without one).

    The crash rates and mobility are the ranking mode's outcomes, else the VUTs' own
    SPCPs' (exposure).
    """
    mode = get_mode(a.ranking_mode)
    outcomes = mode.outcomes(a) or EXPOSURE.outcomes(a)
    standings = mode.standings(a)
    labels = rank_labels([bool(s.significant) for s in standings[:-1]]) if standings else []
    human = (
        crossplay_result(a).references.get(CAREFUL_HUMAN)
        if a.ranking_mode == CROSSPLAY.name
        else None
    )
    against = {r.vut: r for r in human.rows} if human is not None else {}
    return [
        LeaderRow(
            label,
            s.vut,
            _vs_next(s, mode.digits),
            fmt_num(s.score, mode.digits),
            crash_cell(outcomes.get(s.vut)),
            mobility_cell(outcomes.get(s.vut)),
            *_human_cells(against.get(s.vut)),
            hazards_cell(outcomes.get(s.vut)),
            unjustified_cell(outcomes.get(s.vut)),
        )
        for label, s in zip(labels, standings, strict=True)
    ]


def _human_cells(r: ReferenceComparison | None) -> tuple[str, str]:
    """The preventable-crash and careful-human cells of a VUT (cross-play's reference)."""
    if r is None:
        return "—", "—"
    prevent = preventable_text(r)
    if r.verdict == "untested" or math.isnan(r.p_adjusted):
        return prevent, r.verdict
    return prevent, f"{r.verdict} (Holm p {fmt_p(r.p_adjusted)})"


def leaderboard_table(a: CaseAnalysis[RunRecord], level: float) -> Table | None:
    """The case's leaderboard as a report table, or None without a ranking."""
    rows = leaderboard_rows(a)
    if not rows:
        return None
    pct = f"{100 * level:g} %"
    mode = get_mode(a.ranking_mode)
    score = f"{mode.score_name}, {mode.unit(a)}" if a.ranking_mode == "paper" else mode.score_name
    columns = [c for c in COLUMNS if not (c.optional and all(c.cell(r) == "—" for r in rows))]
    head = tuple(c.header.replace("{score}", score).replace("95 %", pct) for c in columns)
    gap = missing_rows_line(a)
    return Table(
        f"{a.info.title}: leaderboard ({a.ranking_mode} mode), safest first",
        head,
        tuple(tuple(c.cell(r) for c in columns) for r in rows),
        tuple(c.numeric for c in columns),
        (f"{gap} " if gap else "")
        + f"vs next: how much safer than the VUT ranked next, as the paired difference the test "
        f"is about, with its {pct} interval (none with fewer than three seeds, never past "
        "what a difference of two scores can be); 'safer than' when the test's p, adjusted by "
        "Holm over the ranking's adjacent claims, is below 0.05, else 'tied' (a tie shares "
        "one rank). Score: point estimate (per-VUT intervals in the mode's section). Crash "
        "rate: episodes pooled over the SPCPs this mode drives, Wilson 95 % interval. Mean "
        "speed: the VUT's mean speed over the same episodes."
        + (
            " Preventable crashes: those R157's careful human avoided when replaying them "
            "(section k); vs the careful human: the VUT's harm against the careful human's "
            "under the same opponents (paired, Holm over the VUTs)."
            if any(c.header == "vs the careful human" for c in columns)
            else ""
        )
        + (
            " Hazards caused: the follower behind the VUT (SUMO's EIDM, 1 s reaction): share "
            "of episodes it ran into the VUT, the share the VUT caused by braking for nothing "
            "(counted in the harm score as a crash), the follower's mean largest braking. "
            "Unjustified braking: episodes where the VUT braked harder than 3.4 m/s² while "
            "nothing ahead was critical (TTC below 2 s, a gap inside the FSM's unsafe distance "
            "or R157's minimum following distance) and no leader had braked as hard in the "
            "1.15 s before, and the speed it shed so per episode; OVER-BRAKING: more than "
            "1.5 × the median VUT's and 0.68 m/s (docs/ranking.md)."
            if any(c.header == "hazards caused" for c in columns)
            else ""
        )
        + _flagged_first(rows),
    )


def _flagged_first(rows: Sequence[LeaderRow]) -> str:
    """A sentence when the VUT ranked first is flagged OVER-BRAKING, else ""."""
    first = [r for r in rows if r.rank.split("–")[0] == "1" and "OVER-BRAKING" in r.unjustified]
    if not first:
        return ""
    names = ", ".join(r.vut for r in first)
    where = "shares the first rank" if any("–" in r.rank for r in first) else "ranks first"
    return (
        f" {names} {where} but is flagged OVER-BRAKING: its low harm comes with braking "
        "for nothing, a hazard to the traffic behind it."
    )


def leaderboard_text(analyses: Sequence[CaseAnalysis[RunRecord]], width: int = 80) -> str:
    """Every case's leaderboard as plain text that fits ``width`` columns.

    A case takes a title line and a line naming its score; each VUT a line with rank, name,
    score, crash rate and mean speed, then its verdict against the next VUT, indented and
    wrapped.
    """
    lines: list[str] = []
    for a in analyses:
        rows = leaderboard_rows(a)
        lines.append(f"{a.case}: leaderboard ({a.ranking_mode} mode), safest first")
        lines.append(f"  score: {get_mode(a.ranking_mode).score_name}")
        if rows and (gap := missing_rows_line(a)) is not None:
            lines += textwrap.wrap(gap, width, initial_indent="  ", subsequent_indent="  ")
        if not rows:
            lines += textwrap.wrap(
                f"no ranking: {headline_text(a)}",
                width,
                initial_indent="  ",
                subsequent_indent="  ",
            )
        name_w = max((len(r.vut) for r in rows), default=0)
        rank_w = max((len(r.rank) for r in rows), default=0)
        for r in rows:
            human = (
                f"   preventable {r.preventable}   vs careful human: {r.vs_human}"
                if r.vs_human != "—"
                else ""
            )
            if r.unjustified != "—":
                human += f"   hazards: {r.hazards}   unjustified braking: {r.unjustified}"
            lines += textwrap.wrap(
                f"{r.rank:>{rank_w}}. {r.vut:<{name_w}}  {r.score}   crashes {r.crash_rate}   "
                f"speed {r.mobility}{human}",
                width,
                initial_indent="  ",
                subsequent_indent="      ",
            )
            if r.vs_next != "—":
                lines += textwrap.wrap(
                    r.vs_next, width, initial_indent="      ", subsequent_indent="        "
                )
    return "\n".join(lines)
