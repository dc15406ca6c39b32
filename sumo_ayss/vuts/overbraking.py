"""A degenerate VUT that brakes hard whenever a leader comes near (issue 33).

:class:`OverBraker` is the controller the issue's new user tried: it brakes at
``brake_mps2`` (6 m/s²) whenever its leader is within ``near_thw_s`` (2 s) of time headway
(plus ``standstill_m``), closing in or not, and otherwise drives up to ``cruise_mps`` at
``accel_mps2``. In car-following the leader sets the pace, so its mean speed stays close to
the others' while it keeps every gap wide: with nobody behind it, braking is free and it
looked safest. It exists to test that the ranking sees what it does to the traffic behind it
(:mod:`sumo_ayss.analysis.hazards`) and flags it (OVER-BRAKING, ``docs/ranking.md``).

:data:`~sumo_ayss.vuts.reference_types.OVERBRAKER_VUT` is its catalog entry (SUMO's
passenger body): a pipeline that names ``overbraker`` in ``grid.vuts`` ranks it
(``configs/overbraking.yaml``).
"""

from __future__ import annotations

from dataclasses import dataclass

from sumo_ayss.vuts.controllers import ControllerInput

__all__ = ["OverBraker"]


@dataclass
class OverBraker:
    """Brakes hard whenever a leader is near; otherwise drives up to a cruise speed.

    Attributes:
        near_thw_s: A leader closer than this time headway (plus ``standstill_m``) is "near".
        standstill_m: The distance kept at rest [m].
        brake_mps2: Its braking while a leader is near [m/s²], > 0.
        accel_mps2: Its acceleration otherwise [m/s²], > 0.
        cruise_mps: The speed it drives up to [m/s] (the road's limit).
    """

    near_thw_s: float = 2.0
    standstill_m: float = 2.0
    brake_mps2: float = 6.0
    accel_mps2: float = 2.0
    cruise_mps: float = 30.0

    def acceleration(self, state: ControllerInput) -> float:
        """``-brake_mps2`` with a near leader, else toward ``cruise_mps`` [m/s²]."""
        if state.has_leader and state.gap_m < self.standstill_m + self.near_thw_s * (
            state.speed_mps
        ):
            return -self.brake_mps2
        return min(self.accel_mps2, (self.cruise_mps - state.speed_mps) / state.dt_s)
