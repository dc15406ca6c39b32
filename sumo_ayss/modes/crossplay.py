"""Cross-play mode (the default): every SPCP of a case against every VUT; a VUT's score is
the mean harm per episode the pooled SPCPs bring about (:mod:`sumo_ayss.analysis.crossplay`).

Needs the case's ``crossplay.csv`` (the pipeline runs the cross-play stage in this mode);
without it the headline falls back to the exposure mode's and says so.
"""

from __future__ import annotations

import functools
import math
from typing import TYPE_CHECKING, Any

from sumo_ayss.modes.formatting import fmt_p_family, ranking_line
from sumo_ayss.modes.registry import Standing, get_mode, register_mode
from sumo_ayss.modes.seed_level import INTERVAL_NAME, SeedLevelMode, seed_ends, seed_standings

if TYPE_CHECKING:
    from sumo_ayss.analysis.case import CaseAnalysis
    from sumo_ayss.analysis.case_verdict import CaseVerdict
    from sumo_ayss.analysis.crossplay import CrossplayGap
    from sumo_ayss.analysis.seeds import SeedComparison

__all__ = [
    "CROSSPLAY",
    "CROSSPLAY_COMMAND",
    "NO_CROSSPLAY_TABLE",
    "CrossplayMode",
    "crossplay_gap_text",
    "crossplay_headline",
    "crossplay_sentence",
    "crossplay_verdict",
]

NAME = "crossplay"

CROSSPLAY_COMMAND = "python -m sumo_ayss.crossplay <config>"
"""The command that writes a case's cross-play table."""

NO_CROSSPLAY_TABLE = f"no cross-play table for this case (run {CROSSPLAY_COMMAND})"
"""Why a case has no cross-play ranking when its loader found no table."""


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


def _gap(a: CaseAnalysis[Any]) -> str:
    """Why the case has no cross-play ranking, one sentence."""
    if a.crossplay_gap is not None:
        return crossplay_gap_text(a.crossplay_gap)
    return "the cross-play table ranks fewer than two VUTs"


def crossplay_verdict(a: CaseAnalysis[Any]) -> CaseVerdict:
    """The cross-play mode's verdict; without a ranking of two VUTs, the exposure mode's
    in its place, as a warning."""
    import dataclasses

    from sumo_ayss.analysis.case_verdict import seed_verdict
    from sumo_ayss.modes.exposure import EXPOSURE, exposure_verdict

    v = seed_verdict(NAME, a.crossplay_rows, a.crossplay_pairs)
    if not v.missing:
        return v
    return dataclasses.replace(exposure_verdict(a, EXPOSURE.name), kind="warning")


def crossplay_headline(a: CaseAnalysis[Any], v: CaseVerdict) -> str:
    """The cross-play mode's verdict in words; one that fell back to the exposure mode's
    says why first."""
    from sumo_ayss.analysis.seeds import SeedComparison

    if v.mode != NAME:
        reason = _gap(a)
        shown = get_mode(v.mode).headline(a, v)
        return f"[{NAME} mode] {reason}. Shown instead, labelled: {shown}"
    assert isinstance(v.top, SeedComparison)
    return crossplay_sentence(v.top, a.crossplay_blocks)


def _companion_lines(a: CaseAnalysis[Any]) -> list[str]:
    """The exposure ranking beside the cross-play one."""
    rows = a.exposure_rows
    if not rows:
        return []
    line = ranking_line([r.name for r in rows], [bool(r.significant_vs_next) for r in rows[:-1]])
    return [f"Ranking (exposure mode), safest first: {line}"]


class CrossplayMode(SeedLevelMode):
    """Cross-play mode: its ranking, verdict and words (see the module docstring)."""

    def available(self, a: CaseAnalysis[Any]) -> bool:
        return bool(a.crossplay_rows)

    def standings(self, a: CaseAnalysis[Any]) -> list[Standing]:
        sentence = functools.partial(crossplay_sentence, blocks=a.crossplay_blocks)
        return seed_standings(a.crossplay_rows, sentence)

    def verdict(self, a: CaseAnalysis[Any]) -> CaseVerdict:
        return crossplay_verdict(a)

    def headline(self, a: CaseAnalysis[Any], v: CaseVerdict) -> str:
        return crossplay_headline(a, v)

    def unit(self, a: CaseAnalysis[Any]) -> str:
        return "harm/episode, pooled SPCPs (lower = safer)"

    def ends(self, a: CaseAnalysis[Any], safest: str, least: str) -> tuple[bool, float]:
        return seed_ends(a.crossplay_pairs, safest, least)

    def companion_lines(self, a: CaseAnalysis[Any]) -> list[str]:
        return _companion_lines(a)

    def gap_text(self, a: CaseAnalysis[Any]) -> str | None:
        return _gap(a)


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
