"""Confidence intervals and bootstraps for AYSS indicators (numpy and the stdlib only).

* :func:`t_quantile` — Student t quantile without scipy (regularized incomplete beta by
  Lentz's continued fraction, inverted by bisection; Cornish-Fisher for very large df).
* :func:`mean_ci` — mean with a Student t interval.
* :func:`binned_mean_ci` — per-bin means with t intervals, e.g. indicator vs headway.
* :func:`hierarchical_bootstrap` / :func:`bootstrap_ci` — two-level (seed, then sample)
  bootstrap and its percentile interval.
* :func:`cohens_d` — standardised mean difference with the pooled standard deviation.
"""

from __future__ import annotations

import functools
import math
import numbers
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from statistics import NormalDist

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sumo_ayss.errors import ConfigError

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
]

_CF_MAX_ITER = 100_000
_CF_EPS = 1e-15
_TINY = 1e-300
_LARGE_DF = 1e5  # above this the Cornish-Fisher expansion is exact to double precision

Statistic = Callable[[NDArray[np.float64]], float]
RngLike = np.random.Generator | int | None


# --------------------------------------------------------------------------- validation


def _is_real(value: object) -> bool:
    """True for real numbers (numpy scalars included), False for bools and the rest."""
    return isinstance(value, numbers.Real) and not isinstance(value, bool | np.bool_)


def check_level(level: float, name: str = "level") -> float:
    """Validates a confidence level or probability.

    Args:
        level: Candidate value.
        name: Argument name used in the error message.

    Returns:
        ``level`` as a float.

    Raises:
        ConfigError: If ``level`` is not a real number strictly between 0 and 1.
    """
    if not _is_real(level) or not 0.0 < float(level) < 1.0:
        raise ConfigError(f"{name}: expected a number in (0, 1), got {level!r}")
    return float(level)


def _finite_1d(x: ArrayLike, name: str) -> NDArray[np.float64]:
    """Returns ``x`` as a finite 1-D float array (scalars become length 1)."""
    try:
        arr = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ConfigError(f"{name}: expected real numbers") from exc
    if arr.ndim > 1:
        raise ConfigError(f"{name}: expected a 1-D array, got shape {arr.shape}")
    arr = np.atleast_1d(arr)
    if not np.all(np.isfinite(arr)):
        raise ConfigError(f"{name}: contains NaN or infinite values")
    return arr


# --------------------------------------------------------------------------- Student t


def _betacf(a: float, b: float, x: float) -> float:
    """Continued fraction of the incomplete beta function (modified Lentz)."""
    qab, qap, qam = a + b, a + 1.0, a - 1.0
    c, d = 1.0, 1.0 - qab * x / qap
    d = 1.0 / (d if abs(d) > _TINY else _TINY)
    h = d
    for m in range(1, _CF_MAX_ITER + 1):
        m2 = 2 * m
        even = m * (b - m) * x / ((qam + m2) * (a + m2))
        odd = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2))
        for aa in (even, odd):
            d = 1.0 + aa * d
            d = 1.0 / (d if abs(d) > _TINY else _TINY)
            c = 1.0 + aa / c
            c = c if abs(c) > _TINY else _TINY
            h *= d * c
        if abs(d * c - 1.0) < _CF_EPS:
            return h
    raise ArithmeticError(f"incomplete beta continued fraction did not converge (a={a}, b={b})")


def _reg_inc_beta(a: float, b: float, x: float, y: float) -> float:
    """Regularized incomplete beta I_x(a, b) for a, b > 0, 0 <= x <= 1 and y = 1 - x.

    ``y`` is passed separately so that a tiny ``1 - x`` keeps its precision.
    """
    if x <= 0.0:
        return 0.0
    if y <= 0.0:
        return 1.0
    log_beta = math.lgamma(a) + math.lgamma(b) - math.lgamma(a + b)
    log_front = a * math.log(x) + b * math.log(y) - log_beta
    if x < (a + 1.0) / (a + b + 2.0):
        return math.exp(log_front) * _betacf(a, b, x) / a
    return 1.0 - math.exp(log_front) * _betacf(b, a, y) / b


def student_t_sf(t: float, df: float) -> float:
    """Upper tail P(T > t) of Student's t distribution.

    Args:
        t: Quantile (dimensionless).
        df: Degrees of freedom, > 0 (non-integer allowed; ``math.inf`` gives the normal).

    Returns:
        The survival function at ``t``, in [0, 1].

    Raises:
        ConfigError: If ``df`` is not positive.
    """
    if not _is_real(df) or not df > 0.0:
        raise ConfigError(f"df: expected a positive number, got {df!r}")
    if math.isinf(df):
        return 1.0 - NormalDist().cdf(t) if t < 0 else NormalDist().cdf(-t)
    t2 = t * t
    tail = 0.5 * _reg_inc_beta(0.5 * df, 0.5, df / (df + t2), t2 / (df + t2))
    return tail if t >= 0.0 else 1.0 - tail


def _cornish_fisher_t(p: float, df: float) -> float:
    """Student t quantile by the Cornish-Fisher expansion (A&S 26.7.5), for large df."""
    x = NormalDist().inv_cdf(p)
    x2 = x * x
    g1 = (x2 + 1.0) * x / 4.0
    g2 = ((5.0 * x2 + 16.0) * x2 + 3.0) * x / 96.0
    g3 = (((3.0 * x2 + 19.0) * x2 + 17.0) * x2 - 15.0) * x / 384.0
    g4 = ((((79.0 * x2 + 776.0) * x2 + 1482.0) * x2 - 1920.0) * x2 - 945.0) * x / 92160.0
    return x + g1 / df + g2 / df**2 + g3 / df**3 + g4 / df**4


def _upper_t_quantile(p: float, df: float) -> float:
    """Solves P(T > t) = 1 - p for t >= 0 by bracketing and bisection (p > 0.5)."""
    target = 1.0 - p
    lo, hi = 0.0, max(1.0, 2.0 * NormalDist().inv_cdf(p))
    while student_t_sf(hi, df) > target:
        lo, hi = hi, 2.0 * hi
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if student_t_sf(mid, df) > target:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 1e-13 * max(1.0, hi):
            break
    return 0.5 * (lo + hi)


def t_quantile(p: float, df: float) -> float:
    """Quantile function of Student's t distribution, t_{p, df}.

    Exact closed forms for df = 1 and df = 2, the normal quantile for ``df = inf``, the
    Cornish-Fisher expansion for df > 1e5, and otherwise bisection on the survival function
    computed from the regularized incomplete beta function. The tail probability at the
    returned value is within a relative 1e-8 of ``1 - p`` (checked against mpmath).

    Args:
        p: Probability in (0, 1).
        df: Degrees of freedom, > 0 (non-integer allowed; ``math.inf`` gives the normal).

    Returns:
        The value t with P(T <= t) = p (dimensionless).

    Raises:
        ConfigError: If ``p`` is not in (0, 1) or ``df`` is not positive.
    """
    p = check_level(p, "p")
    if not _is_real(df) or not df > 0.0:
        raise ConfigError(f"df: expected a positive number, got {df!r}")
    if p < 0.5:
        return -t_quantile(1.0 - p, df)
    if p == 0.5:
        return 0.0
    return _t_quantile_upper(p, float(df))


@functools.lru_cache(maxsize=1024)
def _t_quantile_upper(p: float, df: float) -> float:
    """t_{p, df} for 0.5 < p < 1 and df > 0 (validated by the caller), memoised."""
    if math.isinf(df):
        return NormalDist().inv_cdf(p)
    if df == 1.0:
        return math.tan(math.pi * (p - 0.5))
    if df == 2.0:
        return (2.0 * p - 1.0) / math.sqrt(2.0 * p * (1.0 - p))
    if df > _LARGE_DF:
        return _cornish_fisher_t(p, df)
    return _upper_t_quantile(p, df)


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
    arr = _finite_1d(x, "x")
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
    arr = _finite_1d(edges, name)
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
    xs, ys = _finite_1d(x, "x"), _finite_1d(y, "y")
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


def _check_groups(groups: Sequence[ArrayLike]) -> list[NDArray[np.float64]]:
    """Validates bootstrap groups: non-empty, each non-empty, finite, 1-D or 2-D."""
    if isinstance(groups, np.ndarray) and groups.dtype != object:
        raise ConfigError("groups: expected a sequence of arrays (one per seed), not one array")
    out = []
    for g, group in enumerate(groups):
        try:
            arr = np.asarray(group, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise ConfigError(f"groups[{g}]: expected real numbers") from exc
        if arr.ndim not in (1, 2) or arr.shape[0] == 0:
            raise ConfigError(f"groups[{g}]: expected a non-empty 1-D or 2-D array")
        if not np.all(np.isfinite(arr)):
            raise ConfigError(f"groups[{g}]: contains NaN or infinite values")
        out.append(arr)
    if not out:
        raise ConfigError("groups: expected at least one group")
    if len({a.shape[1:] for a in out}) != 1:
        raise ConfigError("groups: every group must have the same trailing shape")
    return out


def _resample_rows(arr: NDArray[np.float64], gen: np.random.Generator) -> NDArray[np.float64]:
    """Draws ``len(arr)`` rows of ``arr`` with replacement."""
    return arr[gen.integers(0, arr.shape[0], size=arr.shape[0])]


def hierarchical_bootstrap(
    groups: Sequence[ArrayLike],
    statistic: Statistic = np.mean,
    n_boot: int = 2000,
    rng: RngLike = None,
) -> NDArray[np.float64]:
    """Two-level bootstrap: resample groups, then samples within each chosen group.

    Each replicate draws ``G`` groups with replacement from the ``G`` given (the group — a
    training seed / SPCP — is the unit of replication), then for each chosen group draws
    as many rows as it has with replacement, pools the rows and evaluates ``statistic``.
    With few groups the distribution is coarse (3 seeds give 10 distinct multisets) and
    too narrow when the groups differ systematically: the group-level resampling
    underestimates the between-group variance of a mean by the factor (G-1)/G.

    Args:
        groups: One array per group, shape ``(n_g,)`` or ``(n_g, m)`` (rows are samples;
            every group has the same ``m``), finite, non-empty.
        statistic: Maps the pooled rows, shape ``(N,)`` or ``(N, m)``, to a float.
        n_boot: Number of replicates, >= 1.
        rng: A numpy Generator, a seed, or None for fresh entropy.

    Returns:
        The bootstrap distribution, shape ``(n_boot,)``.

    Raises:
        ConfigError: On empty or non-finite groups or an invalid ``n_boot``.
    """
    data = _check_groups(groups)
    if isinstance(n_boot, bool) or not isinstance(n_boot, int) or n_boot < 1:
        raise ConfigError(f"n_boot: expected an integer >= 1, got {n_boot!r}")
    gen = np.random.default_rng(rng)
    n_groups = len(data)
    out = np.empty(n_boot, dtype=np.float64)
    for r in range(n_boot):
        chosen = gen.integers(0, n_groups, size=n_groups)
        parts = [_resample_rows(data[g], gen) for g in chosen]
        out[r] = float(statistic(np.concatenate(parts, axis=0)))
    return out


def bootstrap_ci(dist: ArrayLike, level: float = 0.95) -> tuple[float, float]:
    """Percentile interval of a bootstrap distribution.

    Args:
        dist: Bootstrap replicates, shape ``(n_boot,)``, finite.
        level: Confidence level in (0, 1).

    Returns:
        ``(lo, hi)``: the ``(1-level)/2`` and ``(1+level)/2`` quantiles (linear
        interpolation), in the unit of the statistic.

    Raises:
        ConfigError: If ``dist`` is empty or not finite, or ``level`` is not in (0, 1).
    """
    level = check_level(level)
    arr = _finite_1d(dist, "dist")
    if arr.size == 0:
        raise ConfigError("dist: expected at least one replicate")
    lo, hi = np.quantile(arr, [0.5 * (1.0 - level), 0.5 * (1.0 + level)])
    return float(lo), float(hi)


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
    xs, ys = _finite_1d(x, "x"), _finite_1d(y, "y")
    if xs.size == 0 or ys.size == 0 or xs.size + ys.size < 3:
        raise ConfigError("x and y: need non-empty samples with at least 3 values in total")
    ss = float(np.sum((xs - xs.mean()) ** 2) + np.sum((ys - ys.mean()) ** 2))
    s_pooled = math.sqrt(ss / (xs.size + ys.size - 2))
    if s_pooled == 0.0:
        return math.nan
    return float(xs.mean() - ys.mean()) / s_pooled


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
    xs, ys = _finite_1d(x, "x"), _finite_1d(y, "y")
    if xs.size < 2 or ys.size < 2:
        raise ConfigError("x and y: Welch's t-test needs at least two values in each sample")
    va, vb = float(xs.var(ddof=1)) / xs.size, float(ys.var(ddof=1)) / ys.size
    if va + vb == 0.0:
        return math.nan, math.nan, math.nan
    t = float(xs.mean() - ys.mean()) / math.sqrt(va + vb)
    df = (va + vb) ** 2 / (va**2 / (xs.size - 1) + vb**2 / (ys.size - 1))
    return t, df, min(1.0, 2.0 * student_t_sf(abs(t), df))
