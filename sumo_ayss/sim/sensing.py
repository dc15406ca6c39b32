"""What a controller VUT's sensors read (:meth:`sumo_ayss.sim.pair.VehiclePair.vut_sensing`),
and the reading of further POVs beside a pair (:mod:`sumo_ayss.sim.second_pov`)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import NamedTuple

import libsumo
from libsumo import _libsumo

from sumo_ayss.sim.session import SUMO_ERRORS
from sumo_ayss.util.errors import SimulationError

__all__ = ["SensedObject", "VutSensing", "sense_extra_povs"]

_get_lane_pos = _libsumo.vehicle_getLanePosition
_get_speed = _libsumo.vehicle_getSpeed
_get_lane_index = _libsumo.vehicle_getLaneIndex
_get_lateral_speed = _libsumo.vehicle_getLateralSpeed
_get_lateral_lane_pos = _libsumo.vehicle_getLateralLanePosition


def sense_extra_povs(
    ids: Sequence[str],
    vut: str,
    range_m: float,
    geometry: tuple[list[float], list[float]],
    leader: tuple[float, float],
    objects: tuple[SensedObject, ...],
) -> tuple[tuple[float, float], tuple[SensedObject, ...]]:
    """The VUT's reading of the further POVs ``ids``, read like the pair's POV: each one in
    range joins ``objects``; the nearest vehicle ahead whose body reaches into the VUT's
    lane within range is the leader ``(gap_m, speed_mps)`` (``leader``: the pair's POV's,
    ``(inf, nan)`` without one). ``geometry``: the lanes' centres and widths [m]."""
    centres, widths = geometry
    try:
        vut_pos, vut_speed = _get_lane_pos(vut), _get_speed(vut)
        vut_lane = _get_lane_index(vut)
        vut_centre = centres[vut_lane] + _get_lateral_lane_pos(vut)
        lat_vut = _get_lateral_speed(vut)
    except SUMO_ERRORS as e:
        raise SimulationError(f"reading {vut} failed: {e}") from e
    for vid in ids:
        try:
            pos, speed = _get_lane_pos(vid), _get_speed(vid)
            centre = centres[_get_lane_index(vid)] + _get_lateral_lane_pos(vid)
            width, length = libsumo.vehicle.getWidth(vid), libsumo.vehicle.getLength(vid)
            lateral = _get_lateral_speed(vid) - lat_vut
        except SUMO_ERRORS as e:
            raise SimulationError(f"reading {vid} failed: {e}") from e
        gap = pos - length - vut_pos
        if -range_m <= gap <= range_m:
            offset = centre - centres[vut_lane]
            obj = SensedObject(gap, offset, speed - vut_speed, lateral, length, width)
            objects = (*objects, obj)
        reach = 0.5 * (widths[vut_lane] + width)
        ahead = abs(centre - vut_centre) < reach and pos > vut_pos and gap <= range_m
        if ahead and gap < leader[0]:
            leader = (gap, speed)
    return leader, objects


class VutSensing(NamedTuple):
    """A reading of the VUT's own sensors (:meth:`VehiclePair.vut_sensing`).

    Attributes:
        time_s: Simulation time of the reading [s] (SUMO's time after the last step).
        speed_mps: The VUT's speed [m/s].
        lane_index: The VUT's lane (0 = rightmost).
        gap_m: Bumper-to-bumper gap to the leader [m], leader rear minus VUT front;
            ``inf`` without a leader.
        leader_speed_mps: The leader's speed [m/s]; NaN without a leader.
        objects: The other vehicles within sensor range, in any lane (an object list).
        lane_width_m: Width of the VUT's lane [m]; NaN where unknown.
    """

    time_s: float
    speed_mps: float
    lane_index: int
    gap_m: float
    leader_speed_mps: float
    objects: tuple[SensedObject, ...] = ()
    lane_width_m: float = math.nan


class SensedObject(NamedTuple):
    """One vehicle of the VUT's object list, in the VUT's road frame.

    Attributes:
        gap_m: Longitudinal gap [m], the object's rear bumper minus the VUT's front bumper:
            > 0 ahead; <= 0 while the object is beside (or behind) the VUT's front.
        lateral_offset_m: The object's centre line from the centre line of the VUT's lane
            [m], + = left (0: centred in the VUT's lane; about one lane width: centred in
            the next lane).
        rel_speed_mps: Object's longitudinal speed minus the VUT's [m/s]; < 0 closing in.
        lateral_speed_mps: Object's lateral speed relative to the VUT [m/s], + = left.
        length_m: Object's length [m].
        width_m: Object's width [m].
    """

    gap_m: float
    lateral_offset_m: float
    rel_speed_mps: float
    lateral_speed_mps: float
    length_m: float
    width_m: float
