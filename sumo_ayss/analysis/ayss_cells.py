"""The AYSS statistics from per-headway-cell moments instead of the samples (numpy only).

:func:`cells_of` reduces a run's samples to cells: per headway cell (an open 1/32 m interval
or one of its edge points) the count ``n``, the mean and ``m2`` (sum of squared deviations
from the mean) of the indicator. The evaluate stage stores them as the run's
``ayss_bins.csv`` (:mod:`sumo_ayss.run_folder.ayss_bins`); :func:`run_cells` gives a run's
cells, of its samples when they were read, else as stored. The bins of any grid whose
edges lie on that lattice are unions of cells, so every per-bin count, mean and standard
deviation, hence :func:`~.stats.binned_mean_ci`, the between-seed bands, the safety index's
point and per-seed values and Cohen's d, come out of the cells equal to what the samples
give, up to float rounding (the sums are taken in another order).

The one thing cells cannot reproduce is the bootstrap's within-seed resampling of single
samples (:func:`~.bootstrap.binned_mean_bootstrap`). :func:`safety_index_from_cells`
keeps its structure (seeds with replacement, then each chosen seed's rows with
replacement: a multinomial count per used bin) and draws each resampled bin sum from the
normal law with the bin's own mean and variance times the count, which the sum of that
many samples drawn from the bin tends to (thousands per bin at the paper budget). Its
interval is therefore a Monte Carlo draw of nearly the same bootstrap, not the same
replicates: the seed choices, which dominate the interval with three seeds, are drawn
alike, the within-bin noise only in distribution. Measured on the paper budget's samples
(car-following pi1, seeds 0-2 of the issue 35 re-run of configs/paper.yaml, 79,935 kept
samples per seed, 2,000 replicates, bootstrap seeds 0-4): the point and per-seed indices
equal, the bounds from cells within 0.0035 m/s² of the samples' (an interval 0.27 m/s²
wide), about as far as the samples' own bounds move between bootstrap seeds (SD 0.0014 and
0.0020).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sumo_ayss.analysis.bootstrap import RngLike, bootstrap_ci
from sumo_ayss.analysis.safety_index import SafetyIndex
from sumo_ayss.analysis.stats import BinnedStats, bin_index, check_edges, t_quantile
from sumo_ayss.analysis.validate import check_level
from sumo_ayss.util.errors import ConfigError

__all__ = [
    "CELL_WIDTH_M",
    "AyssLike",
    "Cells",
    "CellsLike",
    "Moments",
    "binned_stats_from_cells",
    "cells_of",
    "inside_moments",
    "pooled_moments",
    "rebin",
    "run_cells",
    "safety_index_from_cells",
]

CELL_WIDTH_M = 1.0 / 32.0
"""Width of a headway cell [m]: a binary fraction, so every cell edge is exact, and so are
the report's grids of 0.25 m and 0.5 m. The lattice ``ayss_bins.csv`` is stored on
(:data:`sumo_ayss.run_folder.ayss_bins.CELL_WIDTH_M`, checked when read; storage imports no
analysis, a test keeps the two equal)."""


class CellsLike(Protocol):
    """Per-cell moments of a run's AYSS samples (e.g. :class:`sumo_ayss.run_folder.AyssCells`)."""

    @property
    def h_low_m(self) -> NDArray[np.float64]: ...

    @property
    def h_high_m(self) -> NDArray[np.float64]: ...

    @property
    def n(self) -> NDArray[np.int64]: ...

    @property
    def mean(self) -> NDArray[np.float64]: ...

    @property
    def m2(self) -> NDArray[np.float64]: ...


class AyssLike(Protocol):
    """A run's AYSS samples: the indicator and the headway [m] of each."""

    @property
    def h(self) -> NDArray[np.float64]: ...

    @property
    def indicator(self) -> NDArray[np.float64]: ...

    def __len__(self) -> int: ...


class AyssSource(Protocol):
    """A run's AYSS data as read (:class:`sumo_ayss.run_folder.RunRecord` is one): the
    samples (``ayss.csv``) and the stored cells (``ayss_bins.csv``), each None when absent."""

    @property
    def ayss(self) -> AyssLike | None: ...

    @property
    def ayss_bins(self) -> CellsLike | None: ...


@dataclass(frozen=True)
class Cells:
    """Per-cell moments of AYSS samples (:func:`cells_of`), cells sorted by headway.

    Attributes:
        h_low_m: Lower end of each cell [m], shape ``(c,)``.
        h_high_m: Upper end [m]; equal to ``h_low_m`` for an edge-point cell.
        n: Samples in the cell, shape ``(c,)``, >= 1.
        mean: Mean indicator of the cell's samples (m/s² or m/s).
        m2: Sum of squared deviations of the cell's indicator from ``mean`` (unit²).
    """

    h_low_m: NDArray[np.float64]
    h_high_m: NDArray[np.float64]
    n: NDArray[np.int64]
    mean: NDArray[np.float64]
    m2: NDArray[np.float64]


def cells_of(h: ArrayLike, indicator: ArrayLike) -> Cells:
    """The cells of samples ``(h, indicator)``: what ``ayss_bins.csv`` stores of them.

    Args:
        h: Headway of each sample [m], shape ``(n,)``, finite.
        indicator: Indicator of each sample, shape ``(n,)``, finite.

    Returns:
        The non-empty cells, sorted by headway (edge point ``k/32`` before the open interval
        that starts at it).
    """
    hs = np.asarray(h, dtype=np.float64)
    ys = np.asarray(indicator, dtype=np.float64)
    scaled = hs / CELL_WIDTH_M  # exact: a power of two
    k = np.floor(scaled)
    point = scaled == k
    # sort key: 2k for the point {k/32}, 2k + 1 for the open interval (k/32, (k+1)/32)
    key = (2 * k + np.where(point, 0, 1)).astype(np.int64)
    order = np.argsort(key, kind="stable")
    key, ys = key[order], ys[order]
    uniq, start, counts = np.unique(key, return_index=True, return_counts=True)
    means = np.array([float(ys[s : s + c].mean()) for s, c in zip(start, counts, strict=True)])
    m2 = np.array(
        [
            float(np.sum((ys[s : s + c] - m) ** 2))
            for s, c, m in zip(start, counts, means, strict=True)
        ]
    )
    low = (uniq // 2).astype(np.float64) * CELL_WIDTH_M
    high = low + np.where(uniq % 2 == 1, CELL_WIDTH_M, 0.0)
    return Cells(low, high, counts.astype(np.int64), means.reshape(-1), m2.reshape(-1))


def run_cells(run: AyssSource) -> CellsLike | None:
    """A run's AYSS samples as per-cell moments: of ``ayss.csv`` when it was read, else
    ``ayss_bins.csv`` as stored; None without either."""
    if run.ayss is not None:
        return cells_of(run.ayss.h, run.ayss.indicator)
    return run.ayss_bins


class Moments:
    """Per-bin count, mean and sum of squared deviations, each shape ``(k,)``; the mean is
    NaN in an empty bin."""

    def __init__(
        self, n: NDArray[np.int64], mean: NDArray[np.float64], m2: NDArray[np.float64]
    ) -> None:
        self.n, self.mean, self.m2 = n, mean, m2


def _combine(
    n: NDArray[np.int64],
    mean: NDArray[np.float64],
    m2: NDArray[np.float64],
    b: NDArray[np.int64],
    k: int,
) -> Moments:
    """Cells ``(n, mean, m2)`` combined per bin ``b`` (0..k-1), Chan's parallel formula."""
    counts = np.bincount(b, weights=n, minlength=k)
    sums = np.bincount(b, weights=n * mean, minlength=k)
    with np.errstate(invalid="ignore", divide="ignore"):
        means = np.where(counts > 0, sums / np.where(counts > 0, counts, 1), np.nan)
    dev = n * (mean - means[b]) ** 2
    m2s = np.bincount(b, weights=m2 + dev, minlength=k)
    return Moments(counts.astype(np.int64), means, m2s.astype(np.float64))


def _cell_bins(cells: CellsLike, e: NDArray[np.float64]) -> NDArray[np.int64]:
    """The bin of each cell on edges ``e`` (``-1``: outside them).

    Raises:
        ConfigError: A cell straddles an edge (the edge is not on the cells' lattice).
    """
    low, high = np.asarray(cells.h_low_m), np.asarray(cells.h_high_m)
    point = low == high
    b = bin_index(np.where(point, low, 0.5 * (low + high)), e)
    k = e.size - 1
    inside = b >= 0
    bb = np.clip(b, 0, k - 1)
    fits = point | ((e[bb] <= low) & (high <= e[bb + 1]))
    outside = point | (high <= e[0]) | (low >= e[-1])
    if np.any(inside & ~fits) or np.any(~inside & ~outside):
        raise ConfigError(
            f"edges: {e.tolist()} do not lie on the AYSS cells' headway lattice "
            "(ayss_bins.csv): a cell straddles an edge"
        )
    return b


def rebin(cells: CellsLike, edges: ArrayLike) -> Moments:
    """Count, mean and ``m2`` of a run's samples per bin of ``edges`` (half-open, the last
    closed, like :func:`~.stats.bin_index`); cells outside the edges are dropped.

    Raises:
        ConfigError: Invalid edges, or an edge that is not on the cells' lattice.
    """
    e = check_edges(edges)
    return pooled_moments([cells], e)


def pooled_moments(cells_by_seed: Sequence[CellsLike], edges: ArrayLike) -> Moments:
    """:func:`rebin` of several runs' cells pooled (all samples together)."""
    e = check_edges(edges)
    k = e.size - 1
    parts = [(c, _cell_bins(c, e)) for c in cells_by_seed]
    keep = [(c, b >= 0) for c, b in parts]
    b = np.concatenate([bb[m] for (_, bb), (_, m) in zip(parts, keep, strict=True)])
    n = np.concatenate([np.asarray(c.n)[m] for c, m in keep]).astype(np.int64)
    mean = np.concatenate([np.asarray(c.mean)[m] for c, m in keep])
    m2 = np.concatenate([np.asarray(c.m2)[m] for c, m in keep])
    return _combine(n, mean, m2, b.astype(np.int64), k)


def binned_stats_from_cells(
    cells_by_seed: Sequence[CellsLike], edges: ArrayLike, level: float = 0.95, min_count: int = 2
) -> BinnedStats:
    """:func:`~.stats.binned_mean_ci` of the pooled samples of ``cells_by_seed`` (one run:
    a one-element sequence), from their cells: the same counts, and the same means and
    t-intervals up to float rounding."""
    level = check_level(level)
    if isinstance(min_count, bool) or not isinstance(min_count, int) or min_count < 1:
        raise ConfigError(f"min_count: expected an integer >= 1, got {min_count!r}")
    e = check_edges(edges)
    m = pooled_moments(cells_by_seed, e)
    k = e.size - 1
    means, lo, hi = (np.full(k, np.nan) for _ in range(3))
    for b in np.flatnonzero(m.n >= min_count):
        n = int(m.n[b])
        means[b] = float(m.mean[b])
        if n >= 2:
            half = t_quantile(0.5 * (1.0 + level), n - 1) * math.sqrt(m.m2[b] / (n - 1))
            half /= math.sqrt(n)
            lo[b], hi[b] = means[b] - half, means[b] + half
    return BinnedStats(
        edges=e,
        centers=0.5 * (e[:-1] + e[1:]),
        counts=m.n,
        means=means,
        lo=lo,
        hi=hi,
        level=level,
    )


def inside_moments(cells: CellsLike, low_m: float, high_m: float) -> tuple[int, float]:
    """Samples with ``low_m <= h <= high_m`` and their mean indicator (NaN with none)."""
    m = rebin(cells, [low_m, high_m])
    return int(m.n[0]), float(m.mean[0])


def _cells_bootstrap(
    per_seed: Sequence[Moments], used: NDArray[np.bool_], n_boot: int, rng: RngLike
) -> NDArray[np.float64]:
    """The safety index's bootstrap statistic (before the sign) from per-seed bin moments:
    per replicate, seeds with replacement, then per chosen seed a multinomial count per
    used bin and a normal draw of each bin's resampled sum (mean ``c·mean_b``, variance
    ``c·m2_b/n_b``)."""
    gen = np.random.default_rng(rng)
    g = len(per_seed)
    k = used.size
    counts = np.stack([np.where(used, s.n, 0) for s in per_seed]).astype(np.int64)
    means = np.stack([np.nan_to_num(s.mean) for s in per_seed])
    var = np.stack([np.where(s.n > 0, s.m2 / np.maximum(s.n, 1), 0.0) for s in per_seed])
    totals = counts.sum(axis=1)
    probs = counts / totals[:, None]
    out = np.empty(n_boot, dtype=np.float64)
    for r in range(n_boot):
        chosen = gen.integers(0, g, size=g)
        c = np.zeros(k)
        s = np.zeros(k)
        for j in chosen:
            draw = gen.multinomial(totals[j], probs[j])
            s += draw * means[j] + np.sqrt(draw * var[j]) * gen.standard_normal(k)
            c += draw
        keep = used & (c > 0)
        out[r] = float(np.mean(s[keep] / c[keep]))
    return out


def _index(m: Moments, used: NDArray[np.bool_]) -> float:
    keep = used & (m.n > 0)
    return -float(np.mean(m.mean[keep]))


def safety_index_from_cells(
    cells_by_seed: Sequence[CellsLike],
    h_range: tuple[float, float] = (0.0, 5.0),
    *,
    n_bins: int = 10,
    min_count: int = 1,
    level: float = 0.95,
    n_boot: int = 2000,
    rng: RngLike = None,
) -> SafetyIndex:
    """:func:`~.safety_index.safety_index` from the runs' cells (arguments alike).

    The point, the used bins, the per-seed indices, the sample count and the moments for
    Cohen's d (:attr:`~.safety_index.SafetyIndex.indicator_moments`) equal the samples'
    up to float rounding; the interval comes from the moment bootstrap of the module
    docstring.

    Raises:
        ConfigError: No seed, invalid options, or no bin holds ``min_count`` samples.
    """
    if not cells_by_seed:
        raise ConfigError("cells_by_seed: expected at least one seed")
    lo_h, hi_h = float(h_range[0]), float(h_range[1])
    if not (math.isfinite(lo_h) and math.isfinite(hi_h) and lo_h < hi_h):
        raise ConfigError(f"h_range: expected finite h_min < h_max in m, got {h_range!r}")
    level = check_level(level)
    if isinstance(n_boot, bool) or not isinstance(n_boot, int) or n_boot < 1:
        raise ConfigError(f"n_boot: expected an integer >= 1, got {n_boot!r}")
    edges = np.linspace(lo_h, hi_h, n_bins + 1)
    per_seed = [rebin(c, edges) for c in cells_by_seed]
    pooled_n = np.sum([m.n for m in per_seed], axis=0)
    used = pooled_n >= min_count
    if not used.any():
        raise ConfigError(
            f"samples_by_seed: no headway bin on h_range=({lo_h:g}, {hi_h:g}) holds "
            f"min_count={min_count} samples"
        )
    groups = [m for m in per_seed if int(m.n[used].sum()) > 0]
    pooled = pooled_moments(cells_by_seed, edges)
    flat_b = np.concatenate([np.flatnonzero(used & (m.n > 0)) for m in groups])
    n = np.concatenate([m.n[used & (m.n > 0)] for m in groups])
    mean = np.concatenate([m.mean[used & (m.n > 0)] for m in groups])
    m2 = np.concatenate([m.m2[used & (m.n > 0)] for m in groups])
    total = _combine(n, mean, m2, np.zeros_like(flat_b, dtype=np.int64), 1)
    replicates = -_cells_bootstrap(groups, used, n_boot, rng)
    lo, hi = bootstrap_ci(replicates, level)
    replicates.setflags(write=False)
    return SafetyIndex(
        point=_index(pooled, used),
        lo=lo,
        hi=hi,
        n_seeds=len(groups),
        n_samples=int(total.n[0]),
        level=level,
        h_range=(lo_h, hi_h),
        n_bins=n_bins,
        bins_used=tuple(bool(u) for u in used),
        replicates=replicates,
        seed_points=tuple(_index(m, used) for m in groups),
        indicator_moments=(int(total.n[0]), float(total.mean[0]), float(total.m2[0])),
    )
