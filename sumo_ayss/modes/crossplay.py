"""Cross-play mode (the default): every SPCP of a case against every VUT; a VUT's score is
the mean harm per episode the pooled SPCPs bring about (:mod:`sumo_ayss.analysis.crossplay`).

Needs the case's ``crossplay.csv`` (the pipeline runs the cross-play stage in this mode);
without it the headline falls back to the exposure mode's and says so. Its result
(:class:`CrossplayResult`, :func:`compute_crossplay`) is the case's matrix, its ranking and
comparisons, crashes and mobility, the reference drivers' readings and the scenario set's
inevitable-collision share, or why there is no ranking.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from sumo_ayss.modes.formatting import fmt_p_family, ranking_line
from sumo_ayss.modes.registry import Standing, get_mode, mode_result, register_mode
from sumo_ayss.modes.seed_level import INTERVAL_NAME, SeedLevelMode, seed_ends, seed_standings

if TYPE_CHECKING:
    from sumo_ayss.analysis.case import CaseAnalysis
    from sumo_ayss.analysis.case_verdict import CaseVerdict
    from sumo_ayss.analysis.crossplay import CrossplayGap, CrossplayMatrix
    from sumo_ayss.analysis.harm import VutOutcome
    from sumo_ayss.analysis.reference import ReferenceReading, ScenarioSet
    from sumo_ayss.analysis.seeds import SeedComparison, SeedRankRow

__all__ = [
    "CROSSPLAY",
    "CROSSPLAY_COMMAND",
    "NO_CROSSPLAY_TABLE",
    "CrossplayMode",
    "CrossplayResult",
    "compute_crossplay",
    "crossplay_gap_text",
    "crossplay_headline",
    "crossplay_result",
    "crossplay_sentence",
    "crossplay_verdict",
]

NAME = "crossplay"

CROSSPLAY_COMMAND = "python -m sumo_ayss.crossplay <config>"
"""The command that writes a case's cross-play table."""

NO_CROSSPLAY_TABLE = f"no cross-play table for this case (run {CROSSPLAY_COMMAND})"
"""Why a case has no cross-play ranking when its loader found no table."""


@dataclass(frozen=True)
class CrossplayResult:
    """The cross-play mode's result for one case.

    Attributes:
        blocks: Block unit of the paired test (``"seed"`` or ``"opponent"``).
        matrix: The case's cross-play matrix, or None (see ``gap``).
        rows: The ranking, safest first (empty without a table).
        pairs: Comparisons of every pair (A ranked above B).
        path: The ``crossplay.csv`` read, or None.
        gap: Why there is no cross-play ranking; None when there is one.
        diagonal: The table's diagonal check, ``(vut, seed, n, n_equal)`` per run (empty:
            the record predates the check).
        outcomes: ``{vut: VutOutcome}``: crashes with their interval, mobility and hazards
            over the cross-play episodes, shown beside the score.
        references: ``{reference driver: its reading}``: every VUT against each reference
            driver that drove in cross-play (:mod:`sumo_ayss.analysis.reference`), the
            careful human first.
        scenario_set: The share of the case's scenarios that are inevitable-collision
            states, or None (not computed for this table).
    """

    blocks: str = "seed"
    matrix: CrossplayMatrix | None = None
    rows: list[SeedRankRow] = field(default_factory=list)
    pairs: list[SeedComparison] = field(default_factory=list)
    path: Path | None = None
    gap: CrossplayGap | None = None
    diagonal: tuple[tuple[str, int, int, int], ...] = ()
    outcomes: dict[str, VutOutcome] = field(default_factory=dict)
    references: dict[str, ReferenceReading] = field(default_factory=dict)
    scenario_set: ScenarioSet | None = None


def compute_crossplay(a: CaseAnalysis[Any]) -> CrossplayResult:
    """Cross-play ranking of a case from its cross-play table as its loader found it
    (``a.tables``), or why there is none; a table not of exactly these VUTs and runs is not
    used (its lost rows are a line in ``a.problems``)."""
    from sumo_ayss.analysis.crossplay import CrossplayGap, rank_crossplay
    from sumo_ayss.analysis.harm import vut_outcomes
    from sumo_ayss.analysis.reference import ScenarioSet, read_against_reference
    from sumo_ayss.util.errors import ConfigError

    options, found, runs = a.options, a.tables, a.runs
    blocks = options.crossplay_blocks
    if len(runs) < 2:
        return CrossplayResult(blocks, gap=CrossplayGap("one_vut", vut=next(iter(runs), "?")))
    m = found.matrix
    if m is None:
        if found.problem:
            a.problems.append(found.problem)
        return CrossplayResult(blocks, gap=CrossplayGap("not_found", loader=found.missing))
    opponents = {(v, int(r.seed)) for v, rs in runs.items() for r in rs if r.seed is not None}
    if set(m.vuts) != set(runs) or set(m.opponents) != opponents:
        lost = [f"VUT {v}" for v in runs if v not in m.vuts] + [
            f"opponent {v}/seed_{s}" for v, s in sorted(opponents - set(m.opponents))
        ]
        if lost:  # a table that lost rows (or was never extended): a problem, named
            a.problems.append(
                f"{found.path}: no rows of {'; '.join(lost)} (the table holds VUTs "
                f"{', '.join(m.vuts)} and {len(m.opponents)} opponents; the case has "
                f"{len(runs)} VUTs and {len(opponents)} runs)"
            )
        gap = CrossplayGap(
            "not_these_runs",
            path=found.path,
            vuts=tuple(m.vuts),
            n_opponents=len(m.opponents),
            n_runs=len(opponents),
            lost="; ".join(lost),
        )
        return CrossplayResult(blocks, gap=gap)
    rows, pairs = rank_crossplay(m, blocks=blocks, level=options.level, alpha=options.welch_alpha)
    scenario_set = None
    if found.inevitable is not None and found.inevitable[0] == m.n_scenarios:
        scenario_set = ScenarioSet.of(m.n_scenarios, len(found.inevitable[2]), options.level)
    references: dict[str, ReferenceReading] = {}
    if found.reference is not None:
        for name in sorted(found.reference.vuts, key=_careful_human_first):
            try:
                references[name] = read_against_reference(
                    m,
                    found.reference,
                    name,
                    blocks=blocks,
                    level=options.level,
                    alpha=options.welch_alpha,
                )
            except ConfigError as exc:
                a.problems.append(f"{found.path}: reference {name}: {exc}")
    outcomes = vut_outcomes(
        {v: (*m.crashes(v), m.vut_mobility(v)) for v in m.vuts}, options.level, m.hazards
    )
    return CrossplayResult(
        blocks,
        matrix=m,
        rows=rows,
        pairs=pairs,
        path=found.path,
        diagonal=found.diagonal,
        outcomes=outcomes,
        references=references,
        scenario_set=scenario_set,
    )


def _careful_human_first(driver: str) -> tuple[bool, str]:
    """Sort key of the reference drivers: the careful human first, then by name."""
    from sumo_ayss.analysis.reference import CAREFUL_HUMAN

    return driver != CAREFUL_HUMAN, driver


def crossplay_result(a: CaseAnalysis[Any], name: str = NAME) -> CrossplayResult:
    """The cross-play result of a case (that of the mode ``name``, built from this record)."""
    return mode_result(a, name, CrossplayResult)


def _fmt(x: float) -> str:
    return f"{x:.3f}".replace("-", "−")


def crossplay_sentence(c: SeedComparison, blocks: str = "seed") -> str:
    """One quotable sentence for a cross-play comparison (A ranked above B)."""
    from sumo_ayss.analysis.seed_intervals import MIN_SEEDS_FOR_INTERVAL

    unit = "training seeds" if blocks == "seed" else "opponent SPCPs"
    note = "blocks of opponents; " if blocks == "seed" else ""
    pct = f"{100 * c.level:g} %"
    b_higher = c.difference < 0
    lo, hi = (-c.hi, -c.lo) if b_higher else (c.lo, c.hi)
    if math.isfinite(lo) and math.isfinite(hi):
        ci = f"{pct} CI " + (f"{_fmt(lo)}–{_fmt(hi)}" if lo >= 0 else f"{_fmt(lo)} to {_fmt(hi)}")
    elif c.n_a < MIN_SEEDS_FOR_INTERVAL:
        ci = f"no interval with {c.n_a} blocks"
    else:
        ci = "interval undefined"
    p = "p undefined" if not math.isfinite(c.p) else fmt_p_family(c.p, c.p_family, c.family_size)
    df = f"{c.n_a - 1} degree{'s' if c.n_a != 2 else ''} of freedom"
    stats = f"{ci}; paired t-test over {c.n_a} {unit} ({note}{df}), {p}"
    more = "more" if b_higher else "less"
    what = (
        f"the pooled SPCPs bring about {abs(c.difference):.3f} {more} harm per episode "
        f"against {c.name_b} than against {c.name_a}"
    )
    if c.significant and c.difference < 0:
        return f"[crossplay mode] {c.name_a} is safer than {c.name_b}: {what} ({stats})."
    return (
        f"[crossplay mode] No significant difference in safety between {c.name_a} and "
        f"{c.name_b}: {what} ({stats})."
    )


def crossplay_gap_text(gap: CrossplayGap) -> str:
    """Why a case has no cross-play ranking, one sentence."""
    if gap.reason == "one_vut":
        return (
            f"no cross-play for this case: its runs here are of one VUT only ({gap.vut}), and "
            "cross-play compares two or more"
        )
    if gap.reason == "not_these_runs" and gap.lost:
        return (
            f"the cross-play table {gap.path} has no rows of {gap.lost} (damaged, or not yet "
            f"extended to every run); run {CROSSPLAY_COMMAND} --force"
        )
    if gap.reason == "not_these_runs":
        return (
            f"the cross-play table {gap.path} is not of these runs (VUTs {', '.join(gap.vuts)}; "
            f"{gap.n_opponents} opponents, this case has {gap.n_runs} runs with a seed); "
            f"run {CROSSPLAY_COMMAND} again once every job is done"
        )
    return gap.loader or NO_CROSSPLAY_TABLE


def _gap(a: CaseAnalysis[Any], name: str = NAME) -> str:
    """Why the case has no cross-play ranking, one sentence."""
    gap = crossplay_result(a, name).gap
    if gap is not None:
        return crossplay_gap_text(gap)
    return "the cross-play table ranks fewer than two VUTs"


def crossplay_verdict(a: CaseAnalysis[Any], name: str = NAME) -> CaseVerdict:
    """The cross-play mode's verdict; without a ranking of two VUTs, the exposure mode's
    in its place, as a warning."""
    import dataclasses

    from sumo_ayss.analysis.case_verdict import seed_verdict
    from sumo_ayss.modes.exposure import EXPOSURE, exposure_verdict

    result = crossplay_result(a, name)
    v = seed_verdict(NAME, result.rows, result.pairs)
    if not v.missing:
        return v
    return dataclasses.replace(exposure_verdict(a, EXPOSURE.name), kind="warning")


def crossplay_headline(a: CaseAnalysis[Any], v: CaseVerdict, name: str = NAME) -> str:
    """The cross-play mode's verdict in words; one that fell back to the exposure mode's
    says why first."""
    from sumo_ayss.analysis.seeds import SeedComparison

    if v.mode != NAME:
        reason = _gap(a, name)
        shown = get_mode(v.mode).headline(a, v)
        return f"[{NAME} mode] {reason}. Shown instead, labelled: {shown}"
    assert isinstance(v.top, SeedComparison)
    return crossplay_sentence(v.top, crossplay_result(a, name).blocks)


def _companion_lines(a: CaseAnalysis[Any]) -> list[str]:
    """The exposure ranking beside the cross-play one."""
    # Imported here: the exposure mode registers after this one (rows follow that order).
    from sumo_ayss.modes.exposure import EXPOSURE, exposure_result

    rows = exposure_result(a, EXPOSURE.name).rows
    if not rows:
        return []
    line = ranking_line([r.name for r in rows], [bool(r.significant_vs_next) for r in rows[:-1]])
    return [f"Ranking (exposure mode), safest first: {line}"]


class CrossplayMode(SeedLevelMode):
    """Cross-play mode: its ranking, verdict and words (see the module docstring)."""

    def compute(self, a: CaseAnalysis[Any]) -> CrossplayResult:
        return compute_crossplay(a)

    def available(self, a: CaseAnalysis[Any]) -> bool:
        return bool(crossplay_result(a, self.name).rows)

    def standings(self, a: CaseAnalysis[Any]) -> list[Standing]:
        result = crossplay_result(a, self.name)
        sentence = functools.partial(crossplay_sentence, blocks=result.blocks)
        return seed_standings(result.rows, sentence)

    def verdict(self, a: CaseAnalysis[Any]) -> CaseVerdict:
        return crossplay_verdict(a, self.name)

    def headline(self, a: CaseAnalysis[Any], v: CaseVerdict) -> str:
        return crossplay_headline(a, v, self.name)

    def outcomes(self, a: CaseAnalysis[Any]) -> Mapping[str, VutOutcome]:
        return crossplay_result(a, self.name).outcomes

    def unit(self, a: CaseAnalysis[Any]) -> str:
        return "harm/episode, pooled SPCPs (lower = safer)"

    def ends(self, a: CaseAnalysis[Any], safest: str, least: str) -> tuple[bool, float]:
        return seed_ends(crossplay_result(a, self.name).pairs, safest, least)

    def companion_lines(self, a: CaseAnalysis[Any]) -> list[str]:
        return _companion_lines(a)

    def gap_text(self, a: CaseAnalysis[Any]) -> str | None:
        return _gap(a, self.name)


CROSSPLAY = register_mode(
    CrossplayMode(
        name=NAME,
        description=(
            "Cross-play mode (default): every SPCP of a case drives against every VUT of the "
            "case on the same outcome scenarios; a VUT's score H is the mean harm per episode "
            "this pooled population of opponents brings about against it (1 for a collision, "
            "else the near-miss reward paid over the most an episode can pay), and a lower H "
            "is a safer VUT. A collision is the worst outcome for the VUT, never its gain. A "
            "difference between two VUTs is read within each opponent, so the search noise "
            "of one SPCP cancels; two VUTs are compared by a paired t-test over "
            "training-seed blocks (block s = the mean over seed s's opponents; "
            "or one block per opponent where the study's configuration asks for it). A VUT "
            "is called safer than the next when that test's p, adjusted by Holm over the "
            "ranking's adjacent pairs, is below the significance level (0.05 unless "
            "configured: the claims of one leaderboard are then wrong together with "
            "probability at most 5 %); else the two are tied. With few "
            "blocks the test has few degrees of freedom (blocks − 1) and needs a difference "
            "consistent across them. Crash rate and mobility (mean VUT speed) stand beside the "
            "score; a VUT far slower than the others is flagged TIMID."
        ),
        score_name="cross-play harm H per episode (lower = safer)",
        interval_name=INTERVAL_NAME,
        digits=3,
        runs_crossplay=True,
    )
)
