"""Exposure mode: each VUT's own SPCPs, the mean harm per episode they bring about.

Always available (it reads the runs' outcome tables); a paired t-test over shared seeds.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from sumo_ayss.modes.registry import Mode, Standing, register_mode
from sumo_ayss.modes.seed_level import (
    INTERVAL_NAME,
    no_lines,
    paper_verdict_lines,
    seed_ends,
    seed_interval,
    seed_score_text,
    seed_standings,
    verdict_sentence,
)

if TYPE_CHECKING:
    from sumo_ayss.analysis.case import CaseAnalysis
    from sumo_ayss.analysis.seeds import SeedComparison

__all__ = ["EXPOSURE", "EXPOSURE_SCORE", "exposure_headline", "exposure_sentence"]

NAME = "exposure"

EXPOSURE_SCORE = "bring about {amount} {more_less} harm per episode"
"""How an exposure difference reads in a verdict sentence."""


def exposure_sentence(c: SeedComparison) -> str:
    """The exposure-mode verdict sentence of one comparison."""
    return verdict_sentence(
        c, higher_is_safer=False, score=EXPOSURE_SCORE, unit="", mode=NAME, digits=3
    )


def exposure_headline(out: CaseAnalysis) -> None:
    """Headline and ranking line of the exposure mode."""
    from sumo_ayss.analysis.seeds import seed_ranking_line

    rows = out.exposure_rows
    if len(rows) < 2:
        out.headline = "[exposure mode] No verdict yet: a verdict needs outcomes of two VUTs."
        out.headline_kind = "warning"
        out.ranking_line = rows[0].name if rows else ""
        return
    top = rows[0].vs_next
    assert top is not None
    out.headline = exposure_sentence(top)
    out.headline_kind = "safer" if top.significant else "none"
    if out.info.exposure_caution:
        out.headline += " " + out.info.exposure_caution
        out.headline_kind = "warning"
    out.ranking_line = seed_ranking_line(rows)


def _standings(a: CaseAnalysis) -> list[Standing]:
    return seed_standings(a.exposure_rows, exposure_sentence)


EXPOSURE = register_mode(
    Mode(
        name=NAME,
        description=(
            "Exposure mode: a VUT's score is the mean harm per episode its own SPCPs bring "
            "about over the common outcome scenarios (the same scenarios for every VUT and "
            "seed; harm as in cross-play mode); a lower score is a safer VUT. Each training "
            "seed's SPCP is one observation; seeds are shared across VUTs (same seed "
            "values), so two VUTs are compared by a paired t-test on their per-seed "
            "differences (Welch's t-test when the seed sets differ); significant when p < "
            "alpha."
        ),
        score_name="exposure harm per episode (lower = safer)",
        interval_name=INTERVAL_NAME,
        digits=3,
        available=lambda a: bool(a.exposure_rows),
        standings=_standings,
        headline=exposure_headline,
        unit=lambda a: "harm/episode, own SPCPs (lower = safer)",
        ends=lambda a, safest, least: seed_ends(a.exposure_pairs, safest, least),
        score_text=seed_score_text,
        interval_text=seed_interval,
        companion_lines=no_lines,
        closing_lines=paper_verdict_lines,
    )
)
