"""Per-VUT distributions of the safety measures under an opponent pool, and the ranking
each measure alone gives (pure numpy; the loader hands in the episode table's columns).

For every measure of :data:`MEASURES` and every VUT: the episodes of the pool (cross-play:
every opponent SPCP against that VUT, on the same scenarios) where the measure is defined
(not NaN), their median with a two-level bootstrap interval (opponents resampled, then
episodes within each: the opponent is the unit of replication, as in the cross-play
test), and the 10th and 90th percentiles. Medians and percentiles are order statistics
without interpolation (numpy's ``inverted_cdf``), so an infinite value (a TTC where nobody
closes in) is a value like any other and never turns a quantile into NaN.

Each measure then ranks the VUTs by that median alone, in the measure's own direction
(:attr:`MeasureSpec.higher_is_safer`); :func:`measure_rankings` also gives Kendall's τ of
that order against the primary ranking, so a reader sees where the measures agree.

Imports neither SUMO nor torch; reads no file.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Final

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sumo_ayss.analysis.r157 import r157_share
from sumo_ayss.analysis.seeds import kendall_tau
from sumo_ayss.analysis.stats import wilson_interval
from sumo_ayss.util.errors import ConfigError

__all__ = [
    "MEASURES",
    "MeasureRanking",
    "MeasureSpec",
    "MeasureSummary",
    "R157Row",
    "measure_rankings",
    "r157_rows",
]


@dataclass(frozen=True)
class MeasureSpec:
    """How a measure reads: its column, label, unit and which direction is safer."""

    column: str
    label: str
    unit: str
    higher_is_safer: bool


#: The measures ranked, in report order (the R157 columns are summarised apart).
MEASURES: tuple[MeasureSpec, ...] = (
    MeasureSpec("min_ttc_s", "min TTC (1-D)", "s", True),
    MeasureSpec("min_ttc_2d_s", "min TTC (2-D)", "s", True),
    MeasureSpec("min_thw_s", "min time headway", "s", True),
    MeasureSpec("max_drac_mps2", "max DRAC", "m/s²", False),
    MeasureSpec("vut_max_braking_mps2", "VUT max braking", "m/s²", False),
    MeasureSpec("vut_max_jerk_mps3", "VUT max |jerk|", "m/s³", False),
    MeasureSpec("intrusion_ttc_s", "TTC at lane intrusion", "s", True),
    MeasureSpec("intrusion_gap_m", "gap at lane intrusion", "m", True),
    MeasureSpec("pet_s", "post-encroachment time", "s", True),
    MeasureSpec("impact_speed_mps", "relative speed at impact", "m/s", False),
)

_QUANTILE: Final = "inverted_cdf"  # order statistics: no interpolation with inf


def _median(x: NDArray[np.float64]) -> float:
    """``np.quantile(x, 0.5, method=_QUANTILE)``: the order statistic ``ceil(n / 2)`` (1-based;
    the lower middle of an even ``n``), found by ``np.partition`` without ``np.quantile``'s
    per-call cost (the bootstrap takes it thousands of times per VUT and measure)."""
    k = (x.size + 1) // 2 - 1
    return float(np.partition(x, k)[k])


@dataclass(frozen=True)
class MeasureSummary:
    """One VUT's distribution of one measure under the pool.

    Attributes:
        vut: The VUT.
        n: Episodes where the measure is defined.
        n_total: Episodes of the VUT in the table.
        median, lo, hi: The median and its bootstrap interval (NaN with ``n = 0``).
        p10, p90: 10th and 90th percentiles.
        share_inf: Share of the defined episodes with an infinite value.
        rank: The VUT's rank by this measure's median alone (1 = safest; ties share the
            better rank; 0 when undefined).
    """

    vut: str
    n: int
    n_total: int
    median: float
    lo: float
    hi: float
    p10: float
    p90: float
    share_inf: float
    rank: int = 0


@dataclass(frozen=True)
class MeasureRanking:
    """One measure across the VUTs.

    Attributes:
        spec: The measure.
        rows: One :class:`MeasureSummary` per VUT, in the given VUT order.
        order: VUTs safest first by the median (VUTs without a value left out).
        tau: Kendall's τ of ``order`` against the primary order (NaN with fewer than two
            VUTs in common, or when the order has ties).
        ties: Whether two VUTs share a median (the order then is not a ranking).
    """

    spec: MeasureSpec
    rows: tuple[MeasureSummary, ...]
    order: tuple[str, ...]
    tau: float
    ties: bool


def _bootstrap_median(
    groups: Sequence[NDArray[np.float64]], n_boot: int, rng: np.random.Generator, level: float
) -> tuple[float, float]:
    groups = [g for g in groups if g.size]
    if not groups:
        return math.nan, math.nan
    reps = np.empty(n_boot)
    for b in range(n_boot):
        chosen = rng.integers(0, len(groups), len(groups))
        pooled = np.concatenate(
            [groups[i][rng.integers(0, groups[i].size, groups[i].size)] for i in chosen]
        )
        reps[b] = _median(pooled)
    tail = 0.5 * (1.0 - level)
    lo, hi = np.quantile(reps, [tail, 1.0 - tail], method=_QUANTILE)
    return float(lo), float(hi)


def _summary(
    vut: str,
    values: NDArray[np.float64],
    groups: NDArray[np.int64],
    n_boot: int,
    rng: np.random.Generator,
    level: float,
) -> MeasureSummary:
    defined = ~np.isnan(values)
    x = values[defined]
    if x.size == 0:
        nan = math.nan
        return MeasureSummary(vut, 0, int(values.size), nan, nan, nan, nan, nan, nan)
    g = groups[defined]
    lo, hi = _bootstrap_median([x[g == k] for k in np.unique(g)], n_boot, rng, level)
    p10, p90 = np.quantile(x, [0.1, 0.9], method=_QUANTILE)
    return MeasureSummary(
        vut,
        int(x.size),
        int(values.size),
        _median(x),
        lo,
        hi,
        float(p10),
        float(p90),
        float(np.isinf(x).mean()),
    )


def _ranked(spec: MeasureSpec, rows: list[MeasureSummary]) -> tuple[list[MeasureSummary], bool]:
    valued = [r for r in rows if r.n > 0]
    sign = -1.0 if spec.higher_is_safer else 1.0
    key = {r.vut: sign * r.median for r in valued}

    def below(x: float, y: float) -> bool:
        """``x < y`` beyond float noise: medians computed by different float paths
        (5.999999999999997 vs 6.000000000000003) are a tie, not a ranking."""
        return x < y and not math.isclose(x, y, rel_tol=1e-9, abs_tol=1e-12)

    ranks: dict[str, int] = {}
    for r in valued:
        ranks[r.vut] = 1 + sum(1 for other in valued if below(key[other.vut], key[r.vut]))
    ties = any(
        not below(key[a], key[b]) and not below(key[b], key[a])
        for a, b in itertools.combinations(key, 2)
    )
    out = [replace(r, rank=ranks.get(r.vut, 0)) for r in rows]
    return out, ties


def measure_rankings(
    vut: ArrayLike,
    group: ArrayLike,
    columns: Mapping[str, ArrayLike],
    *,
    vuts: Sequence[str],
    primary_order: Sequence[str] = (),
    level: float = 0.95,
    n_boot: int = 1000,
    seed: int = 0,
) -> list[MeasureRanking]:
    """Every measure's per-VUT distribution and ranking.

    Args:
        vut: The VUT of each episode (table column).
        group: The opponent of each episode, any hashable label per row (the bootstrap's
            unit); a VUT's own SPCPs' seeds where the pool is its own SPCPs.
        columns: Measure column name -> per-episode values (the table's columns); a
            measure without a column is left out.
        vuts: The VUTs, in display order.
        primary_order: The primary ranking, safest first, for Kendall's τ.
        level: Interval level.
        n_boot: Bootstrap replicates.
        seed: Bootstrap seed (the summaries are reproducible).

    Returns:
        One :class:`MeasureRanking` per measure of :data:`MEASURES` that has a column.
    """
    names = np.asarray(vut).astype(str)
    labels = np.unique(np.asarray(group).astype(str), return_inverse=True)[1].astype(np.int64)
    if labels.size != names.size:
        raise ConfigError(f"vut and group: {names.size} and {labels.size} rows")
    out: list[MeasureRanking] = []
    for spec in MEASURES:
        if spec.column not in columns:
            continue
        values = np.asarray(columns[spec.column], dtype=np.float64)
        rng = np.random.default_rng(seed)
        rows = [
            _summary(v, values[names == v], labels[names == v], n_boot, rng, level) for v in vuts
        ]
        rows, ties = _ranked(spec, rows)
        order = tuple(r.vut for r in sorted((r for r in rows if r.rank), key=lambda r: r.rank))
        common = [v for v in primary_order if v in order]
        tau = (
            kendall_tau([v for v in order if v in common], common)
            if len(common) >= 2 and not ties
            else math.nan
        )
        out.append(MeasureRanking(spec, tuple(rows), order, tau, ties))
    return out


@dataclass(frozen=True)
class R157Row:
    """One VUT under UN R157's cut-in TTC condition (:mod:`sumo_ayss.analysis.r157`).

    Attributes:
        vut: The VUT.
        n_intrusions: Episodes with a 0.3 m lane intrusion.
        n_required: Of those, the cut-ins the condition says must be handled.
        n_handled: Of those, the ones without a collision.
        share, lo, hi: ``n_handled / n_required`` with its Wilson interval (NaN when none
            was required).
    """

    vut: str
    n_intrusions: int
    n_required: int
    n_handled: int
    share: float
    lo: float
    hi: float


def r157_rows(
    vut: ArrayLike,
    must_avoid: ArrayLike,
    collided: ArrayLike,
    *,
    vuts: Sequence[str],
    level: float = 0.95,
) -> list[R157Row]:
    """Per VUT, the cut-ins R157's TTC condition requires handling and the share handled."""
    names = np.asarray(vut).astype(str)
    must = np.asarray(must_avoid, dtype=np.float64)
    crashed = np.asarray(collided, dtype=bool)
    out = []
    for v in vuts:
        sel = names == v
        s = r157_share(must[sel], crashed[sel])
        lo, hi = (
            wilson_interval(s.n_handled, s.n_required, level)
            if s.n_required
            else (math.nan, math.nan)
        )
        n_in = int((~np.isnan(must[sel])).sum())
        out.append(R157Row(v, n_in, s.n_required, s.n_handled, s.share, lo, hi))
    return out
