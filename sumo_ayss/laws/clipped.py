"""The POV on our actuator (``env.actuator.mode: clipped``, the default).

Once per SUMO step: ``a = clip((v_target − v)/time_constant_s, accel_min, accel_max)``,
``v' = clip(v + a·dt, 0, max_speed_mps)`` (:mod:`sumo_ayss.sim.actuator`), and SUMO drives
``v'`` exactly during the step (speed mode 0). Lane changes are SUMO's: a forced change
with a constant lateral speed over ``env.sim.lanechange_duration_s``.
"""

from __future__ import annotations

from sumo_ayss.config import ActuatorConfig, EnvConfig
from sumo_ayss.laws.base import PovLaw
from sumo_ayss.sim.actuator import next_speed, pov_acceleration
from sumo_ayss.sim.pair import VehiclePair
from sumo_ayss.vuts.hwenv_kinematics import KinematicState

__all__ = ["LATERAL_EPS", "ClippedPov"]

#: |lateral offset| [m] or |lateral speed| [m/s] below which the POV counts as not changing.
LATERAL_EPS = 1e-9


class ClippedPov(PovLaw):
    """Our bounded speed law for the POV, evaluated once per SUMO step.

    Args:
        actuator: The POV's actuator section (``env.actuator``).
        step_length_s: SUMO step [s].
        length_m: The POV's length [m].
    """

    def __init__(self, actuator: ActuatorConfig, step_length_s: float, length_m: float) -> None:
        self._actuator = actuator
        self._dt_s = step_length_s
        self._substeps = actuator.substeps
        self._half_length_m = 0.5 * length_m
        self._speed_mps = 0.0  # the commanded speed [m/s]
        self._accel_mps2 = 0.0  # the acceleration of the last step [m/s²]

    @classmethod
    def from_config(cls, config: EnvConfig) -> ClippedPov:
        return cls(config.actuator, config.sim.step_length_s, config.pov.length_m)

    def start(self, pair: VehiclePair, speed_mps: float) -> None:
        """The actuator starts from the placed speed [m/s]."""
        del pair
        self._speed_mps = speed_mps
        self._accel_mps2 = 0.0

    def command(self, pair: VehiclePair, target_speed_mps: float) -> None:
        """The bounded acceleration toward the target, and the speed SUMO drives next step."""
        actuator = self._actuator
        accel = self._accel_mps2 = pov_acceleration(self._speed_mps, target_speed_mps, actuator)
        v = self._speed_mps = next_speed(self._speed_mps, accel, self._dt_s, actuator)
        pair.command_pov_speed(v)

    def accel_mps2(self, pair: VehiclePair) -> float:
        """The acceleration the actuator commanded for the last step [m/s²]."""
        del pair
        return self._accel_mps2

    def substep_states(self, pair: VehiclePair) -> list[KinematicState]:
        """Constant speed over the step (SUMO's Euler update), heading 0, in its lane."""
        n = self._substeps
        dt = self._dt_s / n
        (x, y), _ = pair.world_fronts()
        x0 = x - self._half_length_m
        v = self._speed_mps
        return [KinematicState(x0 + v * j * dt, y, 0.0, v) for j in range(n + 1)]

    def change_lane(self, pair: VehiclePair, lane: int, request_s: float) -> None:
        """SUMO's forced lane change (lane-change mode 0), requested for ``request_s``."""
        pair.change_pov_lane(lane, request_s)

    def lane_motion(
        self, speed_mps: float, lateral_offset_m: float, lateral_speed_mps: float
    ) -> tuple[float, float, bool]:
        """SUMO's reading as is; changing = off the lane's centre line or moving sideways."""
        changing = abs(lateral_offset_m) > LATERAL_EPS or abs(lateral_speed_mps) > LATERAL_EPS
        return speed_mps, lateral_speed_mps, changing
