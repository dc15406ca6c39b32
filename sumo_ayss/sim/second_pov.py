"""A second POV beside a :class:`~sumo_ayss.sim.pair.VehiclePair` (case ``lead_and_cut_in``).

Added, inserted and placed like the pair's own vehicles (a fresh vehicle per episode at an
insertable spot, one SUMO step, then ``moveTo`` + ``setPreviousSpeed``), driven like the
pair's POV (speed mode 0: the env's actuator bounds it; lane-change mode 0: it changes lane
only when commanded, by force). Registered on the pair (:attr:`VehiclePair.extra_povs`)
so that a controller VUT's sensors see it (:meth:`VehiclePair.vut_sensing`); SUMO's own
car-following VUTs see it as any vehicle.
"""

from __future__ import annotations

import contextlib
from typing import NamedTuple

import libsumo
from libsumo import _libsumo

from sumo_ayss.config import ActuatorConfig
from sumo_ayss.sim.actuator import next_speed, pov_acceleration
from sumo_ayss.sim.pair import LC_MODE_NONE, SPEED_MODE_UNCHECKED, VehiclePair
from sumo_ayss.sim.session import SUMO_ERRORS
from sumo_ayss.util.errors import SimulationError

__all__ = ["SECOND_POV_INSERT_POS_M", "SecondPov", "SecondPovState"]

#: Where the second POV is inserted (front position [m]), downstream of the pair's two
#: (10 m and 60 m), before being moved into place.
SECOND_POV_INSERT_POS_M = 110.0

_get_lane_pos = _libsumo.vehicle_getLanePosition
_get_speed = _libsumo.vehicle_getSpeed
_get_lane_index = _libsumo.vehicle_getLaneIndex
_get_lateral_speed = _libsumo.vehicle_getLateralSpeed
_get_lateral_lane_pos = _libsumo.vehicle_getLateralLanePosition
_set_speed = _libsumo.vehicle_setSpeed


class SecondPovState(NamedTuple):
    """What a step reads back of the second POV (front bumper; m, m/s).

    Attributes:
        pos_m: Front-bumper lane position [m].
        speed_mps: Longitudinal speed [m/s].
        lane: SUMO lane index of its front (0 = rightmost).
        lateral_offset_m: Offset from its lane's centre line [m], + = left.
        lateral_speed_mps: Lateral speed over the last step [m/s], + = left.
    """

    pos_m: float
    speed_mps: float
    lane: int
    lateral_offset_m: float
    lateral_speed_mps: float


class SecondPov:
    """The second POV of one pair, a fresh SUMO vehicle per episode.

    Args:
        pair: The pair it drives beside (its session, road, route and id prefix).
        vtype: Its vType id (loaded by the session).
        tag: Id part after the pair's prefix, e.g. ``"pov2"``.
    """

    def __init__(self, pair: VehiclePair, vtype: str, tag: str = "pov2") -> None:
        self.pair = pair
        self.vtype = vtype
        self.tag = tag
        self.id = ""

    def add(self) -> None:
        """Remove the last episode's vehicle and add a fresh one (inserted by the next
        step); call after the pair's :meth:`~VehiclePair.add` (same episode number)."""
        self.remove()
        pair = self.pair
        self.id = f"{pair.prefix}.{self.tag}.{pair.episode}"
        try:
            libsumo.vehicle.add(
                self.id, pair.route, self.vtype, "now", "0", str(SECOND_POV_INSERT_POS_M), "0"
            )
        except SUMO_ERRORS as e:
            raise SimulationError(f"adding {self.id} failed: {e}") from e
        pair.extra_povs = (self.id,)

    def place(self, lane: int, pos_m: float, speed_mps: float) -> None:
        """Put the freshly inserted vehicle's front at ``pos_m`` on ``lane`` at ``speed_mps``."""
        vid, edge = self.id, self.pair.edge
        try:
            libsumo.vehicle.setLaneChangeMode(vid, LC_MODE_NONE)
            libsumo.vehicle.setSpeedMode(vid, SPEED_MODE_UNCHECKED)
            libsumo.vehicle.moveTo(vid, f"{edge}_{lane}", pos_m)
            libsumo.vehicle.setPreviousSpeed(vid, speed_mps)
        except SUMO_ERRORS as e:
            raise SimulationError(
                f"placing {vid} at {pos_m} m on lane {lane} failed ({e}); was it inserted?"
            ) from e

    def remove(self) -> None:
        """Remove the vehicle if it is still in the simulation."""
        if self.id:
            with contextlib.suppress(*SUMO_ERRORS):
                libsumo.vehicle.remove(self.id)
        self.id = ""
        self.pair.extra_povs = ()

    def command_speed(self, speed_mps: float) -> None:
        """It drives at exactly ``speed_mps`` during the next step (checks are off)."""
        _set_speed(self.id, speed_mps)

    def drive_toward(
        self, speed_mps: float, target_mps: float, dt_s: float, actuator: ActuatorConfig
    ) -> tuple[float, float]:
        """Command the next step on the POV actuator (``env.actuator``, clipped): from
        ``speed_mps`` toward ``target_mps`` over ``dt_s`` [s]. Returns ``(acceleration
        [m/s²], speed [m/s] it will drive)``, the model state the caller keeps."""
        accel = pov_acceleration(speed_mps, target_mps, actuator)
        speed = next_speed(speed_mps, accel, dt_s, actuator)
        self.command_speed(speed)
        return accel, speed

    def change_lane(self, lane: int, request_s: float) -> None:
        """Start a forced, continuous change to ``lane`` (``--lanechange.duration``)."""
        try:
            libsumo.vehicle.changeLane(self.id, lane, request_s)
        except SUMO_ERRORS as e:
            raise SimulationError(f"lane change of {self.id} failed: {e}") from e

    def state(self) -> SecondPovState:
        """Its state after the last step."""
        vid = self.id
        try:
            return SecondPovState(
                _get_lane_pos(vid),
                _get_speed(vid),
                _get_lane_index(vid),
                float(_get_lateral_lane_pos(vid)),
                float(_get_lateral_speed(vid)),
            )
        except SUMO_ERRORS as e:
            raise SimulationError(f"{vid} vanished from SUMO ({e}): did it leave the road?") from e
