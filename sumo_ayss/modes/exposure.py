"""Exposure mode: each VUT's own SPCPs, the mean harm per episode they bring about.

Always available (it reads the runs' outcome tables); a paired t-test over shared seeds.
Its result (:class:`ExposureResult`, computed from the runs by :func:`compute_exposure`) is
the seed-level ranking, its comparisons, the per-seed scores and the crash counts.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from sumo_ayss.modes.registry import Standing, mode_result, register_mode
from sumo_ayss.modes.seed_level import (
    INTERVAL_NAME,
    SeedLevelMode,
    seed_ends,
    seed_standings,
    verdict_sentence,
)

if TYPE_CHECKING:
    from sumo_ayss.analysis.case import CaseAnalysis
    from sumo_ayss.analysis.case_verdict import CaseVerdict
    from sumo_ayss.analysis.harm import VutOutcome
    from sumo_ayss.analysis.seeds import SeedComparison, SeedRankRow

__all__ = [
    "EXPOSURE",
    "EXPOSURE_SCORE",
    "ExposureMode",
    "ExposureResult",
    "compute_exposure",
    "exposure_headline",
    "exposure_result",
    "exposure_sentence",
    "exposure_verdict",
]

NAME = "exposure"

EXPOSURE_SCORE = "bring about {amount} {more_less} harm per episode"
"""How an exposure difference reads in a verdict sentence."""


@dataclass(frozen=True)
class ExposureResult:
    """The exposure mode's result for one case.

    Attributes:
        rows: The ranking, safest first (empty without an outcome table with a seed).
        pairs: Comparisons of every pair (A ranked above B).
        scores: ``{vut: {seed: E}}``, the per-seed exposures behind the ranking.
        outcomes: ``{vut: VutOutcome}``: crashes with their interval and mobility over the
            VUT's own SPCPs' outcome episodes, shown beside the score.
    """

    rows: list[SeedRankRow] = field(default_factory=list)
    pairs: list[SeedComparison] = field(default_factory=list)
    scores: dict[str, dict[int, float]] = field(default_factory=dict)
    outcomes: dict[str, VutOutcome] = field(default_factory=dict)


def compute_exposure(a: CaseAnalysis[Any]) -> ExposureResult:
    """Exposure ranking of a case: each VUT's own SPCPs, the mean harm of their outcome
    episodes per seed (:func:`sumo_ayss.analysis.harm.run_episodes`), ranked by
    :func:`sumo_ayss.analysis.seeds.rank_seeds`; a run whose table does not fit its scale,
    and a VUT without a table, get a line in ``a.problems``."""
    import numpy as np

    from sumo_ayss.analysis.case import run_label
    from sumo_ayss.analysis.harm import HARM_RANGE, run_episodes, vut_outcomes
    from sumo_ayss.analysis.seeds import SeedScores, rank_seeds
    from sumo_ayss.util.errors import ConfigError

    options = a.options
    scores = []
    counts: dict[str, tuple[int, int, float]] = {}
    for vut, members in a.runs.items():
        done = []
        for r in members:
            try:
                episodes = run_episodes(r)
            except ConfigError as exc:  # the table does not fit the run's scale
                a.problems.append(f"{run_label(r)}: outcome.csv unreadable ({exc})")
                continue
            if r.seed is not None and episodes is not None:
                done.append((r.seed, episodes))
        if done:
            scores.append(SeedScores(vut, {seed: e.mean_harm for seed, e in done}))
            counts[vut] = (
                sum(e.crashes for _, e in done),
                sum(e.n for _, e in done),
                float(np.mean([e.mobility for _, e in done])),
            )
        else:
            a.problems.append(f"{vut}: no outcome table with a seed, so no exposure")
    if not scores:
        return ExposureResult(outcomes=vut_outcomes(counts, options.level) if counts else {})
    rows, pairs = rank_seeds(
        scores,
        higher_is_safer=False,
        level=options.level,
        alpha=options.welch_alpha,
        bounds=HARM_RANGE,
    )
    return ExposureResult(
        rows=rows,
        pairs=pairs,
        scores={sc.name: dict(sc.values) for sc in scores},
        outcomes=vut_outcomes(counts, options.level),
    )


def exposure_result(a: CaseAnalysis[Any], name: str = NAME) -> ExposureResult:
    """The exposure result of a case (that of the mode ``name``, built from this record)."""
    return mode_result(a, name, ExposureResult)


def exposure_sentence(c: SeedComparison) -> str:
    """The exposure-mode verdict sentence of one comparison."""
    return verdict_sentence(
        c, higher_is_safer=False, score=EXPOSURE_SCORE, unit="", mode=NAME, digits=3
    )


def exposure_verdict(a: CaseAnalysis[Any], name: str = NAME) -> CaseVerdict:
    """The exposure mode's verdict, ranked under ``name`` (a plug-in built from this
    record ranks under its own name)."""
    from sumo_ayss.analysis.case_verdict import seed_verdict

    caution = bool(a.info.exposure_caution)
    result = exposure_result(a, name)
    return seed_verdict(name, result.rows, result.pairs, caution=caution)


def exposure_headline(a: CaseAnalysis[Any], v: CaseVerdict) -> str:
    """The exposure mode's verdict in words."""
    from sumo_ayss.analysis.seeds import SeedComparison

    if not isinstance(v.top, SeedComparison):
        return f"[{NAME} mode] No verdict yet: a verdict needs outcomes of two VUTs."
    text = exposure_sentence(v.top)
    if v.caveat == "case_caution":
        text += " " + a.info.exposure_caution
    return text


class ExposureMode(SeedLevelMode):
    """Exposure mode: its ranking, verdict and words (see the module docstring)."""

    def compute(self, a: CaseAnalysis[Any]) -> ExposureResult:
        return compute_exposure(a)

    def available(self, a: CaseAnalysis[Any]) -> bool:
        return bool(exposure_result(a, self.name).rows)

    def standings(self, a: CaseAnalysis[Any]) -> list[Standing]:
        return seed_standings(exposure_result(a, self.name).rows, exposure_sentence)

    def verdict(self, a: CaseAnalysis[Any]) -> CaseVerdict:
        return exposure_verdict(a, self.name)

    def outcomes(self, a: CaseAnalysis[Any]) -> Mapping[str, VutOutcome]:
        return exposure_result(a, self.name).outcomes

    def headline(self, a: CaseAnalysis[Any], v: CaseVerdict) -> str:
        return exposure_headline(a, v)

    def unit(self, a: CaseAnalysis[Any]) -> str:
        return "harm/episode, own SPCPs (lower = safer)"

    def ends(self, a: CaseAnalysis[Any], safest: str, least: str) -> tuple[bool, float]:
        return seed_ends(exposure_result(a, self.name).pairs, safest, least)


EXPOSURE = register_mode(
    ExposureMode(
        name=NAME,
        description=(
            "Exposure mode: a VUT's score is the mean harm per episode its own SPCPs bring "
            "about over the common outcome scenarios (the same scenarios for every VUT and "
            "seed; harm as in cross-play mode); a lower score is a safer VUT. Each training "
            "seed's SPCP is one observation; seeds are shared across VUTs (same seed "
            "values), so two VUTs are compared by a paired t-test on their per-seed "
            "differences (Welch's t-test when the seed sets differ); a VUT is called safer "
            "than the next when that p, adjusted by Holm over the ranking's adjacent pairs, "
            "is below the significance level (0.05 unless configured)."
        ),
        score_name="exposure harm per episode (lower = safer)",
        interval_name=INTERVAL_NAME,
        digits=3,
    )
)
