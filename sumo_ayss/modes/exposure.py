"""Exposure mode: each VUT's own SPCPs, the mean harm per episode they bring about.

Always available (it reads the runs' outcome tables); a paired t-test over shared seeds.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from sumo_ayss.modes.registry import Standing, register_mode
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
    from sumo_ayss.analysis.seeds import SeedComparison

__all__ = [
    "EXPOSURE",
    "EXPOSURE_SCORE",
    "ExposureMode",
    "exposure_headline",
    "exposure_sentence",
    "exposure_verdict",
]

NAME = "exposure"

EXPOSURE_SCORE = "bring about {amount} {more_less} harm per episode"
"""How an exposure difference reads in a verdict sentence."""


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
    return seed_verdict(name, a.exposure_rows, a.exposure_pairs, caution=caution)


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

    def available(self, a: CaseAnalysis[Any]) -> bool:
        return bool(a.exposure_rows)

    def standings(self, a: CaseAnalysis[Any]) -> list[Standing]:
        return seed_standings(a.exposure_rows, exposure_sentence)

    def verdict(self, a: CaseAnalysis[Any]) -> CaseVerdict:
        return exposure_verdict(a, a.mode)

    def headline(self, a: CaseAnalysis[Any], v: CaseVerdict) -> str:
        return exposure_headline(a, v)

    def unit(self, a: CaseAnalysis[Any]) -> str:
        return "harm/episode, own SPCPs (lower = safer)"

    def ends(self, a: CaseAnalysis[Any], safest: str, least: str) -> tuple[bool, float]:
        return seed_ends(a.exposure_pairs, safest, least)


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
