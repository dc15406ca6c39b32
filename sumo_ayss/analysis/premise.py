"""The method's premise: did the SPCPs of different VUTs reach the same overall outcome?

The paper reads a VUT's safety from how aggressive its SPCP is *at an equal overall safety
outcome*. When the SPCPs of two VUTs end with different outcomes (mean episode reward, crash
rate, final headway), a difference in aggressiveness may reflect the outcome, not the VUT:
the aggressiveness comparison is confounded. This module checks the premise per case.

Rule: for each metric, every VUT's seed mean (one SPCP per seed, t-interval over seeds,
clipped to the metric's possible range, none with fewer than three seeds) is
computed; the premise holds for the metric when the spread of the VUT means (max - min) is
within the metric's tolerance, and for the case when it holds for every metric. The
tolerances are a statement of what "about the same outcome" means, not a test: they are
report options, printed next to the verdict.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from sumo_ayss.analysis.seed_intervals import UNBOUNDED, Bounds, seed_mean_ci
from sumo_ayss.util.errors import ConfigError

__all__ = ["PREMISE_METRICS", "Premise", "PremiseMetric", "PremiseMetricSpec", "premise_check"]


@dataclass(frozen=True)
class PremiseMetricSpec:
    """A premise metric: its key, name, unit, scale for display and default tolerance.

    Attributes:
        key: Key in the per-metric input mapping.
        name: Human name.
        unit: Display unit ("" for reward, "%" for rates, "m").
        scale: Multiplier from the stored value to the display unit (100 for rates).
        tolerance: Default tolerance on the spread of VUT means, in the stored unit.
        bounds: The metric's possible range, stored unit (``(0, 1)`` for a rate); the
            intervals over seeds are clipped to it.
    """

    key: str
    name: str
    unit: str
    scale: float
    tolerance: float
    bounds: Bounds = UNBOUNDED


PREMISE_METRICS: tuple[PremiseMetricSpec, ...] = (
    PremiseMetricSpec("mean_return", "mean episode reward", "", 1.0, 1.0),
    PremiseMetricSpec("crash_rate", "crash rate", "%", 100.0, 0.02, (0.0, 1.0)),
    PremiseMetricSpec("mean_final_headway_m", "mean final headway", "m", 1.0, 2.0),
)
"""Metrics of the premise check with their default tolerances: reward within 1.0 per
episode (about 5 % of a converged car-following SPCP's return), crash rate within 2
percentage points, final headway within 2 m."""


@dataclass(frozen=True)
class PremiseMetric:
    """The premise on one metric.

    Attributes:
        spec: Which metric.
        tolerance: Tolerance used, stored unit.
        per_vut: VUT -> ``(mean, lo, hi, n_seeds)`` over its seeds (t-interval clipped to
            the metric's possible range; NaN bounds with fewer than three seeds).
        spread: Max minus min of the VUT means; NaN with fewer than two VUTs.
        met: Whether ``spread <= tolerance`` (False when undefined).
    """

    spec: PremiseMetricSpec
    tolerance: float
    per_vut: Mapping[str, tuple[float, float, float, int]]
    spread: float
    met: bool


@dataclass(frozen=True)
class Premise:
    """The premise check of one case.

    Attributes:
        metrics: One entry per metric with data.
        met: Whether every metric met its tolerance (False without metrics).
    """

    metrics: tuple[PremiseMetric, ...]
    met: bool

    def failed(self) -> list[PremiseMetric]:
        """The metrics whose spread exceeds their tolerance."""
        return [m for m in self.metrics if not m.met]


def premise_check(
    values: Mapping[str, Mapping[str, Sequence[float]]],
    *,
    tolerances: Mapping[str, float] | None = None,
    level: float = 0.95,
) -> Premise:
    """Checks whether the VUTs' SPCPs reached the same overall outcome.

    Args:
        values: Metric key (see :data:`PREMISE_METRICS`) -> VUT -> one value per seed (the
            seed's SPCP outcome). Non-finite values are ignored; a metric without two VUTs
            with data is left out.
        tolerances: Metric key -> tolerance on the spread of VUT means, stored unit;
            defaults from :data:`PREMISE_METRICS`.
        level: Confidence level of the per-VUT intervals.

    Returns:
        The :class:`Premise`.

    Raises:
        ConfigError: On an unknown metric key or a negative / non-finite tolerance.
    """
    specs = {s.key: s for s in PREMISE_METRICS}
    tol = {k: s.tolerance for k, s in specs.items()}
    for key, value in (tolerances or {}).items():
        if key not in specs:
            raise ConfigError(f"tolerances: unknown metric {key!r}; allowed: {sorted(specs)}")
        if not (math.isfinite(value) and value >= 0):
            raise ConfigError(f"tolerances.{key} must be a finite number >= 0, got {value!r}")
        tol[key] = float(value)
    metrics = []
    for key, by_vut in values.items():
        if key not in specs:
            raise ConfigError(f"values: unknown metric {key!r}; allowed: {sorted(specs)}")
        per_vut: dict[str, tuple[float, float, float, int]] = {}
        for vut, seeds in by_vut.items():
            arr = np.asarray([v for v in seeds if v is not None and math.isfinite(v)], float)
            if arr.size:
                mean, lo, hi = seed_mean_ci(arr, level, bounds=specs[key].bounds)
                per_vut[vut] = (mean, lo, hi, int(arr.size))
        if len(per_vut) < 2:
            continue
        means = [m[0] for m in per_vut.values()]
        spread = max(means) - min(means)
        metrics.append(PremiseMetric(specs[key], tol[key], per_vut, spread, spread <= tol[key]))
    return Premise(tuple(metrics), bool(metrics) and all(m.met for m in metrics))
