"""A worked example of a user controller as the VUT: ACC with a constant time-gap policy.

The controller follows the protocol of :mod:`sumo_ayss.vuts.controllers`: it is built from
keyword arguments, sees only its own speed, the gap and relative speed to its leader, its
lane and the clock, and returns an acceleration [m/s²] (> 0 forward, < 0 braking).

Control law (units m, s, m/s, m/s²)::

    with a leader:     a_gap    = k_gap · (gap − s0 − T·v) + k_rel · Δv
    always:            a_cruise = k_cruise · (v_set − v)
    command:           a = clip(min(a_gap, a_cruise), −b_max, a_max)

with ``gap`` the bumper-to-bumper gap to the leader, ``Δv = v_leader − v`` (> 0: the gap
opens), ``s0`` the standstill gap and ``T`` the time gap. In steady state behind a leader at
constant speed v the gap settles at ``s0 + T·v``, so a larger ``T`` keeps a larger gap.
The gap error dynamics ``e'' + (k_rel + k_gap·T)·e' + k_gap·e = 0`` are overdamped with the
defaults (k_gap = 0.3 s⁻², k_rel = 0.8 s⁻¹, T = 1.5 s: poles −0.33 and −0.92 s⁻¹).

Use it as a VUT from YAML (run from the repository root, so that ``examples`` imports)::

    env:
      vut: acc_tg2
      vuts:
        acc_tg2:
          description: constant time-gap ACC, T = 2 s
          controller:
            target: examples.acc_controller:TimeGapACC
            params: {time_gap_s: 2.0}
            max_accel_mps2: 3.0
            max_decel_mps2: 6.0

or from Python: ``VehicleType(controller=ControllerSpec("examples/acc_controller.py:
TimeGapACC", 3.0, 6.0, params={"time_gap_s": 2.0}))``.
"""

from __future__ import annotations

from dataclasses import dataclass

from sumo_ayss.vuts.controllers import ControllerInput


@dataclass
class TimeGapACC:
    """Adaptive cruise control with a constant time-gap spacing policy.

    Attributes:
        time_gap_s: Time gap T [s] of the spacing policy, > 0.
        standstill_gap_m: Gap s0 kept at standstill [m], >= 0 (bumper to bumper).
        gap_gain: k_gap [1/s²] on the spacing error ``gap − s0 − T·v``.
        rel_speed_gain: k_rel [1/s] on the relative speed ``v_leader − v``.
        set_speed_mps: Cruise (set) speed v_set [m/s] without a leader.
        cruise_gain: k_cruise [1/s] of the cruise (speed) control.
        max_accel_mps2: Comfort acceleration limit of the controller [m/s²], > 0.
        max_decel_mps2: Braking limit of the controller [m/s²], a positive number. The
            testbed additionally clips to the vehicle's declared limits.
    """

    time_gap_s: float = 1.5
    standstill_gap_m: float = 5.0
    gap_gain: float = 0.3
    rel_speed_gain: float = 0.8
    set_speed_mps: float = 30.0
    cruise_gain: float = 0.4
    max_accel_mps2: float = 3.0
    max_decel_mps2: float = 6.0

    def __post_init__(self) -> None:
        if not self.time_gap_s > 0:
            raise ValueError(f"time_gap_s must be > 0, got {self.time_gap_s}")
        if not self.standstill_gap_m >= 0:
            raise ValueError(f"standstill_gap_m must be >= 0, got {self.standstill_gap_m}")
        if not (self.max_accel_mps2 > 0 and self.max_decel_mps2 > 0):
            raise ValueError("max_accel_mps2 and max_decel_mps2 must be > 0")

    def reset(self) -> None:
        """Start of an episode: this controller keeps no state, nothing to do."""

    def desired_gap_m(self, speed_mps: float) -> float:
        """Spacing policy: the gap [m] wanted at ``speed_mps``, ``s0 + T·v``."""
        return self.standstill_gap_m + self.time_gap_s * speed_mps

    def acceleration(self, state: ControllerInput) -> float:
        """Acceleration command [m/s²] for the next step (see the module docstring)."""
        v = state.speed_mps
        accel = self.cruise_gain * (self.set_speed_mps - v)
        if state.has_leader:
            spacing_error = state.gap_m - self.desired_gap_m(v)
            accel = min(
                accel, self.gap_gain * spacing_error + self.rel_speed_gain * state.rel_speed_mps
            )
        return min(max(accel, -self.max_decel_mps2), self.max_accel_mps2)
