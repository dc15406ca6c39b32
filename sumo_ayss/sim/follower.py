"""The follower behind the VUT (issue 33): a SUMO-driven car in the VUT's lane.

Driven by SUMO's own car-following model with every check on (a human-like driver, its
type from ``env.follower``); it never changes lanes. :class:`Follower` is held by a
:class:`~sumo_ayss.sim.pair.VehiclePair` for the episodes that have one: it adds a fresh
follower with the pair's vehicles, places it behind the VUT, reads its state, and tells a
rear-end collision (the follower into the VUT) from the pair's own crash by SUMO's
collision pairs (``simulation.getCollisions``: collider and victim).

A follower that hit the VUT is removed from the simulation at once: with SUMO's collision
action ``warn`` it would otherwise drive on through the VUT and become the VUT's leader,
which would change the VUT-POV episode. A collision of the follower with the POV (a cut-in
between them) is not the VUT's hazard and is ignored.
"""

from __future__ import annotations

import contextlib
import math

import libsumo
from libsumo import _libsumo

from sumo_ayss.sim.session import SUMO_ERRORS, SumoSession
from sumo_ayss.util.errors import SimulationError

__all__ = ["FOLLOWER_INSERT_POS_M", "VUT_INSERT_POS_WITH_FOLLOWER_M", "Follower"]

#: Where a follower is inserted (front position [m]) before being moved into place, and
#: where the VUT is inserted then (further downstream, to make room). Upstream of the VUT:
#: a follower inserted ahead of it and moved back behind it did not see the VUT as its
#: leader (SUMO 1.28: ``getLeader`` None, it drove into the VUT).
FOLLOWER_INSERT_POS_M = 10.0
VUT_INSERT_POS_WITH_FOLLOWER_M = 35.0

_get_lane_pos = _libsumo.vehicle_getLanePosition
_get_speed = _libsumo.vehicle_getSpeed
_get_accel = _libsumo.vehicle_getAcceleration

#: SUMO lane-change mode 0: the follower keeps its lane.
_LC_MODE_NONE = 0


class Follower:
    """The follower of one pair, for the episodes that have one.

    Args:
        vtype: Its vType id (loaded by the session).
        prefix: The pair's vehicle-id prefix.
    """

    def __init__(self, vtype: str, prefix: str) -> None:
        self.vtype = vtype
        self.prefix = prefix
        self.id = ""
        self.rear_end = False  # the follower ran into the VUT in this episode
        self.gone = False  # removed after its rear-end collision

    def add(self, route: str, episode: int) -> None:
        """Add a fresh follower (inserted by the next step, upstream of the VUT)."""
        self.id = f"{self.prefix}.fol.{episode}"
        self.rear_end = self.gone = False
        try:
            libsumo.vehicle.add(
                self.id, route, self.vtype, "now", "0", str(FOLLOWER_INSERT_POS_M), "0"
            )
        except SUMO_ERRORS as e:
            raise SimulationError(f"adding the follower of pair {self.prefix} failed: {e}") from e

    def place(self, lane_id: str, pos_m: float, speed_mps: float) -> None:
        """Put the freshly inserted follower's front at ``pos_m`` on ``lane_id`` at
        ``speed_mps``. It decides every SUMO step: an action step longer than the step on any
        vehicle changes how SUMO moves the others (:mod:`sumo_ayss.config.follower`)."""
        vid = self.id
        try:
            libsumo.vehicle.setLaneChangeMode(vid, _LC_MODE_NONE)
            libsumo.vehicle.moveTo(vid, lane_id, pos_m)
            libsumo.vehicle.setPreviousSpeed(vid, speed_mps)
        except SUMO_ERRORS as e:
            raise SimulationError(
                f"placing the follower of pair {self.prefix} at {pos_m} m failed ({e})"
            ) from e

    def remove(self) -> None:
        """Remove the follower if it is still in the simulation."""
        if self.id and not self.gone:
            with contextlib.suppress(*SUMO_ERRORS):
                libsumo.vehicle.remove(self.id)
        self.id = ""

    def check_collisions(self, session: SumoSession, vut: str, pov: str) -> bool:
        """Read the last step's collision pairs: record a rear-end (follower and VUT), and
        say whether the VUT and the POV collided with each other."""
        pairs = session.collision_pairs()
        fol = self.id
        pair_crash = False
        for a, b in pairs:
            ab = {a, b}
            if ab == {vut, pov}:
                pair_crash = True
            elif ab == {fol, vut} and not self.gone:
                self.rear_end = True
                self.gone = True
                with contextlib.suppress(*SUMO_ERRORS):
                    libsumo.vehicle.remove(fol)
        return pair_crash

    def state(self) -> tuple[float, float, float]:
        """``(front lane position [m], speed [m/s], acceleration [m/s²])``; NaN once it is
        gone (after a rear-end)."""
        if self.gone or not self.id:
            return math.nan, math.nan, math.nan
        vid = self.id
        try:
            return _get_lane_pos(vid), _get_speed(vid), _get_accel(vid)
        except SUMO_ERRORS as e:
            raise SimulationError(f"the follower {vid} vanished from SUMO ({e})") from e
