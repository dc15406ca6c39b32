"""highway-env's laws inside a :class:`~sumo_ayss.envs.pair_env.PairEnv` (paper-fidelity mode).

With ``env.actuator.mode: highway_env`` and/or a :class:`~sumo_ayss.hwenv_laws.HighwayEnvIDM`
VUT (``hwenv_pi1``/``hwenv_pi2``), the env integrates highway-env's laws itself at
``env.actuator.substeps`` Euler sub-steps per SUMO step and gives SUMO the exact end state
(:meth:`HighwayEnvLaws._command_hwenv`); see docs/paper_fidelity.md. Nothing here runs in
the default mode.
"""

from __future__ import annotations

from sumo_ayss.config import ActuatorConfig, EnvConfig
from sumo_ayss.controllers import ControlledVut
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.hwenv_kinematics import KinematicState, collision_check
from sumo_ayss.hwenv_laws import HighwayEnvIDM, HighwayEnvPov, LateralParams
from sumo_ayss.sim.actuator import next_speed, pov_acceleration
from sumo_ayss.sim.pair import VehiclePair


class HighwayEnvLaws:
    """The highway-env part of :class:`~sumo_ayss.envs.pair_env.PairEnv` (a mixin).

    It shares the env's per-step state, declared below; :meth:`_init_hwenv` sets its own.
    """

    # The env's state this mixin reads and writes (set by PairEnv.__init__ and its phases).
    _actuator: ActuatorConfig
    _pov_length_m: float  # [m]
    _dt_s: float  # SUMO step length [s]
    _vut_control: ControlledVut | None
    _target: float  # the POV's target speed of the current decision [m/s]
    _v_pov: float  # the POV's commanded speed [m/s]
    _accel: float  # the POV's acceleration in the last SUMO step [m/s²]

    def _init_hwenv(self, config: EnvConfig) -> None:
        """Build highway-env's POV / VUT laws for ``config`` (None each in the default mode)."""
        # highway-env's laws (sumo_ayss.hwenv_laws), integrated here at ``substeps`` Euler
        # sub-steps per SUMO step: the POV in actuator mode highway_env, and a VUT whose
        # controller is HighwayEnvIDM. None in the default mode (no per-step cost there).
        self._hw_pov: HighwayEnvPov | None = None
        if self._actuator.highway_env:
            act = self._actuator
            self._hw_pov = HighwayEnvPov(
                act.time_constant_s,
                LateralParams(
                    tau_lateral_s=act.tau_lateral_s,
                    tau_heading_s=act.tau_heading_s,
                    length_m=self._pov_length_m,
                ),
                act.max_speed_mps,
            )
        controller = None if self._vut_control is None else self._vut_control.controller
        self._hw_vut: HighwayEnvIDM | None = (
            controller if isinstance(controller, HighwayEnvIDM) else None
        )
        self._hw = self._hw_pov is not None or self._hw_vut is not None
        # Both vehicles on highway-env's laws: collisions are highway-env's too (rotated
        # bodies checked every sub-step, incl. its one-sub-step look-ahead), not SUMO's.
        self._hw_collisions = self._hw_pov is not None and self._hw_vut is not None
        self._hw_collided = False
        self._hw_impact = False  # highway-env's look-ahead hit: crashed at the next sub-step
        self._hw_bodies = (
            (config.vut_type.length_m, config.pov.length_m),
            (
                float(config.vut_type.params.get("width", 1.8)),
                float(config.pov.params.get("width", 1.8)),
            ),
        )
        self._hw_pending: tuple[float | None, float | None] | None = None
        self._hw_vut_lane_y = 0.0
        self._hw_vut_lane_w = 0.0

    def _start_hwenv(self, pair: VehiclePair, ic: InitialCondition) -> None:
        """Initialise highway-env's POV / VUT states from the placed vehicles."""
        (pov_x, pov_y), _ = pair.world_fronts()
        pov_lane, vut_lane = pair.lanes()
        self._hw_vut_lane_y = pair.lane_centre_y_m(vut_lane)
        self._hw_vut_lane_w = pair.lane_width_m(vut_lane)
        self._hw_pending = None
        self._hw_collided = self._hw_impact = False
        if self._hw_pov is not None:
            state = KinematicState(pov_x - 0.5 * self._pov_length_m, pov_y, 0.0, ic.pov_speed_mps)
            self._hw_pov.start(state, pair.lane_centre_y_m(pov_lane))
        if self._hw_vut is not None:
            self._hw_vut.start(ic.vut_speed_mps)

    def _command_hwenv(self, pair: VehiclePair) -> None:
        """One SUMO step of highway-env's laws: ``substeps`` Euler sub-steps in Python.

        The POV (mode highway_env) is integrated first (its law ignores the VUT), giving its
        state at every sub-instant; the VUT's IDM is then re-evaluated at each sub-instant
        against it, as highway-env's ``Road.act`` / ``Road.step`` do. SUMO receives the
        end state exactly: the POV by ``moveToXY`` (its speed in SUMO = its longitudinal
        velocity, the paper's observed v'); a highway-env VUT by the mean of its
        sub-step speeds (SUMO's Euler update moves it by ``speed · step``, = highway-env's
        sum of ``speed · dt`` over the sub-steps); both speeds are put back after the step
        (:meth:`_sync_hwenv_speeds`). With the clipped actuator the POV drives its commanded
        speed over the whole step (SUMO's Euler), which the VUT sees sub-step by sub-step.
        """
        if self._hw_pending is not None:
            self._sync_hwenv_speeds(pair)
        n = self._actuator.substeps
        dt = self._dt_s / n
        half_pov = 0.5 * self._pov_length_m
        pov_speed: float | None = None
        hw_pov = self._hw_pov
        if hw_pov is not None:
            hw_pov.target_speed_mps = self._target
            pov_states = hw_pov.advance(n, dt)
            end = pov_states[-1]
            pair.move_pov_xy(end.x_m + half_pov, end.y_m, end.heading_rad)
            # SUMO holds the POV's longitudinal speed (what the paper's POV observes as v',
            # "POV longitudinal speed"): speed · cos(heading), = speed outside lane changes.
            pov_speed = self._v_pov = end.vx_mps
            self._accel = hw_pov.last_accel_mps2
        else:
            actuator = self._actuator
            accel = self._accel = pov_acceleration(self._v_pov, self._target, actuator)
            v = self._v_pov = next_speed(self._v_pov, accel, self._dt_s, actuator)
            pair.command_pov_speed(v)
            pov_states = []
            if self._hw_vut is not None:
                (x, y), _ = pair.world_fronts()
                x0 = x - half_pov
                pov_states = [KinematicState(x0 + v * j * dt, y, 0.0, v) for j in range(n)]
        vut_speed: float | None = None
        if self._hw_vut is not None and self._vut_control is not None:
            (_, _), (vx, vy) = pair.world_fronts()
            _, _, _, v_vut = pair.longitudinal()
            own = KinematicState(vx - 0.5 * self._hw_vut.length_m, vy, 0.0, v_vut)
            states = self._hw_vut.advance(
                own, self._hw_vut_lane_y, self._hw_vut_lane_w, pov_states[:n], dt
            )
            mean_speed = (states[-1].x_m - own.x_m) / self._dt_s
            pair.command_vut_speed(mean_speed)
            vut_speed = states[-1].speed_mps
            self._vut_control.last_command_mps2 = (vut_speed - v_vut) / self._dt_s
            if self._hw_collisions:
                self._check_hwenv_collisions(states, pov_states[1:], dt)
        elif self._vut_control is not None:
            self._vut_control.before_step(pair)
        self._hw_pending = (pov_speed, vut_speed)

    def _check_hwenv_collisions(
        self, vut: list[KinematicState], pov: list[KinematicState], dt_s: float
    ) -> None:
        """highway-env's collision test after each sub-step (``Road.step``): overlap now,
        or a look-ahead hit at the previous sub-step (its ``impact``, crashed one later)."""
        lengths, widths = self._hw_bodies
        for a, b in zip(vut, pov, strict=True):
            if self._hw_impact:
                self._hw_collided = True
                return
            hit, will_hit = collision_check(a, b, dt_s, lengths, widths)
            if hit:
                self._hw_collided = True
                return
            self._hw_impact = will_hit

    def _sync_hwenv_speeds(self, pair: VehiclePair) -> None:
        """After a SUMO step: give SUMO highway-env's end-of-step speeds (see above)."""
        pending = self._hw_pending
        self._hw_pending = None
        if pending is not None:
            pair.set_speed_state(*pending)
