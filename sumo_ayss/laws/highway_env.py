"""highway-env's laws driving SUMO vehicles (paper-fidelity mode, docs/paper_fidelity.md).

The POV in ``env.actuator.mode: highway_env`` (:class:`HighwayEnvPovLaw`) and a VUT whose
controller is :class:`~sumo_ayss.laws.hwenv.HighwayEnvIDM` (``hwenv_pi1``/``hwenv_pi2``,
:class:`HighwayEnvIdmVut`) are integrated here, in Python, at ``env.actuator.substeps``
explicit-Euler sub-steps per SUMO step, as highway-env's ``Road.act`` / ``Road.step`` do:
the POV first (its law ignores the VUT), giving its state at every sub-instant; the VUT's
IDM is then re-evaluated at each sub-instant against it. SUMO receives the end state
exactly: the POV by ``moveToXY`` (its speed in SUMO = its longitudinal velocity, the
paper's observed v'); the VUT by the mean of its sub-step speeds (SUMO's Euler update moves
it by ``speed · step``, = highway-env's sum of ``speed · dt`` over the sub-steps). Both
speeds are put back after the step (:meth:`~sumo_ayss.laws.base.VehicleLaw.sync`). With
the clipped POV (:class:`~sumo_ayss.laws.clipped.ClippedPov`) the POV drives its commanded
speed over the whole step, which the VUT sees sub-step by sub-step.

Coordinates as in :mod:`sumo_ayss.laws.hwenv`: centres [m], y positive to the left,
headings [rad] from +x toward +y; speeds m/s, accelerations m/s².
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from sumo_ayss.config import ActuatorConfig, EnvConfig
from sumo_ayss.laws.base import PovLaw, VutLaw
from sumo_ayss.laws.hwenv import HighwayEnvPov, LateralParams
from sumo_ayss.sim.pair import VehiclePair
from sumo_ayss.vuts.hwenv_kinematics import KinematicState, collision_check

__all__ = ["HighwayEnvIdmVut", "HighwayEnvPovLaw"]


class HighwayEnvPovLaw(PovLaw):
    """highway-env's ControlledVehicle as the POV: speed law and lane-centring steering.

    Args:
        actuator: ``env.actuator`` (mode ``highway_env``): time constant, lateral
            constants, soft top speed, sub-steps, ``lane_change_done_m``.
        step_length_s: SUMO step [s].
        length_m: The POV's length [m].
    """

    def __init__(self, actuator: ActuatorConfig, step_length_s: float, length_m: float) -> None:
        self._law = HighwayEnvPov(
            actuator.time_constant_s,
            LateralParams(
                tau_lateral_s=actuator.tau_lateral_s,
                tau_heading_s=actuator.tau_heading_s,
                length_m=length_m,
            ),
            actuator.max_speed_mps,
        )
        self._substeps = actuator.substeps
        self._dt_s = step_length_s
        self._length_m = length_m
        self._lane_change_done_m = actuator.lane_change_done_m
        self._states: list[KinematicState] = []
        self._pending_speed_mps: float | None = None  # SUMO's speed after the last step

    @classmethod
    def from_config(cls, config: EnvConfig) -> HighwayEnvPovLaw:
        return cls(config.actuator, config.sim.step_length_s, config.pov.length_m)

    def start(self, pair: VehiclePair, speed_mps: float) -> None:
        """The law's state from the placed POV, tracking ``speed_mps`` in its own lane."""
        (pov_x, pov_y), _ = pair.world_fronts()
        pov_lane, _ = pair.lanes()
        self._pending_speed_mps = None
        state = KinematicState(pov_x - 0.5 * self._length_m, pov_y, 0.0, speed_mps)
        self._law.start(state, pair.lane_centre_y_m(pov_lane))

    def command(self, pair: VehiclePair, target_speed_mps: float) -> None:
        """``substeps`` Euler sub-steps toward the target; the end state goes to SUMO."""
        self.sync(pair)
        n = self._substeps
        law = self._law
        law.target_speed_mps = target_speed_mps
        states = self._states = law.advance(n, self._dt_s / n)
        end = states[-1]
        pair.move_pov_xy(end.x_m + 0.5 * self._length_m, end.y_m, end.heading_rad)
        # SUMO holds the POV's longitudinal speed (what the paper's POV observes as v',
        # "POV longitudinal speed"): speed · cos(heading), = speed outside lane changes.
        self._pending_speed_mps = end.vx_mps

    def sync(self, pair: VehiclePair) -> None:
        """After a SUMO step: SUMO reports the distance moved; put the law's speed back."""
        speed = self._pending_speed_mps
        if speed is not None:
            self._pending_speed_mps = None
            pair.set_speed_state(speed, None)

    def accel_mps2(self, pair: VehiclePair) -> float:
        """The mean commanded acceleration over the last step's sub-steps [m/s²]."""
        del pair
        return self._law.last_accel_mps2

    def substep_states(self, pair: VehiclePair) -> list[KinematicState]:
        """The states of the last :meth:`command`'s integration."""
        del pair
        return self._states

    def change_lane(self, pair: VehiclePair, lane: int, request_s: float) -> None:
        """A new target lane for the steering loop (integrated here, put into SUMO)."""
        del request_s
        self._law.target_lane_y_m = pair.lane_centre_y_m(lane)

    def lane_motion(
        self, speed_mps: float, lateral_offset_m: float, lateral_speed_mps: float
    ) -> tuple[float, float, bool]:
        """The law's own velocity ``speed·(cos ψ, sin ψ)`` (SUMO, moved by ``moveToXY``,
        reports no lateral speed); changing until the centre is within
        ``lane_change_done_m`` of the target lane's centre line."""
        del speed_mps, lateral_offset_m, lateral_speed_mps
        law = self._law
        st = law.state
        changing = abs(st.y_m - law.target_lane_y_m) > self._lane_change_done_m
        return st.vx_mps, st.vy_mps, changing


class HighwayEnvIdmVut(VutLaw):
    """highway-env's IDMVehicle as the VUT, re-evaluated at every sub-step.

    Args:
        idm: The :class:`~sumo_ayss.laws.hwenv.HighwayEnvIDM` built from the VUT's
            controller entry (its ``params``).
        step_length_s: SUMO step [s].
        substeps: Euler sub-steps per SUMO step.
        lengths_m: ``(VUT, POV)`` body lengths [m] for the collision test.
        widths_m: ``(VUT, POV)`` body widths [m].
        judges_collisions: Both vehicles run highway-env's laws: collisions are
            highway-env's too (rotated bodies checked every sub-step, incl. its
            one-sub-step look-ahead), not SUMO's.
    """

    def __init__(
        self,
        idm: Any,
        step_length_s: float,
        substeps: int,
        lengths_m: tuple[float, float],
        widths_m: tuple[float, float],
        judges_collisions: bool,
    ) -> None:
        self._idm = idm
        self._dt_s = step_length_s
        self._substeps = substeps
        self._bodies = (lengths_m, widths_m)
        self._judges = judges_collisions
        self._lane_y_m = 0.0
        self._lane_width_m = 0.0
        self._accel_mps2 = 0.0
        self._pending_speed_mps: float | None = None
        self._collided = False
        self._impact = False  # highway-env's look-ahead hit: crashed at the next sub-step

    @classmethod
    def from_config(cls, config: EnvConfig) -> HighwayEnvIdmVut:
        """Build the IDM from ``config.vut``'s controller entry (``hwenv_pi1``/``hwenv_pi2``)."""
        vt = config.vut_type
        assert vt.controller is not None
        idm = vt.controller.build(f"env.vuts.{config.vut}.controller")
        return cls(
            idm,
            config.sim.step_length_s,
            config.actuator.substeps,
            (vt.length_m, config.pov.length_m),
            (float(vt.params.get("width", 1.8)), float(config.pov.params.get("width", 1.8))),
            judges_collisions=config.actuator.highway_env,
        )

    def start(self, pair: VehiclePair, speed_mps: float) -> None:
        """Speed mode 0 for the VUT; v0 from ``speed_mps`` [m/s]; its lane's geometry."""
        pair.take_vut_control()
        self._idm.reset()
        _, vut_lane = pair.lanes()
        self._lane_y_m = pair.lane_centre_y_m(vut_lane)
        self._lane_width_m = pair.lane_width_m(vut_lane)
        self._pending_speed_mps = None
        self._collided = self._impact = False
        self._accel_mps2 = 0.0
        self._idm.start(speed_mps)

    def command(self, pair: VehiclePair, pov: PovLaw) -> None:
        """``substeps`` Euler sub-steps against the POV's sub-step states; SUMO drives the
        mean speed over the step."""
        self.sync(pair)
        n = self._substeps
        dt = self._dt_s / n
        idm = self._idm
        pov_states = pov.substep_states(pair)
        (_, _), (vx, vy) = pair.world_fronts()
        _, _, _, v_vut = pair.longitudinal()
        own = KinematicState(vx - 0.5 * idm.length_m, vy, 0.0, v_vut)
        states = idm.advance(own, self._lane_y_m, self._lane_width_m, pov_states[:n], dt)
        mean_speed = (states[-1].x_m - own.x_m) / self._dt_s
        pair.command_vut_speed(mean_speed)
        vut_speed = states[-1].speed_mps
        self._accel_mps2 = (vut_speed - v_vut) / self._dt_s
        if self._judges:
            self._check_collisions(states, pov_states[1:], dt)
        self._pending_speed_mps = vut_speed

    def sync(self, pair: VehiclePair) -> None:
        """After a SUMO step: put the law's end-of-step speed back into SUMO."""
        speed = self._pending_speed_mps
        if speed is not None:
            self._pending_speed_mps = None
            pair.set_speed_state(None, speed)

    def accel_mps2(self, pair: VehiclePair) -> float:
        """The VUT's speed change over the last step divided by the step [m/s²]."""
        del pair
        return self._accel_mps2

    def collided(self, sumo_collided: bool) -> bool:
        """highway-env's verdict when both vehicles run its laws, else SUMO's."""
        return self._collided if self._judges else sumo_collided

    def _check_collisions(
        self, vut: Sequence[KinematicState], pov: Sequence[KinematicState], dt_s: float
    ) -> None:
        """highway-env's collision test after each sub-step (``Road.step``): overlap now,
        or a look-ahead hit at the previous sub-step (its ``impact``, crashed one later)."""
        lengths, widths = self._bodies
        for a, b in zip(vut, pov, strict=True):
            if self._impact:
                self._collided = True
                return
            hit, will_hit = collision_check(a, b, dt_s, lengths, widths)
            if hit:
                self._collided = True
                return
            self._impact = will_hit
