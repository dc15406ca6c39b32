"""Two-level (seed, then sample) bootstraps and percentile intervals (numpy only).

* :func:`hierarchical_bootstrap` — any statistic of the pooled resampled rows.
* :func:`binned_mean_bootstrap` — the same resampling for the mean over headway bins of the
  per-bin mean (the safety index), without building the pooled rows.
* :func:`bootstrap_ci` — percentile interval of a bootstrap distribution.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sumo_ayss.analysis.validate import check_level, finite_1d
from sumo_ayss.util.errors import ConfigError

__all__ = ["RngLike", "binned_mean_bootstrap", "bootstrap_ci", "hierarchical_bootstrap"]

Statistic = Callable[[NDArray[np.float64]], float]
RngLike = np.random.Generator | int | None


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
    rows: NDArray[np.float64] = arr[gen.integers(0, arr.shape[0], size=arr.shape[0])]
    return rows


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
    arr = finite_1d(dist, "dist")
    if arr.size == 0:
        raise ConfigError("dist: expected at least one replicate")
    lo, hi = np.quantile(arr, [0.5 * (1.0 - level), 0.5 * (1.0 + level)])
    return float(lo), float(hi)


def binned_mean_bootstrap(
    bins_by_group: Sequence[NDArray[np.intp]],
    values_by_group: Sequence[NDArray[np.float64]],
    used: NDArray[np.bool_],
    n_boot: int = 2000,
    rng: RngLike = None,
) -> NDArray[np.float64]:
    """:func:`hierarchical_bootstrap` of the mean over used bins of the per-bin mean value.

    The statistic of a replicate is ``mean_{b ∈ U, n_b > 0} (sum_b / n_b)`` over the pooled
    resampled rows, with ``U`` the ``used`` bins; bins of ``U`` that the resample leaves
    empty are skipped. It draws the same random numbers in the same order as
    :func:`hierarchical_bootstrap` (per replicate: the groups, then the rows of each chosen
    group) and sums each bin's values in the same order, so for the same ``rng`` it returns
    the same replicates, bit for bit; it only gathers bin indices and values straight into
    preallocated buffers instead of pooling ``(bin, value)`` rows and converting them.

    Args:
        bins_by_group: Per group, the bin of each row, shape ``(n_g,)``, in ``0..k-1`` (only
            rows of used bins).
        values_by_group: Per group, the value of each row, shape ``(n_g,)``, finite.
        used: Shape ``(k,)``: the bins that enter the mean.
        n_boot: Number of replicates, >= 1.
        rng: A numpy Generator, a seed, or None for fresh entropy.

    Returns:
        The bootstrap distribution of the statistic, shape ``(n_boot,)``.

    Raises:
        ConfigError: On no group, an empty group, mismatched shapes or an invalid ``n_boot``.
    """
    if isinstance(n_boot, bool) or not isinstance(n_boot, int) or n_boot < 1:
        raise ConfigError(f"n_boot: expected an integer >= 1, got {n_boot!r}")
    if not bins_by_group or len(bins_by_group) != len(values_by_group):
        raise ConfigError("bins_by_group, values_by_group: expected one array each per group")
    bins = [np.asarray(b, dtype=np.intp) for b in bins_by_group]
    values = [np.asarray(v, dtype=np.float64) for v in values_by_group]
    if any(b.size == 0 or b.shape != v.shape for b, v in zip(bins, values, strict=True)):
        raise ConfigError("groups: expected non-empty groups with one value per bin index")
    k = used.size
    gen = np.random.default_rng(rng)
    n_groups = len(bins)
    sizes = [b.size for b in bins]
    capacity = n_groups * max(sizes)
    bin_buf = np.empty(capacity, dtype=np.intp)
    val_buf = np.empty(capacity, dtype=np.float64)
    out = np.empty(n_boot, dtype=np.float64)
    for r in range(n_boot):
        chosen = gen.integers(0, n_groups, size=n_groups)
        end = 0
        for g in chosen:
            rows = gen.integers(0, sizes[g], size=sizes[g])
            np.take(bins[g], rows, out=bin_buf[end : end + sizes[g]])
            np.take(values[g], rows, out=val_buf[end : end + sizes[g]])
            end += sizes[g]
        counts = np.bincount(bin_buf[:end], minlength=k)
        sums = np.bincount(bin_buf[:end], weights=val_buf[:end], minlength=k)
        keep = used & (counts > 0)
        out[r] = float(np.mean(sums[keep] / counts[keep]))
    return out
