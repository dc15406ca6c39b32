"""Confidence intervals, t-tests and effect sizes for AYSS indicators (numpy and scipy).

* :func:`student_t_sf`, :func:`t_quantile` — Student's t distribution (``scipy.stats.t``),
  with our argument checks.
* :func:`welch_t_test` — two-sided unequal-variance test of equal means.
* :func:`mean_ci` — mean with a Student t interval.
* :func:`binned_mean_ci` — per-bin means with t intervals, e.g. indicator vs headway.
* :func:`cohens_d` — standardised mean difference with the pooled standard deviation.

Re-exported from their modules: the bootstraps (:mod:`.bootstrap`) and the argument checks
(:mod:`.validate`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from statistics import NormalDist

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import stats as _scipy_stats

from sumo_ayss.analysis.bootstrap import RngLike, bootstrap_ci, hierarchical_bootstrap
from sumo_ayss.analysis.validate import check_level, finite_1d, is_real
from sumo_ayss.util.errors import ConfigError

__all__ = [
    "BinnedStats",
    "RngLike",
    "bin_index",
    "binned_mean_ci",
    "bootstrap_ci",
    "check_edges",
    "check_level",
    "cohens_d",
    "hierarchical_bootstrap",
    "mean_ci",
    "student_t_sf",
    "t_quantile",
    "welch_t_test",
    "wilson_interval",
]


# --------------------------------------------------------------------------- Student t


def _check_df(df: float) -> float:
    if not is_real(df) or not df > 0.0:
        raise ConfigError(f"df: expected a positive number, got {df!r}")
    return float(df)


def student_t_sf(t: float, df: float) -> float:
    """Upper tail P(T > t) of Student's t distribution (``scipy.stats.t.sf``).

    Args:
        t: Quantile (dimensionless).
        df: Degrees of freedom, > 0 (non-integer allowed; ``math.inf`` gives the normal).

    Returns:
        The survival function at ``t``, in [0, 1].

    Raises:
        ConfigError: If ``df`` is not positive.
    """
    return float(_scipy_stats.t.sf(t, _check_df(df)))


def t_quantile(p: float, df: float) -> float:
    """Quantile function of Student's t distribution, t_{p, df} (``scipy.stats.t.ppf``).

    Args:
        p: Probability in (0, 1).
        df: Degrees of freedom, > 0 (non-integer allowed; ``math.inf`` gives the normal).

    Returns:
        The value t with P(T <= t) = p (dimensionless).

    Raises:
        ConfigError: If ``p`` is not in (0, 1) or ``df`` is not positive.
    """
    p = check_level(p, "p")
    return float(_scipy_stats.t.ppf(p, _check_df(df)))


def welch_t_test(x: ArrayLike, y: ArrayLike) -> tuple[float, float, float]:
    """Welch's unequal-variance t-test of ``mean(x) = mean(y)``, two-sided.

    Args:
        x: First sample, shape ``(n_x,)``, finite, n_x >= 2.
        y: Second sample, shape ``(n_y,)``, finite, n_y >= 2.

    Returns:
        ``(t, df, p)``: the statistic (positive when ``x`` is larger on average), the
        Welch-Satterthwaite degrees of freedom and the two-sided p-value. All NaN when both
        samples have zero variance.

    Raises:
        ConfigError: If a sample has fewer than two values or is not finite.
    """
    xs, ys = finite_1d(x, "x"), finite_1d(y, "y")
    if xs.size < 2 or ys.size < 2:
        raise ConfigError("x and y: Welch's t-test needs at least two values in each sample")
    va, vb = float(xs.var(ddof=1)) / xs.size, float(ys.var(ddof=1)) / ys.size
    if va + vb == 0.0:
        return math.nan, math.nan, math.nan
    t = float(xs.mean() - ys.mean()) / math.sqrt(va + vb)
    df = (va + vb) ** 2 / (va**2 / (xs.size - 1) + vb**2 / (ys.size - 1))
    return t, df, min(1.0, 2.0 * student_t_sf(abs(t), df))


# --------------------------------------------------------------------------- intervals


def mean_ci(x: ArrayLike, level: float = 0.95) -> tuple[float, float, float]:
    """Sample mean with a two-sided Student t confidence interval.

    ``mean ± t_{(1+level)/2, n-1} · s / sqrt(n)`` with ``s`` the sample standard deviation
    (ddof = 1). The samples are treated as independent.

    Args:
        x: Samples, shape ``(n,)``, finite; in the unit of the quantity (e.g. m/s²).
        level: Confidence level in (0, 1).

    Returns:
        ``(mean, lo, hi)`` in the unit of ``x``. ``n = 1`` gives NaN bounds; ``n = 0`` gives
        NaN for all three.

    Raises:
        ConfigError: If ``x`` is not 1-D and finite or ``level`` is not in (0, 1).
    """
    level = check_level(level)
    arr = finite_1d(x, "x")
    n = arr.size
    if n == 0:
        return math.nan, math.nan, math.nan
    mean = float(arr.mean())
    if n == 1:
        return mean, math.nan, math.nan
    half = t_quantile(0.5 * (1.0 + level), n - 1) * float(arr.std(ddof=1)) / math.sqrt(n)
    return mean, mean - half, mean + half


@dataclass(frozen=True)
class BinnedStats:
    """Per-bin mean and confidence interval of ``y`` against ``x``.

    Attributes:
        edges: Bin edges, shape ``(k + 1,)``, in the unit of ``x`` (e.g. m of headway).
        centers: Bin centres, shape ``(k,)``.
        counts: Number of samples per bin, shape ``(k,)``, int.
        means: Per-bin mean of ``y``, shape ``(k,)``; NaN where ``counts < min_count``.
        lo: Lower t-interval bound, shape ``(k,)``; NaN where ``counts < max(min_count, 2)``.
        hi: Upper t-interval bound, shape ``(k,)``; NaN like ``lo``.
        level: Confidence level of ``lo``/``hi``.
    """

    edges: NDArray[np.float64]
    centers: NDArray[np.float64]
    counts: NDArray[np.int64]
    means: NDArray[np.float64]
    lo: NDArray[np.float64]
    hi: NDArray[np.float64]
    level: float


def check_edges(edges: ArrayLike, name: str = "edges") -> NDArray[np.float64]:
    """Validates bin edges: 1-D, finite, at least two, strictly increasing.

    Args:
        edges: Candidate edges, shape ``(k + 1,)``.
        name: Argument name used in the error message.

    Returns:
        The edges as a float array.

    Raises:
        ConfigError: If the edges are not valid.
    """
    arr = finite_1d(edges, name)
    if arr.size < 2 or not np.all(np.diff(arr) > 0.0):
        raise ConfigError(f"{name}: expected at least two strictly increasing values")
    return arr


def bin_index(x: NDArray[np.float64], edges: NDArray[np.float64]) -> NDArray[np.int64]:
    """Bin of each ``x``: half-open ``[e_k, e_{k+1})`` except the last, which is closed.

    Args:
        x: Values, shape ``(n,)``.
        edges: Strictly increasing edges, shape ``(k + 1,)``.

    Returns:
        Bin indices in ``0..k-1``, shape ``(n,)``; ``-1`` for values outside the edges or NaN.
    """
    idx = np.searchsorted(edges, x, side="right") - 1
    n_bins = edges.size - 1
    idx[x == edges[-1]] = n_bins - 1
    idx[(idx < 0) | (idx >= n_bins) | np.isnan(x)] = -1
    return idx.astype(np.int64)


def binned_mean_ci(
    x: ArrayLike,
    y: ArrayLike,
    edges: ArrayLike,
    level: float = 0.95,
    min_count: int = 2,
) -> BinnedStats:
    """Mean of ``y`` per bin of ``x`` with a Student t interval per bin.

    Bins are half-open ``[e_k, e_{k+1})`` except the last, ``[e_{k-1}, e_k]``, which is
    closed; samples with ``x`` outside ``[e_0, e_k]`` are dropped.

    Args:
        x: Binning variable, shape ``(n,)``, finite (e.g. headway in m).
        y: Quantity to average, shape ``(n,)``, finite (e.g. POV acceleration in m/s²).
        edges: Strictly increasing bin edges, shape ``(k + 1,)``, in the unit of ``x``.
        level: Confidence level in (0, 1).
        min_count: Bins with fewer samples get NaN mean and bounds; >= 1. Bounds need at
            least two samples regardless.

    Returns:
        A :class:`BinnedStats` with arrays of shape ``(k,)``.

    Raises:
        ConfigError: On non-finite or mismatched ``x``/``y``, invalid ``edges``, ``level``
            or ``min_count``.
    """
    level = check_level(level)
    xs, ys = finite_1d(x, "x"), finite_1d(y, "y")
    if xs.shape != ys.shape:
        raise ConfigError(f"x and y: shapes differ ({xs.shape} vs {ys.shape})")
    if isinstance(min_count, bool) or not isinstance(min_count, int) or min_count < 1:
        raise ConfigError(f"min_count: expected an integer >= 1, got {min_count!r}")
    e = check_edges(edges)
    idx = bin_index(xs, e)
    k = e.size - 1
    counts = np.bincount(idx[idx >= 0], minlength=k).astype(np.int64)
    means, lo, hi = (np.full(k, np.nan) for _ in range(3))
    for b in np.flatnonzero(counts >= min_count):
        means[b], lo[b], hi[b] = mean_ci(ys[idx == b], level)
    return BinnedStats(
        edges=e,
        centers=0.5 * (e[:-1] + e[1:]),
        counts=counts,
        means=means,
        lo=lo,
        hi=hi,
        level=level,
    )


# --------------------------------------------------------------------------- bootstrap


def cohens_d(x: ArrayLike, y: ArrayLike) -> float:
    """Cohen's d: ``(mean(x) - mean(y)) / s_pooled``.

    ``s_pooled = sqrt(((n_x - 1) s_x² + (n_y - 1) s_y²) / (n_x + n_y - 2))`` with ddof = 1.

    Args:
        x: First sample, shape ``(n_x,)``, finite, n_x >= 1.
        y: Second sample, shape ``(n_y,)``, finite, n_y >= 1, n_x + n_y >= 3.

    Returns:
        The standardised difference (dimensionless), positive when ``x`` is larger on
        average; NaN when the pooled standard deviation is 0.

    Raises:
        ConfigError: If a sample is empty, not finite, or there are fewer than 3 samples.
    """
    xs, ys = finite_1d(x, "x"), finite_1d(y, "y")
    if xs.size == 0 or ys.size == 0 or xs.size + ys.size < 3:
        raise ConfigError("x and y: need non-empty samples with at least 3 values in total")
    ss = float(np.sum((xs - xs.mean()) ** 2) + np.sum((ys - ys.mean()) ** 2))
    s_pooled = math.sqrt(ss / (xs.size + ys.size - 2))
    if s_pooled == 0.0:
        return math.nan
    return float(xs.mean() - ys.mean()) / s_pooled


def wilson_interval(count: int, n: int, level: float = 0.95) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion ``count / n``.

    ``(p + z²/2n ± z·sqrt(p(1-p)/n + z²/4n²)) / (1 + z²/n)`` with ``p = count / n`` and
    ``z`` the standard normal ``(1 + level) / 2`` quantile. Unlike the Wald interval it
    does not collapse to a point at 0 or n successes: at ``count = 0`` it is
    ``[0, z² / (n + z²)]``.

    Args:
        count: Successes, ``0 <= count <= n``.
        n: Trials, >= 1.
        level: Confidence level in (0, 1).

    Returns:
        ``(lo, hi)`` as fractions in [0, 1].

    Raises:
        ConfigError: If ``n < 1``, ``count`` is outside ``[0, n]`` or ``level`` is invalid.
    """
    level = check_level(level)
    if isinstance(n, bool) or int(n) != n or n < 1:
        raise ConfigError(f"n: expected an integer >= 1, got {n!r}")
    if isinstance(count, bool) or int(count) != count or not 0 <= count <= n:
        raise ConfigError(f"count: expected an integer in [0, {n}], got {count!r}")
    z = NormalDist().inv_cdf(0.5 * (1.0 + level))
    p = count / n
    z2n = z * z / n
    denom = 1.0 + z2n
    centre = (p + 0.5 * z2n) / denom
    half = z / denom * math.sqrt(p * (1.0 - p) / n + z * z / (4.0 * n * n))
    lo = 0.0 if count == 0 else max(0.0, centre - half)
    hi = 1.0 if count == n else min(1.0, centre + half)
    return lo, hi
