"""highway-env's vehicle laws (v1.8.2), as pure functions: the paper's VUT and POV.

The paper ran on highway-env. This module restates, constant for constant, the laws of
highway-env 1.8.2 (``highway_env/vehicle/behavior.py``, ``controller.py``,
``kinematics.py``; unchanged up to 1.12) so that SUMO vehicles can be driven by them
(:mod:`sumo_ayss.laws.highway_env`, ``env.actuator.mode: highway_env`` and the VUT catalog's
``hwenv_pi1``/``hwenv_pi2``). No SUMO here: the env and the cross-check test against
highway-env itself (``tests/test_hwenv_crosscheck.py``) both call this code.

Coordinates: a straight road along +x; ``y`` is the lateral world coordinate, positive to
the left (SUMO's); ``heading`` [rad] is measured from +x toward +y. The laws are mirror
symmetric, so highway-env's y-down frame maps to this one by ``y -> -y``. States are of the
vehicle's *centre* (highway-env's position), not its front bumper (SUMO's).

**VUT: highway-env's IDMVehicle** (:func:`idm_acceleration`, :class:`HighwayEnvIDM`):

* ``a = a_max·(1 − (max(v, 0)/v0)^δ) − a_max·(d*/d)²``, then clipped to ``±acc_max``;
* ``d`` = **centre-to-centre** distance along the lane (``lane_distance_to``), so for two
  5 m cars ``d = h + 5 m`` with h the bumper-to-bumper gap;
* ``d* = DISTANCE_WANTED + v·T + v·Δv/(2·sqrt(a_max·b))`` **without a clamp at zero**
  (``Δv`` = own speed minus the leader's velocity projected on the own heading);
* ``v0`` = the target speed: by default the speed at creation, clipped to ``[0, lane
  speed limit]`` (``ControlledVehicle.__init__``: ``target_speed or speed``);
* the leader is the nearest vehicle whose centre is level with or ahead of the own centre
  and whose centre lies within ``lane_width/2 + 1 m`` of the own lane's centre line
  (``Road.neighbour_vehicles`` with ``on_lane(margin=1)``);
* ``utils.not_zero`` guards (|x| <= 0.01 -> ±0.01) on ``v0`` and ``d`` as in highway-env.

**POV: highway-env's ControlledVehicle** (:func:`speed_control`, :func:`steering_control`):
``a = (v_target − v)/TAU_ACC`` (0.6 s), **unclipped**; lateral: a lane-centring cascade
(lateral position -> lateral speed -> heading, ``TAU_LATERAL`` 0.6 s, ``TAU_HEADING`` 0.2 s,
pursuit ``TAU_PURSUIT`` 0.1 s) giving a steering angle clipped to ±π/3.

**Kinematics** (:func:`bicycle_step`): highway-env's kinematic bicycle, explicit Euler:
position moves with the speed *before* the step, ``x += v·cos(ψ+β)·dt``, ``y += v·sin(ψ+β)·dt``,
``ψ += v·sin(β)/(L/2)·dt``, then ``v += a·dt`` (``β = atan(tan(δ_f)/2)``); above
``MAX_SPEED`` (40 m/s) the acceleration is capped at ``1/s·(MAX_SPEED − v)``
(``Vehicle.clip_actions``). Integration step: ``1/simulation_frequency`` (1/15 s), every
vehicle's controller re-evaluated at every step (``Road.act``, then ``Road.step``).

**One deliberate difference.** highway-env lets speeds go negative (down to −40 m/s: an
IDM car at standstill closer than ``DISTANCE_WANTED`` backs away). A SUMO vehicle cannot
drive backwards, so :func:`bicycle_step` floors the speed at ``min_speed_mps`` (0 by
default, set it to −40 for highway-env's bound where no SUMO vehicle is involved).

The state, the bicycle and the collision test live in :mod:`sumo_ayss.vuts.hwenv_kinematics`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from sumo_ayss.vuts.hwenv_kinematics import KinematicState, bicycle_step, not_zero

__all__ = [
    "HIGHWAY_ENV_IDM_TARGET",
    "HIGHWAY_ENV_VERSION",
    "HighwayEnvIDM",
    "HighwayEnvPov",
    "LateralParams",
    "idm_acceleration",
    "speed_control",
    "steering_control",
]

#: The highway-env release these laws are copied from (and cross-checked against).
HIGHWAY_ENV_VERSION = "1.8.2"

#: The controller ``target`` of :class:`HighwayEnvIDM` (the catalog's ``hwenv_pi1`` /
#: ``hwenv_pi2``): its registered name
#: (:data:`~sumo_ayss.vuts.controller_spec.CONTROLLERS`); run folders written before store
#: the module path it had at the package root, ``sumo_ayss.hwenv_laws:HighwayEnvIDM``, which
#: :data:`~sumo_ayss.vuts.controller_spec.TARGET_ALIASES` reads as this name.
HIGHWAY_ENV_IDM_TARGET = "highway_env_idm"


# ------------------------------------------------------------------ POV (ControlledVehicle)


def speed_control(speed_mps: float, target_speed_mps: float, tau_acc_s: float = 0.6) -> float:
    """``ControlledVehicle.speed_control``: ``(v_target − v)/tau_acc_s`` [m/s²], unclipped."""
    return (target_speed_mps - speed_mps) / tau_acc_s


@dataclass(frozen=True)
class LateralParams:
    """highway-env ControlledVehicle's lateral controller constants.

    Attributes:
        tau_lateral_s: ``TAU_LATERAL`` [s]: lateral speed command = −offset / tau.
        tau_heading_s: ``TAU_HEADING`` [s]: heading rate command = heading error / tau.
        tau_pursuit_s: ``TAU_PURSUIT`` [s] (look-ahead along the lane; irrelevant on a
            straight road, kept for completeness).
        max_heading_cmd_rad: Bound of the heading reference relative to the lane [rad] (π/4).
        max_steering_rad: ``MAX_STEERING_ANGLE`` [rad] (π/3).
        length_m: Vehicle length [m] (``Vehicle.LENGTH``).
    """

    tau_lateral_s: float = 0.6
    tau_heading_s: float = 0.2
    tau_pursuit_s: float = 0.1
    max_heading_cmd_rad: float = math.pi / 4
    max_steering_rad: float = math.pi / 3
    length_m: float = 5.0


def steering_control(s: KinematicState, target_lane_y_m: float, p: LateralParams) -> float:
    """``ControlledVehicle.steering_control`` toward a straight lane along +x [rad].

    Lateral offset -> lateral speed command -> heading reference (±π/4) -> heading rate ->
    steering angle (±π/3), exactly highway-env's cascade on a straight lane (lane heading 0).
    """
    lateral = s.y_m - target_lane_y_m
    lateral_speed_command = -lateral / p.tau_lateral_s
    speed = not_zero(s.speed_mps)
    heading_command = math.asin(min(max(lateral_speed_command / speed, -1.0), 1.0))
    heading_ref = min(max(heading_command, -p.max_heading_cmd_rad), p.max_heading_cmd_rad)
    error = ((heading_ref - s.heading_rad + math.pi) % (2 * math.pi)) - math.pi
    heading_rate_command = error / p.tau_heading_s
    slip = math.asin(min(max(p.length_m / 2 / speed * heading_rate_command, -1.0), 1.0))
    steering = math.atan(2 * math.tan(slip))
    return min(max(steering, -p.max_steering_rad), p.max_steering_rad)


# ------------------------------------------------------------------ VUT (IDMVehicle)


def idm_acceleration(
    speed_mps: float,
    target_speed_mps: float,
    distance_m: float | None,
    delta_v_mps: float,
    *,
    distance_wanted_m: float = 10.0,
    time_wanted_s: float = 1.5,
    comfort_acc_max_mps2: float = 3.0,
    comfort_acc_min_mps2: float = -5.0,
    delta: float = 4.0,
    acc_max_mps2: float = 6.0,
) -> float:
    """highway-env's ``IDMVehicle.acceleration`` followed by ``act``'s ±``acc_max`` clip.

    Args:
        speed_mps: Own speed v [m/s].
        target_speed_mps: v0 [m/s] (already clipped to the lane limit by the caller).
        distance_m: Centre-to-centre distance d to the leader along the lane [m], or
            ``None`` without a leader.
        delta_v_mps: Own speed minus the leader's velocity projected on the own heading
            [m/s] (> 0 closing in).
        distance_wanted_m: ``DISTANCE_WANTED`` [m], centre to centre (default 5 m + one
            5 m length = 10 m: the paper's s0 = 10 m).
        time_wanted_s: ``TIME_WANTED`` T [s].
        comfort_acc_max_mps2: ``COMFORT_ACC_MAX`` a [m/s²].
        comfort_acc_min_mps2: ``COMFORT_ACC_MIN`` −b [m/s²] (negative).
        delta: ``DELTA`` exponent δ.
        acc_max_mps2: ``ACC_MAX`` [m/s²]: the result is clipped to ±this.

    Returns:
        The acceleration command [m/s²].
    """
    a = comfort_acc_max_mps2 * (
        1 - math.pow(max(speed_mps, 0.0) / abs(not_zero(target_speed_mps)), delta)
    )
    if distance_m is not None:
        ab = -comfort_acc_max_mps2 * comfort_acc_min_mps2
        d_star = (
            distance_wanted_m
            + speed_mps * time_wanted_s
            + speed_mps * delta_v_mps / (2 * math.sqrt(ab))
        )
        a -= comfort_acc_max_mps2 * (d_star / not_zero(distance_m)) ** 2
    return min(max(a, -acc_max_mps2), acc_max_mps2)


class HighwayEnvIDM:
    """highway-env's IDMVehicle as a VUT controller (every constant a parameter).

    Used two ways:

    * by the env's law :class:`~sumo_ayss.laws.highway_env.HighwayEnvIdmVut` (chosen for
      the target :data:`HIGHWAY_ENV_IDM_TARGET`), which drives the VUT with
      :meth:`advance`: ``substeps`` explicit-Euler steps of the exact law per SUMO step,
      each re-evaluated against the POV's state at that sub-instant (highway-env's 15 Hz
      inside a 5 Hz decision);
    * as a plain :class:`~sumo_ayss.vuts.controllers.Controller` (:meth:`acceleration`, one
      evaluation per SUMO step from the sensed bumper-to-bumper gap), e.g. by code that
      only knows the controller protocol.

    Args:
        distance_wanted_m: ``DISTANCE_WANTED`` [m], centre to centre (pi1: 10, pi2: 20).
        time_wanted_s: ``TIME_WANTED`` [s].
        comfort_acc_max_mps2: ``COMFORT_ACC_MAX`` [m/s²].
        comfort_acc_min_mps2: ``COMFORT_ACC_MIN`` [m/s²], negative.
        delta: ``DELTA``.
        acc_max_mps2: ``ACC_MAX`` [m/s²] (the ± clip).
        target_speed_mps: v0 [m/s]; ``None`` (default): the speed at the start of each
            episode (highway-env: the speed at creation).
        lane_speed_limit_mps: The lane's ``speed_limit`` [m/s] that v0 is clipped to
            (highway-env's highway roads: 30 m/s); ``None``: no clip.
        length_m: Own length [m] (centre-to-centre distances).
        leader_length_m: Assumed leader length [m], only for :meth:`acceleration`'s
            bumper-to-bumper -> centre-to-centre conversion.
        lane_margin_m: ``on_lane`` margin [m]: a vehicle is in the lane while its centre is
            within ``lane_width/2 + margin`` of the lane's centre line (highway-env: 1 m).
        max_speed_mps: ``Vehicle.MAX_SPEED`` [m/s] (soft cap, see :func:`bicycle_step`).
        min_speed_mps: Speed floor [m/s] (0: SUMO cannot reverse).
    """

    def __init__(
        self,
        distance_wanted_m: float = 10.0,
        time_wanted_s: float = 1.5,
        comfort_acc_max_mps2: float = 3.0,
        comfort_acc_min_mps2: float = -5.0,
        delta: float = 4.0,
        acc_max_mps2: float = 6.0,
        target_speed_mps: float | None = None,
        lane_speed_limit_mps: float | None = 30.0,
        length_m: float = 5.0,
        leader_length_m: float = 5.0,
        lane_margin_m: float = 1.0,
        max_speed_mps: float = 40.0,
        min_speed_mps: float = 0.0,
    ) -> None:
        checks = {
            "time_wanted_s": time_wanted_s >= 0,
            "comfort_acc_max_mps2": comfort_acc_max_mps2 > 0,
            "comfort_acc_min_mps2": comfort_acc_min_mps2 < 0,
            "delta": delta > 0,
            "acc_max_mps2": acc_max_mps2 > 0,
            "length_m": length_m > 0,
            "leader_length_m": leader_length_m > 0,
            "lane_margin_m": lane_margin_m >= 0,
            "max_speed_mps": max_speed_mps > 0,
            "min_speed_mps": min_speed_mps <= 0,
        }
        for name, ok in checks.items():
            if not ok:
                raise ValueError(f"{name} out of range, got {locals()[name]!r}")
        if target_speed_mps is not None and target_speed_mps < 0:
            raise ValueError(f"target_speed_mps must be >= 0 or None, got {target_speed_mps!r}")
        self.distance_wanted_m = float(distance_wanted_m)
        self.time_wanted_s = float(time_wanted_s)
        self.comfort_acc_max_mps2 = float(comfort_acc_max_mps2)
        self.comfort_acc_min_mps2 = float(comfort_acc_min_mps2)
        self.delta = float(delta)
        self.acc_max_mps2 = float(acc_max_mps2)
        self.target_speed_mps = target_speed_mps
        self.lane_speed_limit_mps = lane_speed_limit_mps
        self.length_m = float(length_m)
        self.leader_length_m = float(leader_length_m)
        self.lane_margin_m = float(lane_margin_m)
        self.max_speed_mps = float(max_speed_mps)
        self.min_speed_mps = float(min_speed_mps)
        self.v0_mps: float | None = None  # the episode's target speed, set by start()

    def reset(self) -> None:
        """Forget the episode's target speed (set again by :meth:`start` / first call)."""
        self.v0_mps = None

    def start(self, speed_mps: float) -> None:
        """Begin an episode at ``speed_mps``: v0 = target or that speed, clipped to the limit."""
        v0 = speed_mps if self.target_speed_mps is None else self.target_speed_mps
        # highway-env: ``target_speed or speed`` (a 0 target falls back to the speed).
        if not v0 and self.target_speed_mps is not None:
            v0 = speed_mps
        if self.lane_speed_limit_mps is not None:
            v0 = min(max(v0, 0.0), self.lane_speed_limit_mps)
        self.v0_mps = float(v0)

    def accel(self, speed_mps: float, distance_m: float | None, delta_v_mps: float) -> float:
        """The law at one instant [m/s²] (see :func:`idm_acceleration`)."""
        if self.v0_mps is None:
            self.start(speed_mps)
        assert self.v0_mps is not None
        return idm_acceleration(
            speed_mps,
            self.v0_mps,
            distance_m,
            delta_v_mps,
            distance_wanted_m=self.distance_wanted_m,
            time_wanted_s=self.time_wanted_s,
            comfort_acc_max_mps2=self.comfort_acc_max_mps2,
            comfort_acc_min_mps2=self.comfort_acc_min_mps2,
            delta=self.delta,
            acc_max_mps2=self.acc_max_mps2,
        )

    def leader_terms(
        self,
        own: KinematicState,
        lane_y_m: float,
        lane_width_m: float,
        other: KinematicState,
    ) -> tuple[float | None, float]:
        """``(d, Δv)`` toward ``other`` if it is the leader in the own lane, else ``(None, 0)``.

        ``d`` = centre-to-centre distance along the lane [m]; ``Δv`` = own velocity minus
        the other's, projected on the own heading [m/s] (``desired_gap(projected=True)``).
        """
        if abs(other.y_m - lane_y_m) > lane_width_m / 2 + self.lane_margin_m:
            return None, 0.0
        if other.x_m < own.x_m:
            return None, 0.0
        ch, sh = math.cos(own.heading_rad), math.sin(own.heading_rad)
        dv = (own.vx_mps - other.vx_mps) * ch + (own.vy_mps - other.vy_mps) * sh
        return other.x_m - own.x_m, dv

    def advance(
        self,
        own: KinematicState,
        lane_y_m: float,
        lane_width_m: float,
        others: Sequence[KinematicState],
        dt_s: float,
    ) -> list[KinematicState]:
        """Integrate ``len(others)`` Euler steps of ``dt_s``; the law re-evaluated each step.

        Args:
            own: The VUT's state now (centre; heading 0 in its lane).
            lane_y_m: Lateral position of the VUT's lane centre [m].
            lane_width_m: That lane's width [m].
            others: The POV's state at the start of each sub-step.
            dt_s: Sub-step [s].

        Returns:
            The VUT's states after each sub-step (``len(others)`` entries).
        """
        out = []
        s = own
        for other in others:
            d, dv = self.leader_terms(s, lane_y_m, lane_width_m, other)
            a = self.accel(s.speed_mps, d, dv)
            # The VUT keeps its lane: highway-env's steering toward its own lane centre is 0
            # there, so the bicycle reduces to straight motion.
            s = bicycle_step(s, a, 0.0, dt_s, self.length_m, self.max_speed_mps, self.min_speed_mps)
            out.append(s)
        return out

    # The Controller protocol (sumo_ayss.vuts.controllers), one evaluation per call.
    def acceleration(self, state: object) -> float:
        """:class:`~sumo_ayss.vuts.controllers.Controller` form: one evaluation from the sensed
        bumper-to-bumper gap (centre distance = gap + half of both lengths) [m/s²]."""
        speed = float(state.speed_mps)  # type: ignore[attr-defined]
        gap = float(state.gap_m)  # type: ignore[attr-defined]
        if math.isfinite(gap):
            d = gap + 0.5 * (self.length_m + self.leader_length_m)
            return self.accel(speed, d, -float(state.rel_speed_mps))  # type: ignore[attr-defined]
        return self.accel(speed, None, 0.0)


class HighwayEnvPov:
    """highway-env's ControlledVehicle: target speed and target lane -> trajectory.

    Args:
        tau_acc_s: ``TAU_ACC`` [s] of the speed law ``a = (v_target − v)/tau_acc_s``.
        lateral: Lateral controller constants.
        max_speed_mps: ``Vehicle.MAX_SPEED`` [m/s] (soft cap).
        min_speed_mps: Speed floor [m/s] (0 for SUMO; the law never brakes below 0 toward
            a target >= 0 when ``dt < tau_acc_s``).

    Attributes:
        state: The current state (centre).
        target_speed_mps: The speed the controller tracks [m/s].
        target_lane_y_m: Lateral position of the centre line it steers to [m].
    """

    def __init__(
        self,
        tau_acc_s: float = 0.6,
        lateral: LateralParams | None = None,
        max_speed_mps: float = 40.0,
        min_speed_mps: float = 0.0,
    ) -> None:
        self.tau_acc_s = float(tau_acc_s)
        self.lateral = lateral if lateral is not None else LateralParams()
        self.max_speed_mps = float(max_speed_mps)
        self.min_speed_mps = float(min_speed_mps)
        self.state = KinematicState(0.0, 0.0, 0.0, 0.0)
        self.target_speed_mps = 0.0
        self.target_lane_y_m = 0.0
        self.last_accel_mps2 = 0.0

    def start(self, state: KinematicState, lane_y_m: float) -> None:
        """Begin an episode at ``state``, tracking its speed in the lane at ``lane_y_m``."""
        self.state = state
        self.target_speed_mps = state.speed_mps
        self.target_lane_y_m = lane_y_m
        self.last_accel_mps2 = 0.0

    def advance(self, n: int, dt_s: float) -> list[KinematicState]:
        """``n`` Euler steps of ``dt_s``: the states at the start of each step, then the end.

        Returns ``n + 1`` states (the first is the current one); :attr:`state` becomes the
        last. ``last_accel_mps2`` is the mean commanded acceleration over the steps.
        """
        p = self.lateral
        s = self.state
        out = [s]
        total = 0.0
        for _ in range(n):
            a = speed_control(s.speed_mps, self.target_speed_mps, self.tau_acc_s)
            steer = steering_control(s, self.target_lane_y_m, p)
            s = bicycle_step(s, a, steer, dt_s, p.length_m, self.max_speed_mps, self.min_speed_mps)
            out.append(s)
            total += a
        self.state = s
        self.last_accel_mps2 = total / n if n else 0.0
        return out
