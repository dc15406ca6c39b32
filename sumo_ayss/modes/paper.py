"""Paper mode: the paper's indicator, the aggressiveness of the SPCP's action in the
adversarial-yet-safe states, condensed into a safety index over headway bins
(:mod:`sumo_ayss.analysis.safety_index`; hierarchical bootstrap, the slow part).

Its headline is computed for every report (``CaseAnalysis.paper_headline``); a ranking
in this mode lists it only when it was asked for.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from sumo_ayss.modes.registry import Mode, Standing, register_mode
from sumo_ayss.modes.seed_level import no_lines

if TYPE_CHECKING:
    from sumo_ayss.analysis.case import CaseAnalysis

__all__ = ["PAPER"]

NAME = "paper"


def _standings(a: CaseAnalysis) -> list[Standing]:
    pairs = {(p.verdict.name_a, p.verdict.name_b): p for p in a.pairs}
    order = [r.name for r in a.ranking]
    out = []
    for i, ranked in enumerate(a.ranking):
        nxt = order[i + 1] if i + 1 < len(order) else None
        pair = pairs.get((ranked.name, nxt)) if nxt else None
        out.append(
            Standing(
                rank=ranked.rank,
                vut=ranked.name,
                score=ranked.point,
                lo=ranked.lo,
                hi=ranked.hi,
                n_seeds=ranked.n_seeds,
                next_vut=nxt,
                significant=pair.significant if pair else None,
                ranked_apart=bool(ranked.significant_vs_next),
                p=pair.verdict.p_seed_welch if pair else None,
                test="Welch t" if pair else "",
                # Tagged like the seed-level modes' sentences ("[exposure mode] ...").
                vs_next=f"[paper mode] {pair.sentence}" if pair else "",
            )
        )
    return out


def _ends(a: CaseAnalysis, safest: str, least: str) -> tuple[bool, float]:
    pair = next(
        (p for p in a.pairs if {p.verdict.name_a, p.verdict.name_b} == {safest, least}),
        None,
    )
    return pair is not None and pair.safer == safest, math.nan


def _score_text(a: CaseAnalysis, s: Standing) -> str:
    from sumo_ayss.analysis.formatting import fmt_interval, fmt_num

    ci = fmt_interval(s.lo, s.hi)
    return f"{fmt_num(s.score)} {a.info.indicator.unit}" + (f" ({ci})" if ci else "")


def _interval_text(lo: float, hi: float, n_seeds: int, digits: int) -> str:
    from sumo_ayss.analysis.formatting import fmt_interval

    return fmt_interval(lo, hi, digits)


def _headline(a: CaseAnalysis) -> None:
    """The headline is already the paper mode's (computed first, for every report)."""


PAPER = register_mode(
    Mode(
        name=NAME,
        description=(
            "Paper mode: the paper's indicator, the aggressiveness of the SPCP's action in the "
            "adversarial-yet-safe states (POV acceleration in car-following, Δv̄ in cut-in), "
            "condensed into a safety index over headway bins; meaningful only when the SPCPs "
            "reached the same overall outcome (the premise check)."
        ),
        score_name="safety index (higher = safer)",
        interval_name="bootstrap interval",
        digits=2,
        # Ranked in paper mode only: the bootstrap is skipped in the other modes.
        available=lambda a: bool(a.ranking) and a.mode == NAME,
        standings=_standings,
        headline=_headline,
        unit=lambda a: f"{a.info.indicator.unit} (higher = safer)",
        ends=_ends,
        score_text=_score_text,
        interval_text=_interval_text,
        companion_lines=no_lines,
        closing_lines=no_lines,
        needs_safety_index=True,
    )
)
