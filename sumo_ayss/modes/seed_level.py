"""What the seed-level modes (cross-play, exposure) share: a ranking of seed means with a
t-test against the next VUT (:class:`~sumo_ayss.analysis.seeds.SeedRankRow`), and how a
comparison of seed-level scores reads (:func:`verdict_sentence`).

The hooks here import the analysis when called, so that the registry stays light.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from sumo_ayss.modes.formatting import (
    fmt_interval,
    fmt_num,
    fmt_p_family,
    ranking_line,
    seed_interval_text,
)
from sumo_ayss.modes.registry import Mode, Standing, get_mode

if TYPE_CHECKING:
    from sumo_ayss.analysis.case import CaseAnalysis
    from sumo_ayss.analysis.seeds import SeedComparison, SeedRankRow

__all__ = [
    "INTERVAL_NAME",
    "SeedLevelMode",
    "no_lines",
    "paper_verdict_lines",
    "seed_ends",
    "seed_interval",
    "seed_score_text",
    "seed_standings",
    "verdict_sentence",
]

#: What a seed-level score's interval is.
INTERVAL_NAME = "t-interval over seeds"


def verdict_sentence(
    c: SeedComparison,
    *,
    higher_is_safer: bool,
    score: str,
    unit: str,
    mode: str,
    digits: int = 2,
) -> str:
    """One quotable sentence for a seed-level comparison.

    Args:
        c: The comparison (A ranked above B).
        higher_is_safer: Orientation of the score.
        score: What the score is, as "their SPCPs ..." completes it, e.g.
            ``"bring about {amount} {more_less} harm per episode"`` with ``{amount}`` and
            ``{more_less}`` filled in here.
        unit: Unit appended to the amount ("" for none).
        mode: Analysis mode named at the start of the sentence.
        digits: Decimals of the amount and its interval.
    """
    pct = f"{100 * c.level:g} %"
    if c.test == "paired t":
        df = c.n_a - 1
        how = (
            f"paired t-test over {c.n_a} shared seeds ({df} degree{'s' if df != 1 else ''} "
            "of freedom)"
        )
    elif c.test == "Welch t":
        how = f"Welch t-test, {c.n_a} vs {c.n_b} seeds"
    else:
        how = f"no test: {c.n_a} vs {c.n_b} seeds"
    # Stated as "B's SPCPs <score> than A's" (A ranked safer), with the interval of the
    # stated amount: of B - A when B scores higher, of A - B otherwise.
    b_higher = c.difference < 0
    lo, hi = (-c.hi, -c.lo) if b_higher else (c.lo, c.hi)
    ci = fmt_interval(lo, hi, digits)
    n = min(c.n_a, c.n_b)
    if ci:
        ci = f"{pct} CI {ci}"
    elif n < 3:  # :data:`sumo_ayss.analysis.seed_intervals.MIN_SEEDS_FOR_INTERVAL`
        ci = f"no interval with {n} seed{'s' if n != 1 else ''}"
    else:
        ci = "interval undefined"
    p = fmt_p_family(c.p, c.p_family, c.family_size, undefined="undefined")
    stats = f"{ci}; {how}, {p}"
    amount = fmt_num(abs(c.difference), digits, minus="-", missing="nan")
    amount += f" {unit}" if unit else ""
    what = score.format(amount=amount, more_less="more" if b_higher else "less")
    if c.significant and (c.difference > 0) == higher_is_safer:
        return (
            f"[{mode} mode] {c.name_a} is safer than {c.name_b}: {c.name_b}'s SPCPs {what} "
            f"than {c.name_a}'s ({stats})."
        )
    return (
        f"[{mode} mode] No significant difference in safety between {c.name_a} and "
        f"{c.name_b}: {c.name_b}'s SPCPs {what} than {c.name_a}'s ({stats})."
    )


def seed_standings(
    rows: Sequence[SeedRankRow],
    sentence: Callable[[SeedComparison], str],
    *,
    higher_is_safer: bool = False,
) -> list[Standing]:
    """:class:`Standing` rows of a seed-level ranking; ``sentence`` words a comparison.

    ``higher_is_safer`` orients the margin against the next VUT (harm: lower is safer, so
    the margin is the next VUT's score minus this one's)."""
    out = []
    for i, r in enumerate(rows):
        c = r.vs_next
        sign = 1.0 if higher_is_safer else -1.0
        margin = (math.nan, math.nan, math.nan)
        if c is not None:
            bounds = sorted((sign * c.lo, sign * c.hi))
            margin = (sign * c.difference, bounds[0], bounds[1])
        out.append(
            Standing(
                rank=r.rank,
                vut=r.name,
                score=r.mean,
                lo=r.lo,
                hi=r.hi,
                n_seeds=r.n_seeds,
                next_vut=rows[i + 1].name if i + 1 < len(rows) else None,
                significant=c.significant if c is not None else None,
                ranked_apart=bool(r.significant_vs_next),
                p=c.p if c is not None else None,
                p_adjusted=c.p_decision if c is not None else None,
                test=c.test if c is not None else "",
                n_a=c.n_a if c is not None else 0,
                n_b=c.n_b if c is not None else 0,
                vs_next=sentence(c) if c is not None else "",
                margin=margin[0],
                margin_lo=margin[1],
                margin_hi=margin[2],
            )
        )
    return out


def seed_ends(comparisons: Sequence[SeedComparison], safest: str, least: str) -> tuple[bool, float]:
    """Whether ``safest`` is found significantly safer than ``least``, and the p-value.

    The known ends are declared before the data are seen: one pre-specified test, so its
    raw p decides (no family; the ranking's own claims are adjusted,
    :mod:`sumo_ayss.analysis.multiplicity`).
    """
    ends = {frozenset((c.name_a, c.name_b)): c for c in comparisons}
    end_cmp = ends.get(frozenset((safest, least)))
    found = (
        end_cmp is not None
        and math.isfinite(end_cmp.p)
        and end_cmp.p < end_cmp.alpha
        and end_cmp.name_a == safest  # ranked above, i.e. found safer
    )
    return found, end_cmp.p if end_cmp is not None else math.nan


def seed_interval(lo: float, hi: float, n_seeds: int, digits: int) -> str:
    """A seed-level interval as ``ranking.md`` writes it."""
    return seed_interval_text(lo, hi, n_seeds, digits)


def seed_score_text(a: CaseAnalysis[Any], s: Standing) -> str:
    """A seed-level score with its interval, three decimals, as the leaderboard writes it."""
    return f"{fmt_num(s.score, 3)} ({seed_interval(s.lo, s.hi, s.n_seeds, 3)})"


def paper_verdict_lines(a: CaseAnalysis[Any]) -> list[str]:
    """The paper mode's verdict, closing the callout of a mode that is not the paper's."""
    from sumo_ayss.modes.paper import paper_result

    v = paper_result(a).verdict
    line = get_mode(v.mode).headline(a, v)
    if v.order:
        line += f" Ranking ({v.mode} mode): {ranking_line(v.order, v.apart)}."
    return [line]


def no_lines(a: CaseAnalysis[Any]) -> list[str]:
    """No further verdict lines."""
    return []


class SeedLevelMode(Mode):
    """A mode whose score is a per-seed mean compared by a paired test over seeds (exposure,
    cross-play): its interval and score read alike, and its callout closes with the paper
    mode's verdict."""

    def score_text(self, a: CaseAnalysis[Any], s: Standing) -> str:
        return seed_score_text(a, s)

    def interval_text(self, lo: float, hi: float, n_seeds: int, digits: int) -> str:
        return seed_interval(lo, hi, n_seeds, digits)

    def closing_lines(self, a: CaseAnalysis[Any]) -> list[str]:
        return paper_verdict_lines(a)
