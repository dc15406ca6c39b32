"""The vehicle-law interfaces the env calls: one law per vehicle of the pair.

A law decides how a vehicle moves over each SUMO step and puts that into SUMO through
:class:`~sumo_ayss.sim.pair.VehiclePair` (laws never touch libsumo themselves). The env
(:class:`~sumo_ayss.envs.pair_env.PairEnv`) holds one :class:`PovLaw` and one
:class:`VutLaw`, built once from the configuration (:func:`~sumo_ayss.laws.build_laws`),
and calls, in this order::

    vut.start(pair, v_vut); pov.start(pair, v_pov)     # an episode's placed vehicles
    per SUMO step:
        pov.command(pair, target_speed_mps)            # before the step
        vut.command(pair, pov)                          # before the step, after the POV
    after the decision's steps:
        pov.sync(pair); vut.sync(pair)                  # before the env reads SUMO back
        vut.collided(sumo_collided), *.accel_mps2(pair)

Units: positions and lengths m, speeds m/s, accelerations m/s² (> 0 speeds up, < 0
brakes), times s. Lateral quantities are positive to the left (SUMO's world y).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence
from typing import NamedTuple

from sumo_ayss.sim.pair import VehiclePair
from sumo_ayss.vuts.hwenv_kinematics import KinematicState

__all__ = ["PovLaw", "VehicleLaw", "VehicleLaws", "VutLaw"]


class VehicleLaw(ABC):
    """What every law does: start an episode, settle SUMO's state, report its acceleration."""

    @abstractmethod
    def start(self, pair: VehiclePair, speed_mps: float) -> None:
        """Take over the freshly placed vehicle, whose initial speed is ``speed_mps`` [m/s]."""

    def sync(self, pair: VehiclePair) -> None:
        """Give SUMO the vehicle's end-of-step state before anything reads it.

        A law integrated in Python (highway-env's) commands a mean speed for a SUMO step
        and puts the step's end speed back here; the others have nothing to do. Each law
        calls it at the start of its own ``command``; the env calls it after a decision.
        """
        del pair

    @abstractmethod
    def accel_mps2(self, pair: VehiclePair) -> float:
        """The vehicle's acceleration during the last SUMO step [m/s²]."""

    def close(self) -> None:
        """Release what the law holds outside SUMO (an FMU, a process); safe to call twice."""
        return None  # most laws hold nothing outside SUMO


class PovLaw(VehicleLaw):
    """How the POV follows the policy: a target speed [m/s] (and a target lane) -> SUMO."""

    @abstractmethod
    def command(self, pair: VehiclePair, target_speed_mps: float) -> None:
        """Command the POV for the coming SUMO step toward ``target_speed_mps`` [m/s]."""

    @abstractmethod
    def substep_states(self, pair: VehiclePair) -> Sequence[KinematicState]:
        """The POV's centre state at the start of each of the coming SUMO step's
        ``env.actuator.substeps`` sub-steps, then at its end (``substeps + 1`` states).

        For a VUT law that integrates at sub-steps; call after :meth:`command`.
        """

    @abstractmethod
    def change_lane(self, pair: VehiclePair, lane: int, request_s: float) -> None:
        """Start the POV's change into ``lane`` (SUMO lane index, 0 = rightmost).

        ``request_s``: how long SUMO keeps a lane-change request active [s] (a law that
        steers itself ignores it).
        """

    @abstractmethod
    def lane_motion(
        self, speed_mps: float, lateral_offset_m: float, lateral_speed_mps: float
    ) -> tuple[float, float, bool]:
        """The POV's velocity and whether it is changing lanes, from SUMO's reading.

        Args:
            speed_mps: SUMO's longitudinal speed of the POV [m/s].
            lateral_offset_m: SUMO's offset from its lane's centre line [m], + left.
            lateral_speed_mps: SUMO's lateral speed in the last step [m/s], + left.

        Returns:
            ``(velocity along the road [m/s], lateral velocity [m/s] + left, changing)``.
        """


class VutLaw(VehicleLaw):
    """How the VUT drives: SUMO's own model, a user controller, or highway-env's IDM."""

    @abstractmethod
    def command(self, pair: VehiclePair, pov: PovLaw) -> None:
        """Command the VUT for the coming SUMO step (after the POV's :meth:`PovLaw.command`)."""

    def collided(self, sumo_collided: bool) -> bool:
        """Whether the pair collided during the decision: SUMO's verdict ``sumo_collided``
        unless the law judges collisions itself."""
        return sumo_collided


class VehicleLaws(NamedTuple):
    """The two laws of one env: the POV's and the VUT's."""

    pov: PovLaw
    vut: VutLaw
