"""Scalar safety index per VUT, pairwise verdicts and rankings (numpy and the stdlib only).

The paper compares VUTs by plotting an aggressiveness indicator of their SPCPs against
headway over the adversarial-yet-safe states (AYSS). This module condenses such a curve into
one number with a confidence interval:

    safety index = - mean over equal-width headway bins of (mean indicator in the bin)

The indicator is the POV acceleration implied by the SPCP's action (car-following, m/s²) or
Δv̄ (cut-in, m/s); smaller (more negative) means a more aggressive SPCP, and an SPCP can be
more aggressive only against a safer VUT, hence the minus sign: **a larger index is a safer
VUT**. Averaging per-bin means, rather than all samples, keeps the index from depending on
where the Monte Carlo samples happen to fall in headway. Uncertainty comes from a
hierarchical bootstrap: training seeds (one SPCP each) first, then samples within a seed.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sumo_ayss.analysis.bootstrap import RngLike, binned_mean_bootstrap, bootstrap_ci
from sumo_ayss.analysis.stats import bin_index
from sumo_ayss.analysis.validate import check_level
from sumo_ayss.cases import Indicator  # naming records live with their cases; re-exported
from sumo_ayss.cases.car_following import POV_ACCELERATION
from sumo_ayss.cases.cut_in import DELTA_V_BAR
from sumo_ayss.util.errors import ConfigError

__all__ = ["DELTA_V_BAR", "POV_ACCELERATION", "Indicator", "SafetyIndex", "safety_index"]


def _empty() -> NDArray[np.float64]:
    return np.empty(0, dtype=np.float64)


# --------------------------------------------------------------------------- safety index


@dataclass(frozen=True)
class SafetyIndex:
    """Safety index of one VUT with its hierarchical-bootstrap interval; larger = safer.

    Attributes:
        point: Index on all data, in the indicator's unit (m/s² or m/s): minus the mean over
            the used headway bins of the per-bin mean indicator.
        lo: Lower percentile-bootstrap bound at ``level``.
        hi: Upper percentile-bootstrap bound at ``level``.
        n_seeds: Seeds (SPCPs) with at least one sample in a used bin.
        n_samples: Samples in used bins, all seeds together.
        level: Confidence level of ``lo``/``hi``.
        h_range: Headway range ``(h_min, h_max)`` in m over which bins are laid.
        n_bins: Number of equal-width headway bins.
        bins_used: Per bin, whether it held at least ``min_count`` samples (pooled over
            seeds) and so enters the index.
        replicates: Bootstrap distribution of the index, shape ``(n_boot,)``.
        indicator_samples: The raw (not negated) indicator of every sample in a used bin,
            pooled over seeds, shape ``(n_samples,)``; used for Cohen's d.
        seed_points: The index computed on each seed alone (same bins), one per seed in
            ``n_seeds``; used for the seed-level Welch cross-check of :func:`compare`.
        indicator_moments: ``(n, mean, m2)`` of ``indicator_samples`` when the index was
            computed from per-cell moments (:mod:`~.ayss_cells`), which hold no samples;
            None otherwise.
    """

    point: float
    lo: float
    hi: float
    n_seeds: int
    n_samples: int
    level: float = 0.95
    h_range: tuple[float, float] = (0.0, 5.0)
    n_bins: int = 10
    bins_used: tuple[bool, ...] = ()
    replicates: NDArray[np.float64] = field(default_factory=_empty, repr=False, compare=False)
    indicator_samples: NDArray[np.float64] = field(
        default_factory=_empty, repr=False, compare=False
    )
    seed_points: tuple[float, ...] = ()
    indicator_moments: tuple[int, float, float] | None = None


def _check_pos_int(value: object, name: str, minimum: int = 1) -> int:
    """Returns ``value`` if it is an int >= ``minimum``; raises ConfigError otherwise."""
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < minimum:
        raise ConfigError(f"{name}: expected an integer >= {minimum}, got {value!r}")
    return int(value)


def _check_h_range(h_range: Sequence[float]) -> tuple[float, float]:
    """Returns ``h_range`` as two finite floats with lo < hi."""
    try:
        lo, hi = (float(v) for v in h_range)
    except (TypeError, ValueError) as exc:
        raise ConfigError(f"h_range: expected (h_min, h_max) in m, got {h_range!r}") from exc
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise ConfigError(f"h_range: expected finite h_min < h_max in m, got {h_range!r}")
    return lo, hi


def _check_seed_pair(
    y: ArrayLike, h: ArrayLike, s: int
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Validates the indicator and headway arrays of seed ``s``."""
    try:
        ys, hs = np.asarray(y, dtype=np.float64), np.asarray(h, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ConfigError(f"samples_by_seed[{s}] / headway_by_seed[{s}]: not numeric") from exc
    if ys.ndim != 1 or ys.shape != hs.shape:
        raise ConfigError(
            f"samples_by_seed[{s}] and headway_by_seed[{s}]: expected 1-D arrays of equal "
            f"length, got shapes {ys.shape} and {hs.shape}"
        )
    if not (np.all(np.isfinite(ys)) and np.all(np.isfinite(hs))):
        raise ConfigError(f"samples_by_seed[{s}] / headway_by_seed[{s}]: NaN or infinite")
    return ys, hs


def _binned_groups(
    samples_by_seed: Sequence[ArrayLike],
    headway_by_seed: Sequence[ArrayLike],
    edges: NDArray[np.float64],
    min_count: int,
) -> tuple[list[NDArray[np.float64]], NDArray[np.bool_]]:
    """Per-seed ``(bin, indicator)`` rows restricted to used bins, and the used-bin mask.

    Seeds left without rows are dropped. Raises ConfigError when no bin is used.
    """
    per_seed = []
    for s, (y, h) in enumerate(zip(samples_by_seed, headway_by_seed, strict=True)):
        ys, hs = _check_seed_pair(y, h, s)
        per_seed.append(np.column_stack([bin_index(hs, edges).astype(np.float64), ys]))
    pooled_idx = np.concatenate([rows[:, 0] for rows in per_seed]).astype(np.int64)
    counts = np.bincount(pooled_idx[pooled_idx >= 0], minlength=edges.size - 1)
    used = counts >= min_count
    if not used.any():
        raise ConfigError(
            f"samples_by_seed: no headway bin on h_range=({edges[0]:g}, {edges[-1]:g}) holds "
            f"min_count={min_count} samples"
        )
    groups = [rows[_in_used(rows, used)] for rows in per_seed]
    return [g for g in groups if g.shape[0] > 0], used


def _binned_index(rows: NDArray[np.float64], used: NDArray[np.bool_]) -> float:
    """Minus the mean over used, non-empty bins of the per-bin mean of ``rows[:, 1]``.

    Args:
        rows: Shape ``(n, 2)``: bin index (as float) and indicator value.
        used: Shape ``(k,)``: the bins that enter the index.
    """
    idx = rows[:, 0].astype(np.int64)
    counts = np.bincount(idx, minlength=used.size)
    sums = np.bincount(idx, weights=rows[:, 1], minlength=used.size)
    keep = used & (counts > 0)
    return -float(np.mean(sums[keep] / counts[keep]))


def safety_index(
    samples_by_seed: Sequence[ArrayLike],
    headway_by_seed: Sequence[ArrayLike],
    h_range: tuple[float, float] = (0.0, 5.0),
    *,
    n_bins: int = 10,
    min_count: int = 1,
    level: float = 0.95,
    n_boot: int = 2000,
    rng: RngLike = None,
) -> SafetyIndex:
    """Scalar safety index of one VUT from the AYSS indicator of its SPCPs; larger = safer.

    ``index = - (1/|U|) Σ_{b ∈ U} mean{y_i : h_i in bin b}`` over ``n_bins`` equal-width
    headway bins on ``h_range`` (half-open, the last closed); ``U`` is the set of bins with
    at least ``min_count`` samples pooled over seeds. Samples outside ``h_range`` or in
    unused bins are dropped. The interval is the percentile interval of a hierarchical
    bootstrap (seeds with replacement, then samples within each seed with replacement); in
    a replicate, bins of ``U`` that the resample leaves empty are skipped.

    Caveat: with few seeds the interval is too narrow when seeds differ systematically
    (the seed-level bootstrap underestimates between-seed variance by (G-1)/G and has few
    distinct resamples). In 100 simulated comparisons with 3 seeds per VUT, a seed-to-seed
    SD of 0.2 and a within-seed SD of 1 (200 samples per seed), a same-distribution pair
    came out "significant" in 16 % of cases at the nominal 5 %; 6 % with 10 seeds, 3 % with
    no seed-to-seed spread. :func:`compare` therefore also reports a seed-level Welch test.

    Args:
        samples_by_seed: Per seed (SPCP), the indicator of each AYSS sample, shape
            ``(n_s,)``: POV acceleration in m/s² (car-following) or Δv̄ in m/s (cut-in);
            more negative = more aggressive SPCP.
        headway_by_seed: Per seed, the distance headway h in m of each sample, shape
            ``(n_s,)`` matching ``samples_by_seed``.
        h_range: ``(h_min, h_max)`` in m; the paper's AYSS use h <= 5 m.
        n_bins: Number of equal-width headway bins, >= 1.
        min_count: Minimum pooled samples for a bin to enter the index, >= 1.
        level: Confidence level of the interval, in (0, 1).
        n_boot: Bootstrap replicates, >= 1. Use the same value for VUTs to be compared.
        rng: A numpy Generator, a seed, or None.

    Returns:
        The :class:`SafetyIndex`, in the indicator's unit.

    Raises:
        ConfigError: On mismatched, non-finite or empty inputs, invalid options, or when no
            bin holds ``min_count`` samples.
    """
    if len(samples_by_seed) != len(headway_by_seed) or len(samples_by_seed) == 0:
        raise ConfigError(
            "samples_by_seed and headway_by_seed: expected the same, non-zero number of seeds"
        )
    lo_h, hi_h = _check_h_range(h_range)
    level = check_level(level)
    n_bins = _check_pos_int(n_bins, "n_bins")
    min_count = _check_pos_int(min_count, "min_count")
    edges = np.linspace(lo_h, hi_h, n_bins + 1)
    groups, used = _binned_groups(samples_by_seed, headway_by_seed, edges, min_count)
    pooled = np.concatenate(groups, axis=0)
    # The same draws as hierarchical_bootstrap(groups, lambda rows: _binned_index(rows, used))
    # and the same replicates, without pooling the resampled rows.
    replicates = -binned_mean_bootstrap(
        [g[:, 0].astype(np.intp) for g in groups],
        [g[:, 1] for g in groups],
        used,
        n_boot=n_boot,
        rng=rng,
    )
    lo, hi = bootstrap_ci(replicates, level)
    return SafetyIndex(
        point=_binned_index(pooled, used),
        lo=lo,
        hi=hi,
        n_seeds=len(groups),
        n_samples=int(pooled.shape[0]),
        level=level,
        h_range=(lo_h, hi_h),
        n_bins=n_bins,
        bins_used=tuple(bool(u) for u in used),
        replicates=_frozen(replicates),
        indicator_samples=_frozen(pooled[:, 1].copy()),
        seed_points=tuple(_binned_index(g, used) for g in groups),
    )


def _in_used(rows: NDArray[np.float64], used: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """Mask of the rows whose bin index (column 0) is a used bin."""
    idx = rows[:, 0].astype(np.int64)
    return (idx >= 0) & used[np.clip(idx, 0, used.size - 1)]


def _frozen(arr: NDArray[np.float64]) -> NDArray[np.float64]:
    """Marks ``arr`` read-only, so a frozen dataclass holding it stays unchanged."""
    arr.setflags(write=False)
    return arr
