"""Pairwise verdict between two VUTs from their safety indices (numpy, scipy and the stdlib).

:func:`compare` pairs the bootstrap replicates of two :class:`~.safety_index.SafetyIndex`
and states which VUT is safer, by how much and how sure that is, as a :class:`Verdict`
record (the paper mode words it: :func:`sumo_ayss.modes.paper.verdict_sentence`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from sumo_ayss.analysis.bootstrap import bootstrap_ci
from sumo_ayss.analysis.safety_index import Indicator, SafetyIndex
from sumo_ayss.analysis.stats import cohens_d, welch_t_test
from sumo_ayss.analysis.validate import check_level
from sumo_ayss.util.errors import ConfigError

__all__ = ["Verdict", "compare"]


@dataclass(frozen=True)
class Verdict:
    """Which of two VUTs is safer, by how much, and how sure we are.

    Attributes:
        name_a: Name of VUT A.
        name_b: Name of VUT B.
        safer: Name of the safer VUT, or None for "no significant difference".
        difference: ``index_A - index_B`` in the indicator's unit; positive = A safer. Equal
            to the mean over bins of ``indicator_B - indicator_A``.
        diff_lo: Lower percentile-bootstrap bound of ``difference`` at ``level``.
        diff_hi: Upper bound.
        level: Confidence level.
        p_a_safer: Bootstrap probability that A's index exceeds B's (replicates of the two
            independent bootstraps paired by position; ties count one half).
        cohens_d: Cohen's d of the pooled per-sample indicator in used bins, oriented so
            that positive = A safer: ``(mean(y_B) - mean(y_A)) / s_pooled``. It ignores
            headway and seeds; NaN when undefined.
        significant: Whether the interval of ``difference`` excludes 0.
        p_seed_welch: Two-sided p-value of Welch's t-test on the per-seed indices (seeds as
            the only replication, samples within a seed averaged first). A conservative
            cross-check of ``significant``, which with few seeds and real between-seed
            spread is too optimistic (see :func:`safety_index`). NaN with fewer than two
            seeds on a side or zero spread.
        n_seeds_a: Seeds behind A's index.
        n_seeds_b: Seeds behind B's index.
        h_range: Headway range in m of the two indices.
        same_bins: Whether both indices average over the same headway bins.
        indicator: Naming of the indicator, for the wording of the verdict.
    """

    name_a: str
    name_b: str
    safer: str | None
    difference: float
    diff_lo: float
    diff_hi: float
    level: float
    p_a_safer: float
    cohens_d: float
    significant: bool
    p_seed_welch: float
    n_seeds_a: int
    n_seeds_b: int
    h_range: tuple[float, float]
    same_bins: bool
    indicator: Indicator = field(default_factory=Indicator)


def _check_comparable(a: SafetyIndex, b: SafetyIndex) -> None:
    """Raises ConfigError unless the two indices can be compared replicate by replicate."""
    if a.h_range != b.h_range or a.n_bins != b.n_bins:
        raise ConfigError(
            f"b: h_range/n_bins differ from a's ({b.h_range}, {b.n_bins} vs {a.h_range}, "
            f"{a.n_bins})"
        )
    if a.replicates.size == 0 or a.replicates.shape != b.replicates.shape:
        raise ConfigError(
            f"b: needs as many bootstrap replicates as a ({b.replicates.size} vs "
            f"{a.replicates.size}); build both with safety_index and the same n_boot"
        )


def _oriented_cohens_d(a: SafetyIndex, b: SafetyIndex) -> float:
    """Cohen's d of the negated indicators (positive = A safer), NaN if undefined."""
    ya, yb = a.indicator_samples, b.indicator_samples
    if a.indicator_moments is not None or b.indicator_moments is not None:
        return _moments_cohens_d(_moments(a), _moments(b))
    if ya.size == 0 or yb.size == 0 or ya.size + yb.size < 3:
        return math.nan
    return cohens_d(-ya, -yb)


def _moments(a: SafetyIndex) -> tuple[int, float, float]:
    """``(n, mean, m2)`` of an index's indicator: stored, or of its samples."""
    if a.indicator_moments is not None:
        return a.indicator_moments
    y = a.indicator_samples
    if y.size == 0:
        return 0, math.nan, math.nan
    return int(y.size), float(y.mean()), float(np.sum((y - y.mean()) ** 2))


def _moments_cohens_d(a: tuple[int, float, float], b: tuple[int, float, float]) -> float:
    """:func:`~.stats.cohens_d` of the negated indicators from their moments."""
    (na, ma, sa), (nb, mb, sb) = a, b
    if na == 0 or nb == 0 or na + nb < 3:
        return math.nan
    s_pooled = math.sqrt((sa + sb) / (na + nb - 2))
    return math.nan if s_pooled == 0.0 else (mb - ma) / s_pooled


def _seed_welch_p(a: SafetyIndex, b: SafetyIndex) -> float:
    """Welch p-value on the per-seed indices, NaN when undefined."""
    if len(a.seed_points) < 2 or len(b.seed_points) < 2:
        return math.nan
    return welch_t_test(a.seed_points, b.seed_points)[2]


def compare(
    a: SafetyIndex,
    b: SafetyIndex,
    *,
    name_a: str = "A",
    name_b: str = "B",
    level: float = 0.95,
    indicator: Indicator | None = None,
) -> Verdict:
    """Decides which of two VUTs is safer from their safety indices.

    The bootstrap replicates of the two (independent) indices are paired by position to form
    the distribution of ``index_A - index_B``; its percentile interval at ``level`` decides:
    A is safer if the interval lies above 0, B if below, otherwise there is no significant
    difference.

    Args:
        a: Safety index of VUT A (from :func:`safety_index`).
        b: Safety index of VUT B, same ``h_range``, ``n_bins`` and number of replicates.
        name_a: Name of VUT A in the verdict.
        name_b: Name of VUT B; must differ from ``name_a``.
        level: Confidence level of the interval of the difference, in (0, 1).
        indicator: Naming of the indicator in the verdict; a generic one if None.

    Returns:
        The :class:`Verdict`.

    Raises:
        ConfigError: If the indices are not comparable, the names coincide or ``level`` is
            invalid.
    """
    level = check_level(level)
    if name_a == name_b:
        raise ConfigError(f"name_b: must differ from name_a ({name_a!r})")
    _check_comparable(a, b)
    diffs = a.replicates - b.replicates
    lo, hi = bootstrap_ci(diffs, level)
    safer = name_a if lo > 0.0 else name_b if hi < 0.0 else None
    p_a = float(np.mean(diffs > 0.0) + 0.5 * np.mean(diffs == 0.0))
    return Verdict(
        name_a=name_a,
        name_b=name_b,
        safer=safer,
        difference=a.point - b.point,
        diff_lo=lo,
        diff_hi=hi,
        level=level,
        p_a_safer=p_a,
        cohens_d=_oriented_cohens_d(a, b),
        significant=safer is not None,
        p_seed_welch=_seed_welch_p(a, b),
        n_seeds_a=a.n_seeds,
        n_seeds_b=b.n_seeds,
        h_range=a.h_range,
        same_bins=a.bins_used == b.bins_used,
        indicator=indicator if indicator is not None else Indicator(),
    )
