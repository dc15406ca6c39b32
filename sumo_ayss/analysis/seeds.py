"""Seed-level comparison and ranking of VUTs (numpy, scipy and the stdlib).

One training seed of one VUT gives one SPCP; its score (a scalar, e.g. the mean harm per
episode it brings about over the common outcome scenarios) is **one observation**. Samples inside
a seed (episodes, AYSS draws) are not independent replications of the VUT's safety: they
share that seed's training, so only seeds carry the run-to-run spread.

The pipeline gives job (case, VUT, seed ``s``) the same ``s`` for every VUT: the network's
initialisation, SUMO's seed, the exploration stream and the first initial conditions are
shared. Seeds are therefore **blocks**: when two VUTs were trained on the same seed set, the
per-seed differences are compared (paired t-test), which removes the part of the seed noise
that moves every VUT together (seen on a minGap ladder: one seed below another for all four
VUTs). With different seed sets the comparison falls back to Welch's t-test.

Significance rule (:func:`compare_seeds`): two-sided p < ``alpha`` of that t-test, whose
interval at ``level = 1 - alpha`` then excludes 0. Under normal seed-level errors the
paired test is exact, so with no true difference it calls a difference in ``alpha`` of cases
(checked on synthetic data in ``tests/analysis/test_seeds.py``). In a ranking
(:func:`rank_seeds`) the claims against the next VUT form one family, adjusted by Holm's
procedure (:mod:`.multiplicity`), so that all of a leaderboard's "safer than" claims together
are wrong with probability at most ``alpha``.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from sumo_ayss.analysis.multiplicity import chain_adjusted
from sumo_ayss.analysis.seed_intervals import (
    MIN_SEEDS_FOR_INTERVAL,
    UNBOUNDED,
    Bounds,
    clip_interval,
    seed_mean_ci,
)
from sumo_ayss.analysis.stats import check_level, student_t_sf, t_quantile
from sumo_ayss.util.errors import ConfigError

__all__ = [
    "SeedComparison",
    "SeedRankRow",
    "SeedScores",
    "compare_seeds",
    "kendall_tau",
    "rank_seeds",
]

SeedTest = Literal["paired t", "Welch t", "none"]


@dataclass(frozen=True)
class SeedScores:
    """One VUT's score per training seed.

    Attributes:
        name: VUT name.
        values: Training seed -> score of that seed's SPCP, in the score's unit. Finite.
    """

    name: str
    values: Mapping[int, float]

    def __post_init__(self) -> None:
        clean: dict[int, float] = {}
        for seed, value in self.values.items():
            v = float(value)
            if not math.isfinite(v):
                raise ConfigError(f"{self.name}: score of seed {seed} is not finite ({value!r})")
            clean[int(seed)] = v
        if not clean:
            raise ConfigError(f"{self.name}: no seed scores")
        object.__setattr__(self, "values", dict(sorted(clean.items())))

    @property
    def seeds(self) -> tuple[int, ...]:
        """The seeds, ascending."""
        return tuple(self.values)

    @property
    def array(self) -> np.ndarray:
        """Scores in seed order, shape ``(n_seeds,)``."""
        return np.fromiter(self.values.values(), dtype=np.float64)

    def mean_ci(
        self, level: float = 0.95, bounds: Bounds = UNBOUNDED
    ) -> tuple[float, float, float]:
        """``(mean, lo, hi)``: the seed mean with its t-interval clipped to ``bounds`` (NaN
        bounds with fewer than three seeds, :func:`.seed_intervals.seed_mean_ci`)."""
        return seed_mean_ci(self.array, level, bounds=bounds)


@dataclass(frozen=True)
class SeedComparison:
    """``A - B`` at the seed level, with its test.

    Attributes:
        name_a: VUT A.
        name_b: VUT B.
        difference: Mean of A minus mean of B (paired: mean per-seed difference), in the
            score's unit.
        lo: Lower bound of the t-interval of ``difference`` at ``level``; NaN if undefined.
        hi: Upper bound.
        p: Two-sided p-value of the test; NaN if undefined (fewer than two seeds, or no
            spread at all).
        test: ``"paired t"`` (same seed set, >= 2 seeds), ``"Welch t"`` (different seed
            sets, >= 2 seeds each) or ``"none"``.
        n_a: Seeds of A.
        n_b: Seeds of B.
        level: Confidence level of the interval.
        alpha: Significance threshold of ``p`` (of ``p_family`` when there is one).
        p_family: ``p`` adjusted for the family of claims of the ranking it belongs to
            (:func:`~.multiplicity.chain_adjusted`: Holm over the adjacent pairs); None for
            a comparison made on its own (then ``p`` decides).
        family_size: Tests in that family (the ranking's adjacent pairs with a test); 0
            without a family.
    """

    name_a: str
    name_b: str
    difference: float
    lo: float
    hi: float
    p: float
    test: SeedTest
    n_a: int
    n_b: int
    level: float
    alpha: float
    p_family: float | None = None
    family_size: int = 0

    @property
    def p_decision(self) -> float:
        """The p that decides significance: ``p_family`` in a ranking, else ``p``."""
        return self.p if self.p_family is None else self.p_family

    @property
    def significant(self) -> bool:
        """Whether the deciding p (:attr:`p_decision`) is below ``alpha``."""
        return math.isfinite(self.p_decision) and self.p_decision < self.alpha

    def a_higher(self) -> bool | None:
        """True if A's score is significantly higher, False if lower, None if neither."""
        if not self.significant:
            return None
        return self.difference > 0


def compare_seeds(
    a: SeedScores,
    b: SeedScores,
    *,
    level: float = 0.95,
    alpha: float = 0.05,
    bounds: Bounds = UNBOUNDED,
) -> SeedComparison:
    """Compares two VUTs' per-seed scores: paired t over shared seeds, else Welch.

    The interval of ``A - B`` follows the per-VUT intervals' two rules
    (:mod:`.seed_intervals`): none with fewer than :data:`MIN_SEEDS_FOR_INTERVAL` seeds on
    either side (the test's p is still given, with its few degrees of freedom), and never
    past what a difference of two scores in ``bounds`` can be (``±(high - low)``).

    Args:
        a: Scores of VUT A.
        b: Scores of VUT B.
        level: Confidence level of the interval of ``A - B``, in (0, 1).
        alpha: Significance threshold, in (0, 1).
        bounds: The score's possible range (``(0, 1)`` for harm per episode).

    Returns:
        The :class:`SeedComparison`.

    Raises:
        ConfigError: If ``level`` or ``alpha`` is not in (0, 1) or the names coincide.
    """
    level = check_level(level)
    alpha = check_level(alpha, "alpha")
    if a.name == b.name:
        raise ConfigError(f"b.name: must differ from a.name ({a.name!r})")
    c = _compare(a, b, level, alpha)
    if min(c.n_a, c.n_b) < MIN_SEEDS_FOR_INTERVAL:
        return dataclasses.replace(c, lo=math.nan, hi=math.nan)
    width = float(bounds[1]) - float(bounds[0])
    lo, hi = clip_interval(c.lo, c.hi, (-width, width) if math.isfinite(width) else UNBOUNDED)
    return dataclasses.replace(c, lo=lo, hi=hi)


def _compare(a: SeedScores, b: SeedScores, level: float, alpha: float) -> SeedComparison:
    """:func:`compare_seeds` before its interval rules."""
    xa, xb = a.array, b.array
    diff = float(xa.mean() - xb.mean())
    nan = math.nan
    q = 0.5 * (1.0 + level)
    if a.seeds == b.seeds and len(a.seeds) >= 2:
        d = xa - xb
        n = d.size
        se = float(d.std(ddof=1)) / math.sqrt(n)
        if se == 0.0:
            return SeedComparison(
                a.name, b.name, diff, nan, nan, nan, "paired t", n, n, level, alpha
            )
        half = t_quantile(q, n - 1) * se
        p = min(1.0, 2.0 * student_t_sf(abs(diff) / se, n - 1))
        return SeedComparison(
            a.name, b.name, diff, diff - half, diff + half, p, "paired t", n, n, level, alpha
        )
    if xa.size >= 2 and xb.size >= 2:
        va, vb = float(xa.var(ddof=1)) / xa.size, float(xb.var(ddof=1)) / xb.size
        if va + vb == 0.0:
            return SeedComparison(
                a.name, b.name, diff, nan, nan, nan, "Welch t", xa.size, xb.size, level, alpha
            )
        se = math.sqrt(va + vb)
        df = (va + vb) ** 2 / (va**2 / (xa.size - 1) + vb**2 / (xb.size - 1))
        half = t_quantile(q, df) * se
        p = min(1.0, 2.0 * student_t_sf(abs(diff) / se, df))
        return SeedComparison(
            a.name,
            b.name,
            diff,
            diff - half,
            diff + half,
            p,
            "Welch t",
            xa.size,
            xb.size,
            level,
            alpha,
        )
    return SeedComparison(
        a.name, b.name, diff, nan, nan, nan, "none", xa.size, xb.size, level, alpha
    )


@dataclass(frozen=True)
class SeedRankRow:
    """One row of a seed-level ranking, safest first.

    Attributes:
        rank: 1 for the safest.
        name: VUT name.
        mean: Seed mean of the score.
        lo: Lower bound of its t-interval over seeds, clipped to the score's possible range
            (NaN with fewer than three seeds: :data:`.seed_intervals.MIN_SEEDS_FOR_INTERVAL`).
        hi: Upper bound.
        n_seeds: Seeds behind the mean.
        vs_next: Comparison with the next row (this VUT as A), None for the last row.
    """

    rank: int
    name: str
    mean: float
    lo: float
    hi: float
    n_seeds: int
    vs_next: SeedComparison | None

    @property
    def significant_vs_next(self) -> bool | None:
        """Whether this VUT is significantly safer than the next one (None for the last)."""
        return None if self.vs_next is None else self.vs_next.significant


def rank_seeds(
    scores: Sequence[SeedScores],
    *,
    higher_is_safer: bool,
    level: float = 0.95,
    alpha: float = 0.05,
    bounds: Bounds = UNBOUNDED,
) -> tuple[list[SeedRankRow], list[SeedComparison]]:
    """Orders VUTs from safest to least safe by their seed-mean score.

    Args:
        scores: One :class:`SeedScores` per VUT (distinct names).
        higher_is_safer: Orientation of the score (False for harm, where a lower score
            means the SPCP brought about less against the VUT).
        level: Confidence level of every interval.
        alpha: Significance threshold of every comparison.
        bounds: The score's possible range (``(0, 1)`` for harm per episode); each row's
            interval is clipped to it.

    Returns:
        ``(rows, pairs)``: the ranking, safest first (ties broken by name), and the
        comparison of every pair in ranking order (A ranked above B). Every comparison
        carries its family-adjusted p (:func:`~.multiplicity.chain_adjusted`: Holm over the
        adjacent pairs, a pair further apart claimed through the chain between them), which
        decides its ``significant``; the raw ``p`` stays beside it.

    Raises:
        ConfigError: If ``scores`` is empty or names repeat.
    """
    if not scores:
        raise ConfigError("scores: expected at least one VUT")
    names = [s.name for s in scores]
    if len(set(names)) != len(names):
        raise ConfigError(f"scores: duplicate VUT names {names}")
    sign = -1.0 if higher_is_safer else 1.0
    order = sorted(scores, key=lambda s: (sign * float(s.array.mean()), s.name))
    raw = {
        (a.name, b.name): compare_seeds(a, b, level=level, alpha=alpha, bounds=bounds)
        for a, b in itertools.combinations(order, 2)
    }
    names_in_order = [s.name for s in order]
    adjacent = [raw[pair] for pair in itertools.pairwise(names_in_order)]
    family = chain_adjusted(names_in_order, [c.p for c in adjacent])
    size = sum(math.isfinite(c.p) for c in adjacent)
    pairs = [
        dataclasses.replace(c, p_family=family[key], family_size=size) for key, c in raw.items()
    ]
    by_pair = {(p.name_a, p.name_b): p for p in pairs}
    rows = []
    for pos, s in enumerate(order):
        mean, lo, hi = s.mean_ci(level, bounds)
        nxt = by_pair.get((s.name, order[pos + 1].name)) if pos + 1 < len(order) else None
        rows.append(SeedRankRow(pos + 1, s.name, mean, lo, hi, len(s.values), nxt))
    return rows, pairs


def kendall_tau(order: Sequence[str], truth: Sequence[str]) -> float:
    """Kendall's τ between a ranking and the true order (both safest first, same names).

    Returns:
        τ in [-1, 1]: 1 when the orders agree on every pair, -1 when reversed.

    Raises:
        ConfigError: If the two sequences are not permutations of the same >= 2 names.
    """
    if sorted(order) != sorted(truth) or len(set(order)) != len(order) or len(order) < 2:
        raise ConfigError(f"order {list(order)} and truth {list(truth)}: not the same names")
    pos = {name: i for i, name in enumerate(order)}
    concordant = discordant = 0
    for x, y in itertools.combinations(truth, 2):  # x truly safer than y
        if pos[x] < pos[y]:
            concordant += 1
        else:
            discordant += 1
    return (concordant - discordant) / (concordant + discordant)
