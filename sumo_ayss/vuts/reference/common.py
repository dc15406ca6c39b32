"""What the reference drivers share: geometry of the object list, the braking profile and
its exact mean over a step, parameter checks. Units: m, s, m/s, m/s²; lateral + = left."""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from sumo_ayss.sim.sensing import SensedObject
from sumo_ayss.util.errors import ConfigError
from sumo_ayss.vuts.controllers import ControllerInput

__all__ = [
    "G_MPS2",
    "OWN_WIDTH_M",
    "Ramp",
    "ahead",
    "check_param",
    "in_lane",
    "lead_of",
    "mean_of_max",
    "ttc_s",
]

#: Standard gravity [m/s²] (0.774 g = 7.593 m/s², 0.85 g = 8.338 m/s²).
G_MPS2 = 9.81

#: Default width of the own body [m] where a driver needs it (SUMO's passenger default).
OWN_WIDTH_M = 1.8

# The catalog entries that name these classes (``cc_driver``, ``fsm``, ``rss``) are
# :data:`sumo_ayss.vuts.reference_types.REFERENCE_VUTS`.


# ----------------------------------------------------------------------------- geometry


def in_lane(o: SensedObject, lane_width_m: float) -> bool:
    """The object's body reaches into the own lane (between its edges)."""
    half = 0.5 * (lane_width_m if math.isfinite(lane_width_m) else 3.2)
    return abs(o.lateral_offset_m) < half + 0.5 * o.width_m


def ahead(o: SensedObject) -> bool:
    """The object's front is ahead of the own front."""
    return o.gap_m + o.length_m > 0.0


def ttc_s(gap_m: float, rel_speed_mps: float) -> float:
    """Longitudinal TTC [s] from a bumper gap and the object's relative speed (< 0 closing)."""
    if gap_m <= 0.0:
        return 0.0
    return gap_m / -rel_speed_mps if rel_speed_mps < 0.0 else math.inf


def lead_of(state: ControllerInput) -> SensedObject | None:
    """The nearest object ahead whose body reaches into the own lane (the leader)."""
    best: SensedObject | None = None
    for o in state.objects:
        if ahead(o) and in_lane(o, state.lane_width_m) and (best is None or o.gap_m < best.gap_m):
            best = o
    if best is None and state.has_leader:  # a view without an object list (older callers)
        best = SensedObject(state.gap_m, 0.0, state.rel_speed_mps, 0.0, 5.0, OWN_WIDTH_M)
    return best


# ----------------------------------------------------------------------------- profile


@dataclass
class Ramp:
    """A braking profile: ``decel(t) = min(peak, peak · (t - t0) / ramp_s)`` for t >= t0."""

    t0: float
    peak: float
    ramp_s: float

    def at(self, t: float) -> float:
        if t <= self.t0:
            return 0.0
        if self.ramp_s <= 0.0:
            return self.peak
        return min(self.peak, self.peak * (t - self.t0) / self.ramp_s)

    def breaks(self) -> tuple[float, float]:
        return (self.t0, self.t0 + max(self.ramp_s, 0.0))


def mean_of_max(parts: Sequence[tuple[Any, Sequence[float]]], t0: float, t1: float) -> float:
    """Exact mean over ``[t0, t1]`` of ``max_i f_i(t)`` for piecewise-linear ``f_i``.

    ``parts``: ``(f, breakpoints)`` pairs; each ``f_i`` is linear between its breakpoints
    (it may jump at one). On each piece between breakpoints every ``f_i`` is read at two
    interior points (which defines its line without touching a jump); their upper envelope
    is split where two lines cross, and each linear piece's mean is its midpoint value.
    """
    pts = {t0, t1}
    for _f, br in parts:
        pts.update(b for b in br if t0 < b < t1)
    grid = sorted(pts)
    total = 0.0
    for a, b in itertools.pairwise(grid):
        w = b - a
        lines = []
        for f, _ in parts:
            y1, y3 = f(a + 0.25 * w), f(a + 0.75 * w)
            slope = (y3 - y1) / (0.5 * w)
            lines.append((y1 - slope * 0.25 * w, slope))  # value at a, slope
        cuts = [a, b]
        for i in range(len(lines)):
            for j in range(i + 1, len(lines)):
                dv, ds = lines[i][0] - lines[j][0], lines[i][1] - lines[j][1]
                if ds != 0.0 and 0.0 < -dv / ds < w:
                    cuts.append(a - dv / ds)
        cuts.sort()
        for c, d in itertools.pairwise(cuts):
            mid = 0.5 * (c + d) - a
            total += (d - c) * max(v + s * mid for v, s in lines)
    return total / (t1 - t0)


def check_param(name: str, value: Any, *, low: float, strict: bool = False) -> None:
    ok = isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)
    if not ok or value < low or (strict and value == low):
        rel = ">" if strict else ">="
        raise ConfigError(
            f"reference driver: {name} must be a finite number {rel} {low:g}, got {value!r}"
        )
