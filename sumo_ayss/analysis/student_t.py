"""Student t distribution without scipy, and Welch's t-test (numpy and the stdlib only).

* :func:`student_t_sf` — upper tail, from the regularized incomplete beta function (Lentz's
  continued fraction).
* :func:`t_quantile` — quantile, by bisection on the tail (Cornish-Fisher for very large df).
* :func:`welch_t_test` — two-sided unequal-variance test of equal means.
"""

from __future__ import annotations

import functools
import math
from statistics import NormalDist

from numpy.typing import ArrayLike

from sumo_ayss.analysis.validate import check_level, finite_1d, is_real
from sumo_ayss.errors import ConfigError

__all__ = ["student_t_sf", "t_quantile", "welch_t_test"]

_CF_MAX_ITER = 100_000
_CF_EPS = 1e-15
_TINY = 1e-300
_LARGE_DF = 1e5  # above this the Cornish-Fisher expansion is exact to double precision


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
    if not is_real(df) or not df > 0.0:
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
    if not is_real(df) or not df > 0.0:
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
