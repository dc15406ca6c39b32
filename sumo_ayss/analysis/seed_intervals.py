"""Intervals over training seeds, as the report shows them (numpy and the stdlib only).

One training seed of one VUT gives one SPCP, so the spread that a verdict rests on is the
spread *between seeds*. Two rules make those intervals read right:

* **Too few seeds, no interval.** A Student t interval over two points uses
  ``t_{0.975, 1} = 12.7`` times the standard error and reads as nonsense ("crash rate
  28.5 % (−143.03 to 200.03)"). Below :data:`MIN_SEEDS_FOR_INTERVAL` seeds no interval is
  given (the report says why: :func:`sumo_ayss.modes.formatting.seed_interval_text`).
* **Inside what is possible.** A rate lies in [0, 1] and a harm per episode too: an
  interval is clipped to the quantity's possible range (``bounds``), and the caption says so.

:func:`binned_seed_means` is the between-seed view of a quantity against headway (the
paper's Fig. 4 / Fig. 6): per bin, the mean of the seeds' own bin means with the interval
over seeds, so the figure carries the uncertainty the verdict uses.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sumo_ayss.analysis.stats import BinnedStats, binned_mean_ci, mean_ci
from sumo_ayss.util.errors import ConfigError

__all__ = [
    "MIN_SEEDS_FOR_INTERVAL",
    "SeedBands",
    "binned_seed_means",
    "clip_interval",
    "seed_bands",
    "seed_mean_ci",
]

MIN_SEEDS_FOR_INTERVAL = 3
"""Fewest seeds for a seed-level t-interval; with two, ``t`` (12.7 at 95 %) makes it
meaningless, so none is given."""

Bounds = tuple[float, float]
UNBOUNDED: Bounds = (-math.inf, math.inf)


def _check_bounds(bounds: Bounds) -> Bounds:
    low, high = float(bounds[0]), float(bounds[1])
    if math.isnan(low) or math.isnan(high) or low >= high:
        raise ConfigError(f"bounds: expected (low, high) with low < high, got {bounds!r}")
    return low, high


def clip_interval(lo: float, hi: float, bounds: Bounds) -> tuple[float, float]:
    """``(lo, hi)`` clipped to ``bounds`` (the quantity's possible range); NaN stays NaN."""
    low, high = _check_bounds(bounds)
    if not (math.isfinite(lo) and math.isfinite(hi)):
        return lo, hi
    return min(max(lo, low), high), max(min(hi, high), low)


def seed_mean_ci(
    x: ArrayLike, level: float = 0.95, *, bounds: Bounds = UNBOUNDED
) -> tuple[float, float, float]:
    """Seed mean with its t-interval over seeds, inside ``bounds``.

    Args:
        x: One value per seed, shape ``(n,)``, finite, in the quantity's unit.
        level: Confidence level in (0, 1).
        bounds: The quantity's possible range ``(low, high)``, same unit (``(0, 1)`` for a
            rate); the interval is clipped to it.

    Returns:
        ``(mean, lo, hi)``; NaN bounds with fewer than :data:`MIN_SEEDS_FOR_INTERVAL` seeds,
        all NaN with none.
    """
    mean, lo, hi = mean_ci(x, level)
    if np.asarray(x).size < MIN_SEEDS_FOR_INTERVAL:
        return mean, math.nan, math.nan
    lo, hi = clip_interval(lo, hi, bounds)
    return mean, lo, hi


class SeedBands:
    """Between-seed bands of a quantity against headway (:func:`binned_seed_means`).

    Attributes:
        centers: Bin centres, shape ``(k,)``, m.
        means: Per bin, the mean over seeds of each seed's bin mean; NaN where no seed has
            a bin mean.
        lo: Lower bound per bin: the t-interval over the seeds' bin means with at least
            :data:`MIN_SEEDS_FOR_INTERVAL` seeds, the lowest seed mean with two; NaN with
            fewer.
        hi: Upper bound like ``lo``.
        n_seeds: Seeds with a bin mean, per bin, shape ``(k,)``.
        per_seed: Each seed's :class:`BinnedStats`, in input order.
    """

    def __init__(
        self,
        centers: NDArray[np.float64],
        means: NDArray[np.float64],
        lo: NDArray[np.float64],
        hi: NDArray[np.float64],
        n_seeds: NDArray[np.int64],
        per_seed: tuple[BinnedStats, ...],
    ) -> None:
        self.centers, self.means, self.lo, self.hi = centers, means, lo, hi
        self.n_seeds, self.per_seed = n_seeds, per_seed


def binned_seed_means(
    seeds: Sequence[tuple[ArrayLike, ArrayLike]],
    edges: ArrayLike,
    level: float = 0.95,
    min_count: int = 2,
) -> SeedBands:
    """Per headway bin, the mean over seeds of each seed's bin mean, with its band.

    Args:
        seeds: One ``(h, y)`` per seed: headway (m) and the quantity (e.g. m/s²), each
            shape ``(n_s,)``.
        edges: Bin edges in m, shape ``(k + 1,)``.
        level: Confidence level of the t-interval over seeds.
        min_count: Samples a seed needs in a bin for its bin mean to count.

    Returns:
        :class:`SeedBands`. With two seeds in a bin the band is the range of their two
        means (no t-interval, see :data:`MIN_SEEDS_FOR_INTERVAL`), so it always contains
        every seed's bin mean.
    """
    per_seed = tuple(
        binned_mean_ci(h, y, edges, level=level, min_count=min_count) for h, y in seeds
    )
    return seed_bands(per_seed, edges, level)


def seed_bands(per_seed: Sequence[BinnedStats], edges: ArrayLike, level: float = 0.95) -> SeedBands:
    """:func:`binned_seed_means` from each seed's own :class:`BinnedStats` on ``edges``
    (e.g. from per-cell moments, :func:`~.ayss_cells.binned_stats_from_cells`)."""
    per_seed = tuple(per_seed)
    e = np.asarray(edges, dtype=np.float64)
    k = e.size - 1
    means, lo, hi = (np.full(k, np.nan) for _ in range(3))
    n_seeds = np.zeros(k, dtype=np.int64)
    for b in range(k):
        values = np.array([s.means[b] for s in per_seed if math.isfinite(s.means[b])])
        n_seeds[b] = values.size
        if values.size == 0:
            continue
        means[b] = float(values.mean())
        if values.size >= MIN_SEEDS_FOR_INTERVAL:
            _, lo[b], hi[b] = mean_ci(values, level)
        elif values.size == 2:
            lo[b], hi[b] = float(values.min()), float(values.max())
    return SeedBands(0.5 * (e[:-1] + e[1:]), means, lo, hi, n_seeds, per_seed)
