"""One VUT-POV pair on one road of the process's SUMO simulation.

Positions are SUMO lane positions of the *front* bumper along the road [m]; speeds m/s;
lateral positions are world y [m] of the front bumper's centre (lanes run along +x).

Placement recipe (see DESIGN.md, "SUMO facts"): a vehicle added too close to its leader is
silently not inserted, so every episode adds two *fresh* vehicles (stateful car-following
models such as EIDM or ACC start clean) at a far-apart, always-insertable spot upstream,
lets one SUMO step insert them, then ``moveTo`` + ``setPreviousSpeed`` put them exactly at
the requested state. The previous episode's vehicles are removed in that same step; they
are always downstream of the insertion spot, so they cannot block the insertion.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Sequence
from dataclasses import dataclass

import libsumo
from libsumo import _libsumo

from sumo_ayss.sim.follower import VUT_INSERT_POS_WITH_FOLLOWER_M, Follower
from sumo_ayss.sim.sensing import SensedObject, VutSensing, sense_extra_povs
from sumo_ayss.sim.session import SUMO_ERRORS, SumoSession
from sumo_ayss.util.errors import SimulationError

# Hot-path getters bound once to libsumo's compiled functions. The public ``libsumo.vehicle``
# methods are Python wrappers around these; in a 30 µs step the wrapper calls and attribute
# lookups cost as much as the getters themselves (measured: benchmarks/env_throughput.py).
_get_lane_pos = _libsumo.vehicle_getLanePosition
_get_speed = _libsumo.vehicle_getSpeed
_get_accel = _libsumo.vehicle_getAcceleration
_get_lane_index = _libsumo.vehicle_getLaneIndex
_get_position = _libsumo.vehicle_getPosition
_set_speed = _libsumo.vehicle_setSpeed

#: Where new vehicles are inserted (front positions [m]) before being moved into place.
_INSERT_VUT_POS_M = 10.0
_INSERT_POV_POS_M = 60.0

#: SUMO lane-change mode 0: no autonomous lane changes at all (bits 0-7 off), and a
#: TraCI ``changeLane`` request is executed without respecting other drivers (bits 8-9 = 0):
#: the VUT keeps its lane perfectly; the POV changes lane only when commanded, and then
#: by force, because it is the adversary.
LC_MODE_NONE = 0
#: SUMO speed mode 0: every speed check off (safe speed, max accel/decel, speed limit).
#: The POV's limits are ours (:mod:`sumo_ayss.sim.actuator`).
SPEED_MODE_UNCHECKED = 0


@dataclass(frozen=True)
class PairPlacement:
    """Requested state of a pair at the start of an episode.

    Attributes:
        vut_pos_m: VUT front bumper lane position [m].
        vut_speed_mps: VUT speed [m/s].
        vut_lane: VUT lane index (0 = rightmost).
        pov_pos_m: POV front bumper lane position [m].
        pov_speed_mps: POV speed [m/s].
        pov_lane: POV lane index.
    """

    vut_pos_m: float
    vut_speed_mps: float
    vut_lane: int
    pov_pos_m: float
    pov_speed_mps: float
    pov_lane: int


class VehiclePair:
    """A VUT and a POV on ``edge`` of a running :class:`SumoSession`.

    Args:
        session: the process's simulation.
        vut_type: vType id of the VUT (loaded by the session).
        pov_type: vType id of the POV.
        edge: road edge id.
        prefix: vehicle-id prefix, unique per pair in the simulation.
        follower_type: vType id of a follower behind the VUT (:mod:`sumo_ayss.sim.
            follower`), for the episodes that ask for one; None: never a follower.
    """

    def __init__(
        self,
        session: SumoSession,
        vut_type: str,
        pov_type: str,
        edge: str = "road",
        prefix: str = "p0",
        follower_type: str | None = None,
    ) -> None:
        self.session = session
        self.vut_type = vut_type
        self.pov_type = pov_type
        self.edge = edge
        self.prefix = prefix
        self.route = f"route_{edge}"
        self.episode = 0
        self.vut = ""
        self.pov = ""
        self._follower_type = follower_type
        #: This episode's follower, or None (no follower in this episode).
        self.follower: Follower | None = None
        #: Ids of further POVs beside the pair (:mod:`sumo_ayss.sim.second_pov`), which a
        #: controller VUT's sensors see like the POV; empty in the one-POV cases.
        self.extra_povs: tuple[str, ...] = ()

    # ------------------------------------------------------------------ episode set-up

    def add(self, follower: bool = False) -> None:
        """Remove the last episode's vehicles and add fresh ones (inserted by the next step);
        ``follower``: a follower behind the VUT too (the pair needs a ``follower_type``)."""
        self.session.add_route(self.route, [self.edge])
        self.remove()
        self.episode += 1
        self.vut = f"{self.prefix}.vut.{self.episode}"
        self.pov = f"{self.prefix}.pov.{self.episode}"
        vut_pos = _INSERT_VUT_POS_M
        if follower:
            if self._follower_type is None:
                raise SimulationError(f"pair {self.prefix} was built without a follower type")
            self.follower = Follower(self._follower_type, self.prefix)
            vut_pos = VUT_INSERT_POS_WITH_FOLLOWER_M
        add = libsumo.vehicle.add
        try:
            add(self.pov, self.route, self.pov_type, "now", "0", str(_INSERT_POV_POS_M), "0")
            add(self.vut, self.route, self.vut_type, "now", "0", str(vut_pos), "0")
        except SUMO_ERRORS as e:
            raise SimulationError(f"adding pair {self.prefix} failed: {e}") from e
        if self.follower is not None:
            self.follower.add(self.route, self.episode)

    def place(self, p: PairPlacement) -> None:
        """Put the freshly inserted vehicles exactly at ``p`` (call after one step)."""
        try:
            for vid in (self.vut, self.pov):
                libsumo.vehicle.setLaneChangeMode(vid, LC_MODE_NONE)
            libsumo.vehicle.setSpeedMode(self.pov, SPEED_MODE_UNCHECKED)
            libsumo.vehicle.moveTo(self.pov, f"{self.edge}_{p.pov_lane}", p.pov_pos_m)
            libsumo.vehicle.moveTo(self.vut, f"{self.edge}_{p.vut_lane}", p.vut_pos_m)
            libsumo.vehicle.setPreviousSpeed(self.pov, p.pov_speed_mps)
            libsumo.vehicle.setPreviousSpeed(self.vut, p.vut_speed_mps)
            self._start_vut_decisions()
        except SUMO_ERRORS as e:
            raise SimulationError(
                f"placing pair {self.prefix} at {p} failed ({e}); was it inserted? "
                "(a vehicle SUMO could not insert is silently kept waiting)"
            ) from e

    def place_follower(self, lane: int, pos_m: float, speed_mps: float) -> None:
        """Put this episode's follower's front at ``pos_m`` on ``lane`` (after :meth:`place`)."""
        assert self.follower is not None
        self.follower.place(f"{self.edge}_{lane}", pos_m, speed_mps)

    def _start_vut_decisions(self) -> None:
        """The VUT's first decision is the episode's first step, then one every
        ``actionStepLength`` (the testbed's semantics of SUMO's action step; docs/ranking.md).

        SUMO's driver decides only at *action points*, every ``actionStepLength``; between
        them it keeps its last acceleration. Where the first action point falls depends on
        how the vehicle entered the simulation (SUMO: ``MSVehicle::isActionStep``,
        ``(t - myLastActionTime) % actionStepLength == 0``): a vehicle inserted by a step
        and moved into place (the single env) decides in the episode's first step, as one
        departing from a route file does; one placed while still waiting for insertion (the
        vec env) did not, and drove its first second blind (issue 21: 62 % crashes against
        5 %). ``setActionStepLength(id, length, resetActionOffset=True)`` schedules the next
        action point immediately, so every path starts the VUT's decisions alike. A VUT
        whose action step equals the step length decides every step: nothing to align.
        """
        length = libsumo.vehicle.getActionStepLength(self.vut)
        if length > libsumo.simulation.getDeltaT() + 1e-9:
            libsumo.vehicle.setActionStepLength(self.vut, length, True)

    def remove(self) -> None:
        """Remove the pair's vehicles if they are still in the simulation."""
        for vid in (self.vut, self.pov):
            if not vid:
                continue
            with contextlib.suppress(*SUMO_ERRORS):  # gone already (left, or never inserted)
                libsumo.vehicle.remove(vid)
        self.vut = self.pov = ""
        if self.follower is not None:
            self.follower.remove()
            self.follower = None

    # ------------------------------------------------------------------ per step

    def command_pov_speed(self, speed_mps: float) -> None:
        """The POV drives at exactly ``speed_mps`` during the next step (checks are off)."""
        _set_speed(self.pov, speed_mps)

    def longitudinal(self) -> tuple[float, float, float, float]:
        """``(pov_pos_m, pov_speed_mps, vut_pos_m, vut_speed_mps)``, front bumpers."""
        pov, vut = self.pov, self.vut
        try:
            return _get_lane_pos(pov), _get_speed(pov), _get_lane_pos(vut), _get_speed(vut)
        except SUMO_ERRORS as e:
            raise SimulationError(
                f"pair {self.prefix} vanished from SUMO ({e}): did a vehicle leave the road?"
            ) from e

    def vut_accel_mps2(self) -> float:
        """The VUT's acceleration during the last step [m/s²] (SUMO's model)."""
        return float(_get_accel(self.vut))

    def lanes(self) -> tuple[int, int]:
        """``(pov_lane, vut_lane)`` indices (the lane of the vehicle's front)."""
        return _get_lane_index(self.pov), _get_lane_index(self.vut)

    def positions_xy(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """World ``(x, y)`` of the POV's and the VUT's front bumper centre [m]."""
        return _get_position(self.pov), _get_position(self.vut)

    def change_pov_lane(self, lane: int, duration_s: float) -> None:
        """Start a forced change of the POV to ``lane`` (continuous lateral motion).

        ``duration_s`` is how long TraCI keeps the *request* active, not the motion's length:
        the lateral motion takes ``--lanechange.duration`` (``SimConfig.lanechange_duration_s``).
        """
        libsumo.vehicle.changeLane(self.pov, lane, duration_s)

    def collided(self, colliding: Sequence[str]) -> bool:
        """Whether either vehicle of the pair is in ``colliding`` (ids from the session).

        With a follower in the episode, only a collision of the VUT with the POV counts, read
        from SUMO's collision pairs; a rear-end (the follower into the VUT) is recorded on
        :attr:`follower` and does not end the episode (:mod:`sumo_ayss.sim.follower`).
        """
        if not colliding:
            return False
        fol = self.follower
        if fol is not None and (fol.id in colliding or fol.gone):
            return fol.check_collisions(self.session, self.vut, self.pov)
        return self.vut in colliding or self.pov in colliding

    # ------------------------------------------------------------------ highway-env laws

    def move_pov_xy(self, x_front_m: float, y_m: float, heading_rad: float) -> None:
        """Put the POV's front bumper centre at world ``(x, y)`` in the next step.

        For highway-env's POV (:mod:`sumo_ayss.laws.hwenv`), whose state is integrated in
        Python: ``moveToXY`` (keepRoute 1: stay on the road, free lateral position with
        SUMO's sublane model; without it SUMO snaps the POV to the nearest lane centre,
        exact in car-following). SUMO's body stays aligned with the lane; ``heading_rad``
        (from +x toward +y) only sets the drawn angle. SUMO then reports the distance moved
        over the step as the speed: :meth:`set_speed_state` puts highway-env's speed back.
        """
        angle_deg = 90.0 - math.degrees(heading_rad)
        try:
            _move_to_xy(self.pov, self.edge, -1, x_front_m, y_m, angle_deg, 1)
        except SUMO_ERRORS as e:
            raise SimulationError(
                f"moving POV {self.pov} to ({x_front_m}, {y_m}) failed: {e}"
            ) from e

    def set_speed_state(self, pov_speed_mps: float | None, vut_speed_mps: float | None) -> None:
        """Overwrite the speed SUMO holds for the POV and/or the VUT (``None``: leave it).

        With highway-env's explicit Euler a vehicle moves by its speed *before* a sub-step;
        the env commands the mean of those speeds for the SUMO step (so the position is
        exact) and then sets the speed at the step's end here (``setPreviousSpeed``), so
        that everything reading SUMO afterwards sees highway-env's state.
        """
        try:
            if pov_speed_mps is not None:
                _set_previous_speed(self.pov, pov_speed_mps)
            if vut_speed_mps is not None:
                _set_previous_speed(self.vut, vut_speed_mps)
        except SUMO_ERRORS as e:
            raise SimulationError(f"pair {self.prefix}: setting speeds failed: {e}") from e

    def lane_centre_y_m(self, lane: int) -> float:
        """World y of the centre line of ``lane`` of the pair's road [m] (straight roads)."""
        return self._world_lanes()[1][lane]

    def road_origin_x_m(self) -> float:
        """World x of the road's start [m]: world x = this + lane position (straight roads)."""
        return self._world_lanes()[0]

    def _world_lanes(self) -> tuple[float, list[float]]:
        """(world x of the road's start, world y of each lane's centre line), cached."""
        cached: tuple[float, list[float]] | None = getattr(self, "_world_lanes_cache", None)
        if cached is None:
            n = libsumo.edge.getLaneNumber(self.edge)
            shapes = [libsumo.lane.getShape(f"{self.edge}_{i}") for i in range(n)]
            cached = (float(shapes[0][0][0]), [float(sh[0][1]) for sh in shapes])
            self._world_lanes_cache = cached
        return cached

    def world_fronts(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """World ``(x, y)`` of the POV's and the VUT's front bumper centre [m], from lane
        coordinates (lane position, lane centre, lateral offset; straight roads along +x).

        Unlike :meth:`positions_xy`, right after :meth:`place` (before a step) this is
        already the placed state: SUMO updates ``getPosition`` only in the next step.
        """
        x0 = self.road_origin_x_m()
        out = []
        for vid in (self.pov, self.vut):
            try:
                lane = _get_lane_index(vid)
                x = x0 + _get_lane_pos(vid)
                y = self.lane_centre_y_m(lane) + _get_lateral_lane_pos(vid)
            except SUMO_ERRORS as e:
                raise SimulationError(f"pair {self.prefix}: reading {vid} failed: {e}") from e
            out.append((x, y))
        return out[0], out[1]

    def lane_width_m(self, lane: int) -> float:
        """Width of ``lane`` of the pair's road [m]."""
        return self._lane_geometry()[1][lane]

    # ------------------------------------------------------------------ lateral (cut-in)

    def lateral_speeds(self) -> tuple[float, float]:
        """``(pov, vut)`` lateral speeds during the last step [m/s], positive to the left.

        SUMO's ``getLateralSpeed``. With ``--lanechange.duration`` a lane change is a
        continuous lateral motion, and this is the lateral displacement of the last step
        divided by the step length: lane width / duration while a change is under way (e.g.
        -3.2 m/s for a 3.2 m lane in 1.0 s, to the right), 0 otherwise. On the built-in roads
        (along +x) it equals the change of world y per step over the step length.
        """
        return _get_lateral_speed(self.pov), _get_lateral_speed(self.vut)

    def pov_lateral_offset_m(self) -> float:
        """POV's offset from the centre line of the lane its front is on [m], positive left.

        Non-zero while a lane change is under way; the lane (and so the offset's reference)
        flips when the POV's centre crosses the lane boundary, half-way through the change.
        """
        return float(_get_lateral_lane_pos(self.pov))

    def allow_vut_overtake_right(self) -> None:
        """Let the VUT drive past a slower vehicle in the lane to its left.

        SUMO's lane-change model (LC2013) forbids overtaking on the right unless congested:
        it makes a vehicle hold back for a slower leader in the lane to its left, even with
        lane-change mode 0 (checked: a free IDM VUT at 20 m/s, 10 m behind a 20 m/s POV in
        the left lane, alternated +2.4 / -2.4 m/s² instead of accelerating; with the POV
        200 m ahead it still lost 0.1 m/s² in the second step).
        A VUT that reacts only through its car-following model must ignore vehicles in
        other lanes, so this sets the VUT's ``lcOvertakeRight`` to 1 (always allowed);
        SUMO's global ``--lanechange.overtake-right true`` has the same effect for all.
        Call after :meth:`place`, before the episode's first step.
        """
        try:
            libsumo.vehicle.setParameter(self.vut, "laneChangeModel.lcOvertakeRight", "1")
        except SUMO_ERRORS as e:
            raise SimulationError(f"setting lcOvertakeRight of {self.vut} failed: {e}") from e

    # ------------------------------------------------------------------ VUT driven by a controller

    def take_vut_control(self) -> None:
        """Switch SUMO's checks off for the VUT (speed mode 0), as for the POV.

        From now on the VUT drives exactly the speed given to :meth:`command_vut_speed`
        before each step: no safe-speed, acceleration, deceleration or speed-limit check.
        Its limits are the controller's (:mod:`sumo_ayss.vuts.controllers`). Call after
        :meth:`place`, before the episode's first step.
        """
        try:
            libsumo.vehicle.setSpeedMode(self.vut, SPEED_MODE_UNCHECKED)
        except SUMO_ERRORS as e:
            raise SimulationError(f"taking control of {self.vut} failed: {e}") from e

    def command_vut_speed(self, speed_mps: float) -> None:
        """The VUT drives at exactly ``speed_mps`` during the next step (after
        :meth:`take_vut_control`). SUMO's default (Euler) update then moves it by
        ``speed_mps · step_length`` in that step."""
        _set_speed(self.vut, speed_mps)

    def vut_sensing(self, range_m: float) -> VutSensing:
        """What the VUT's own sensors see now: its speed and lane, its leader, its objects.

        The leader is the POV when (a) its body reaches into the VUT's lane — its lateral
        extent, centre ± width / 2, overlaps the lane between the lane's edges; during a
        cut-in that is before SUMO's lane index of the POV flips — and (b) its front is
        ahead of the VUT's front, and (c) the gap is at most ``range_m``. The gap is
        bumper to bumper from lane positions and the POV's length (POV rear minus VUT
        front, as the env's headway h); it is <= 0 while a cut-in's rear is still beside
        the VUT. Computed from positions because ``vehicle.getLeader`` does not report a
        vehicle that only reaches into the lane (checked on SUMO 1.28: it returned no
        leader until the POV's lane index flipped) and its gap subtracts the follower's
        minGap. Lane positions of neighbouring lanes are compared directly, which holds on
        the straight built-in roads.

        The object list (:class:`SensedObject`) holds the POV in any lane while its gap
        lies within ``[-range_m, range_m]``: what a real vehicle's object list reports.

        Args:
            range_m: Sensor range [m]: a leader or object farther than this is not seen.

        Returns:
            The reading; without a leader ``gap_m`` is ``inf`` and ``leader_speed_mps``
            NaN.
        """
        vut, pov = self.vut, self.pov
        try:
            vut_pos, vut_speed = _get_lane_pos(vut), _get_speed(vut)
            vut_lane = _get_lane_index(vut)
            time_s = float(libsumo.simulation.getTime())
            pov_pos, pov_speed = _get_lane_pos(pov), _get_speed(pov)
            pov_lane = _get_lane_index(pov)
            centres, widths = self._lane_geometry()
            pov_centre = centres[pov_lane] + _get_lateral_lane_pos(pov)
            d = pov_centre - (centres[vut_lane] + _get_lateral_lane_pos(vut))
            pov_width = libsumo.vehicle.getWidth(pov)
            pov_length = libsumo.vehicle.getLength(pov)
            reach = 0.5 * (widths[vut_lane] + pov_width)
            gap = pov_pos - pov_length - vut_pos
            lateral = _get_lateral_speed(pov) - _get_lateral_speed(vut)
        except SUMO_ERRORS as e:
            raise SimulationError(
                f"pair {self.prefix}: reading the VUT's sensors failed: {e}"
            ) from e
        lane_width = widths[vut_lane]
        objects: tuple[SensedObject, ...] = ()
        if -range_m <= gap <= range_m:
            offset = pov_centre - centres[vut_lane]  # from the VUT's lane centre line
            objects = (
                SensedObject(gap, offset, pov_speed - vut_speed, lateral, pov_length, pov_width),
            )
        leader = (math.inf, math.nan)
        if abs(d) < reach and pov_pos > vut_pos and gap <= range_m:
            leader = (gap, pov_speed)
        if self.extra_povs:
            leader, objects = sense_extra_povs(
                self.extra_povs, self.vut, range_m, (centres, widths), leader, objects
            )
        return VutSensing(time_s, vut_speed, vut_lane, leader[0], leader[1], objects, lane_width)

    def _lane_geometry(self) -> tuple[list[float], list[float]]:
        """Lateral centre of each lane of the edge from lane 0's centre [m] (+ left), widths."""
        cached: tuple[list[float], list[float]] | None = getattr(self, "_lane_geom", None)
        if cached is None:
            n = libsumo.edge.getLaneNumber(self.edge)
            widths = [libsumo.lane.getWidth(f"{self.edge}_{i}") for i in range(n)]
            centres = [0.0]
            for i in range(1, n):
                centres.append(centres[-1] + 0.5 * (widths[i - 1] + widths[i]))
            cached = (centres, widths)
            self._lane_geom = cached
        return cached


# Getters of the lateral (cut-in) methods, bound like the hot-path ones above.
_get_lateral_speed = _libsumo.vehicle_getLateralSpeed
_get_lateral_lane_pos = _libsumo.vehicle_getLateralLanePosition
_move_to_xy = libsumo.vehicle.moveToXY
_set_previous_speed = libsumo.vehicle.setPreviousSpeed
