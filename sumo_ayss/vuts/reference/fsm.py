"""JRC's Fuzzy Safety Model as a driver (``fsm``): see :class:`FuzzySafetyDriver`."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from sumo_ayss.sim.sensing import SensedObject
from sumo_ayss.util.errors import ConfigError
from sumo_ayss.vuts.controllers import ControllerInput
from sumo_ayss.vuts.reference.common import (
    G_MPS2,
    OWN_WIDTH_M,
    ahead,
    check_param,
    in_lane,
    lead_of,
)

# ----------------------------------------------------------------------------- FSM

__all__ = ["FuzzySafetyDriver"]


@dataclass
class FuzzySafetyDriver:
    """JRC's Fuzzy Safety Model (Mattas et al., AAP 148 (2020) 105794), longitudinal.

    Each reading computes the proactive (PFS) and critical (CFS) fuzzy safety of the
    relevant object (the leader, or a cut-in that passes the relevance filter below):

    * PFS: ``d' = d - margin_dist``; ``d_safe = u_r·τ + u_r²/(2·b_r,min) - u_l²/(2·b_l) +
      margin_safe``; ``d_unsafe = u_r·τ + u_r²/(2·b_r,max) - u_l²/(2·b_l)``; 0 above
      ``d_safe``, 1 below ``d_unsafe``, linear between.
    * CFS (closing in only): with ``a_rF = max(a_r, -b_r,min)`` and ``u_new = u_r + τ·a_rF``:
      if ``u_new < u_l``, 1 when ``d < (u_r - u_l)²/(2|a_r|)``, else 0; otherwise
      ``d_safe = (u_r + a_rF·τ/2 - u_l)·τ + (u_r + a_rF·τ - u_l)²/(2·b_r,min)``, ``d_unsafe``
      the same with ``b_r,max``, linear between.
    * Response, ``reaction_s`` after the first unsafe reading: target deceleration
      ``b_r,min + CFS·(b_r,max - b_r,min)`` when CFS > 0, else ``PFS·b_r,min``, reached at
      ``jerk_mps3`` and capped at ``max_decel_mps2`` (0.774 g); back to holding speed once
      both are 0.
    * Relevance of an object in the next lane (JRC ``FSM_check_safety``): ignored while its
      lateral headway (lateral gap / lateral speed toward the lane) exceeds its longitudinal
      gross headway (gap + both lengths, over the closing speed) by more than 0.1 s.
    """

    reaction_s: float = 0.75
    b_r_min_mps2: float = 4.0
    b_r_max_mps2: float = 6.0
    b_l_mps2: float = 7.0
    margin_dist_m: float = 2.0
    margin_safe_m: float = 2.0
    max_decel_mps2: float = 0.774 * G_MPS2
    jerk_mps3: float = 12.65
    own_length_m: float = 5.0
    own_width_m: float = OWN_WIDTH_M
    _unsafe_since: float | None = field(default=None, init=False, repr=False)
    _decel: float = field(default=0.0, init=False, repr=False)

    def __post_init__(self) -> None:
        for name in ("reaction_s", "margin_dist_m", "margin_safe_m"):
            check_param(name, getattr(self, name), low=0.0)
        for name in ("b_r_min_mps2", "b_r_max_mps2", "b_l_mps2", "max_decel_mps2", "jerk_mps3"):
            check_param(name, getattr(self, name), low=0.0, strict=True)
        if self.b_r_max_mps2 < self.b_r_min_mps2:
            raise ConfigError("fsm: b_r_max_mps2 must be >= b_r_min_mps2")

    def reset(self) -> None:
        self._unsafe_since = None
        self._decel = 0.0

    def pfs(self, gap_m: float, u_r: float, u_l: float) -> float:
        """Proactive fuzzy safety in [0, 1] (1 = unsafe)."""
        tau = self.reaction_s
        d = gap_m - self.margin_dist_m
        common = u_r * tau - u_l**2 / (2.0 * self.b_l_mps2)
        d_safe = common + u_r**2 / (2.0 * self.b_r_min_mps2) + self.margin_safe_m
        d_unsafe = common + u_r**2 / (2.0 * self.b_r_max_mps2)
        return _fuzzy(d, d_safe, d_unsafe)

    def cfs(self, gap_m: float, u_r: float, u_l: float, a_r: float) -> float:
        """Critical fuzzy safety in [0, 1] (1 = unsafe); ``a_r`` own acceleration."""
        if u_r <= u_l:
            return 0.0
        tau = self.reaction_s
        a_rf = max(a_r, -self.b_r_min_mps2)
        u_new = u_r + tau * a_rf
        if u_new < u_l:
            if a_r >= 0.0:
                return 0.0
            return 1.0 if gap_m < (u_r - u_l) ** 2 / (2.0 * abs(a_r)) else 0.0
        first = (u_r + a_rf * tau / 2.0 - u_l) * tau
        d_safe = first + (u_new - u_l) ** 2 / (2.0 * self.b_r_min_mps2)
        d_unsafe = first + (u_new - u_l) ** 2 / (2.0 * self.b_r_max_mps2)
        return _fuzzy(gap_m, d_safe, d_unsafe)

    def _relevant(self, state: ControllerInput) -> SensedObject | None:
        lead = lead_of(state)
        best = lead
        for o in state.objects:
            if not ahead(o) or in_lane(o, state.lane_width_m):
                continue
            toward = -math.copysign(1.0, o.lateral_offset_m) * o.lateral_speed_mps
            if toward <= 0.0:
                continue
            half = 0.5 * (state.lane_width_m if math.isfinite(state.lane_width_m) else 3.2)
            lat_gap = max(abs(o.lateral_offset_m) - 0.5 * o.width_m - half, 0.0)
            lat_headway = lat_gap / toward
            closing = -o.rel_speed_mps
            gross = o.gap_m + o.length_m + self.own_length_m
            long_headway = gross / closing if closing > 0.0 else math.inf
            if lat_headway > long_headway + 0.1:
                continue
            if best is None or o.gap_m < best.gap_m:
                best = o
        return best

    def acceleration(self, state: ControllerInput) -> float:
        """The jerk-limited response [m/s²] for the coming step."""
        o = self._relevant(state)
        target = 0.0
        if o is not None:
            u_r = state.speed_mps
            u_l = u_r + o.rel_speed_mps
            pfs = self.pfs(o.gap_m, u_r, u_l)
            cfs = self.cfs(o.gap_m, u_r, u_l, -self._decel)
            if pfs > 0.0 or cfs > 0.0:
                if self._unsafe_since is None:
                    self._unsafe_since = state.time_s
                if cfs > 0.0:
                    target = self.b_r_min_mps2 + cfs * (self.b_r_max_mps2 - self.b_r_min_mps2)
                else:
                    target = pfs * self.b_r_min_mps2
            else:
                self._unsafe_since = None
        else:
            self._unsafe_since = None
        t, dt = state.time_s, state.dt_s
        since = self._unsafe_since
        if since is None or t + dt <= since + self.reaction_s:
            target_now, start = 0.0, t
        else:
            # The part of the step before the reaction ends keeps the current deceleration.
            target_now, start = min(target, self.max_decel_mps2), max(t, since + self.reaction_s)
        step = self.jerk_mps3 * max(0.0, t + dt - start)
        new = min(max(target_now, self._decel - step), self._decel + step)
        self._decel = new
        return -new


def _fuzzy(d: float, d_safe: float, d_unsafe: float) -> float:
    """0 above ``d_safe``, 1 below ``d_unsafe``, linear between."""
    if d > d_safe:
        return 0.0
    if d < d_unsafe or d_safe <= d_unsafe:
        return 1.0
    return (d - d_safe) / (d_unsafe - d_safe)
