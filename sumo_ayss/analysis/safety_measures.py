"""Surrogate safety measures of one episode, from its trajectory (pure numpy, no SUMO).

The rollout records each episode as a :class:`PairTrajectory`: the two vehicles' states at
the reset and at the end of every decision. :func:`episode_measures` reduces it to the
:class:`EpisodeMeasures` that go to ``outcome.csv`` and ``crossplay.csv``, one row per
episode. Each measure is defined, with its unit, sign and reference, on its field.

Frame and bodies (as on the built-in straight roads, which run along +x):

* ``x`` is the *front bumper's* position along the road [m]; ``y`` the lateral position of
  the body's centre line [m], positive to the left.
* A body is a rectangle aligned with the road, ``[x - length, x] × [y - width/2,
  y + width/2]``: SUMO moves a changing vehicle sideways as a whole, without turning its
  body (see :mod:`sumo_ayss.envs.cut_in`).
* Two vehicles are *in each other's path* when their bodies overlap laterally,
  ``|y_pov - y_vut| < (w_pov + w_vut) / 2``: the 1-D measures (TTC, headway, DRAC) are
  read only then; the 2-D TTC needs no such condition.
* Between two samples the motion is linear (SUMO's own position update moves a vehicle by
  its speed over the step), so event times (a lane intrusion, an arrival) are interpolated
  linearly between the samples around them.

The sampling is the decision period (0.2 s by default, one SUMO step): a finer SUMO step
is not seen between decisions, so an extremum between two decisions can be missed.

References:

* Review of all of them: Wang, C., Xie, Y., Huang, H., Liu, P. (2021). A review of
  surrogate safety measures and their applications in connected and automated vehicles
  safety modeling. Accident Analysis & Prevention 157, 106157 (the paper's
  ``wang2021review``).
* TTC: Hayward, J. C. (1972). Near-miss determination through use of a scale of danger.
  Highway Research Record 384, 24–34.
* 2-D TTC: Guo, H., Xie, K., Keyvan-Ekbatani, M. (2023). Modeling driver's evasive
  behavior during safety-critical lane changes: two-dimensional time-to-collision and deep
  reinforcement learning. Accident Analysis & Prevention 186, 107063 (the paper's
  ``guo2023modeling``).
* Time headway: Vogel, K. (2003). A comparison of headway and time to collision as safety
  indicators. Accident Analysis & Prevention 35(3), 427–433.
* DRAC: Almqvist, S., Hydén, C., Risser, R. (1991). Use of speed limiters in cars for
  increased safety and a better environment. Transportation Research Record 1318, 34–39.
* PET: Allen, B. L., Shin, B. T., Cooper, P. J. (1978). Analysis of traffic conflicts and
  collisions. Transportation Research Record 667, 67–74.
* Relative speed at impact as harm: for a plastic collision of two equal masses each
  vehicle's velocity change (delta-V) is half the relative speed; delta-V is the usual
  predictor of injury risk (Joksch, H. C. (1993). Velocity change and fatality risk in a
  crash — a rule of thumb. Accident Analysis & Prevention 25(1), 103–104).

Imports neither SUMO nor torch; reads no file.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sumo_ayss.analysis.metrics import time_to_collision
from sumo_ayss.analysis.r157 import R157_INTRUSION_DEPTH_M, must_avoid
from sumo_ayss.util.errors import ConfigError

__all__ = [
    "MEASURE_NAMES",
    "EpisodeMeasures",
    "PairTrajectory",
    "crossing_time",
    "episode_measures",
    "ttc_2d",
]

FloatArray = NDArray[np.float64]


def _arr(value: ArrayLike, name: str, n: int | None = None) -> FloatArray:
    try:
        out = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ConfigError(f"{name}: expected real numbers") from exc
    if out.ndim != 1 or (n is not None and out.size != n):
        raise ConfigError(f"{name}: expected a 1-D array of {n or 'n'} samples, got {out.shape}")
    return out


#: The scalar (not per-sample) fields of :class:`PairTrajectory`.
_SCALARS = frozenset(
    {"vut_length_m", "pov_length_m", "vut_width_m", "pov_width_m", "vut_lane_edge_y_m"}
)


@dataclass(frozen=True)
class PairTrajectory:
    """One episode's states, sampled at the reset (index 0) and after each decision.

    Attributes:
        time_s: Sample times from the episode's start [s], strictly increasing.
        vut_x_m, pov_x_m: Front-bumper positions along the road [m].
        vut_y_m, pov_y_m: Lateral positions of the body's centre line [m], + left.
        vut_speed_mps, pov_speed_mps: Longitudinal speeds [m/s].
        vut_lat_speed_mps, pov_lat_speed_mps: Lateral speeds [m/s], + left.
        collided: The episode ended in a collision (at its last sample).
        vut_length_m, pov_length_m, vut_width_m, pov_width_m: Body sizes [m].
        vut_lane_edge_y_m: Cut-in: lateral position [m] of the boundary of the VUT's lane
            that the POV crosses to cut in; ``None`` when the POV starts in the VUT's lane
            (car-following): no intrusion measures then.
    """

    time_s: FloatArray
    vut_x_m: FloatArray
    pov_x_m: FloatArray
    vut_y_m: FloatArray
    pov_y_m: FloatArray
    vut_speed_mps: FloatArray
    pov_speed_mps: FloatArray
    vut_lat_speed_mps: FloatArray
    pov_lat_speed_mps: FloatArray
    collided: bool
    vut_length_m: float
    pov_length_m: float
    vut_width_m: float
    pov_width_m: float
    vut_lane_edge_y_m: float | None = None

    def __post_init__(self) -> None:
        n = np.asarray(self.time_s).size
        for f in fields(self):
            if f.name.endswith(("_m", "_mps", "_s")) and f.name not in _SCALARS:
                object.__setattr__(self, f.name, _arr(getattr(self, f.name), f.name, n))
        if n < 1 or np.any(np.diff(self.time_s) <= 0):
            raise ConfigError("time_s: expected at least one sample, strictly increasing")
        for name in ("vut_length_m", "pov_length_m", "vut_width_m", "pov_width_m"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ConfigError(f"{name}: expected a length > 0, got {value!r}")

    @property
    def n(self) -> int:
        return int(self.time_s.size)

    def pov_ahead_gap_m(self) -> FloatArray:
        """Gap POV rear minus VUT front [m] (the env's headway h; < 0 = overlap or behind)."""
        return self.pov_x_m - self.pov_length_m - self.vut_x_m

    def in_path(self) -> NDArray[np.bool_]:
        """The bodies overlap laterally (each is in the other's path)."""
        half = 0.5 * (self.pov_width_m + self.vut_width_m)
        return np.abs(self.pov_y_m - self.vut_y_m) < half


# --------------------------------------------------------------------------- instant measures


def ttc_2d(
    dx_m: ArrayLike,
    dy_m: ArrayLike,
    dvx_mps: ArrayLike,
    dvy_mps: ArrayLike,
    half_length_sum_m: float,
    half_width_sum_m: float,
) -> FloatArray:
    """2-D time to collision of two road-aligned rectangles at constant velocities [s].

    Guo et al. (2023): the time until the two bodies first touch if both keep their
    current velocity (vector), whatever their lanes. For rectangles that keep their
    orientation the bodies overlap exactly while both the x and the y projections overlap,
    so the first contact is the latest of the two axes' entry times, if it comes before
    the earliest exit time.

    Args:
        dx_m, dy_m: Centre of the POV's body minus the VUT's [m], any shape.
        dvx_mps, dvy_mps: POV velocity minus the VUT's [m/s].
        half_length_sum_m: ``(L_pov + L_vut) / 2`` [m].
        half_width_sum_m: ``(W_pov + W_vut) / 2`` [m].

    Returns:
        TTC in s: 0 where the bodies overlap now, ``+inf`` where they never will.
    """
    entry: list[FloatArray] = []
    leave: list[FloatArray] = []
    for d, u, half in (
        (dx_m, dvx_mps, half_length_sum_m),
        (dy_m, dvy_mps, half_width_sum_m),
    ):
        d_arr, u_arr = np.broadcast_arrays(np.asarray(d, float), np.asarray(u, float))
        inside = np.abs(d_arr) < half
        with np.errstate(divide="ignore", invalid="ignore"):
            t1, t2 = (-half - d_arr) / u_arr, (half - d_arr) / u_arr
        lo = np.where(u_arr == 0.0, np.where(inside, -np.inf, np.inf), np.minimum(t1, t2))
        hi = np.where(u_arr == 0.0, np.where(inside, np.inf, -np.inf), np.maximum(t1, t2))
        entry.append(lo)
        leave.append(hi)
    first, last = np.maximum(entry[0], entry[1]), np.minimum(leave[0], leave[1])
    hit = (first < last) & (last > 0.0)
    return np.where(hit, np.maximum(first, 0.0), np.inf)


def crossing_time(time_s: ArrayLike, values: ArrayLike, level: float) -> tuple[float, int]:
    """First time ``values`` rises above ``level``, interpolated linearly between samples.

    Returns:
        ``(time [s], index of the first sample above)``; ``(nan, -1)`` if it never does,
        ``(time_s[0], 0)`` if it starts above.
    """
    t, v = np.asarray(time_s, float), np.asarray(values, float)
    above = np.flatnonzero(v > level)
    if above.size == 0:
        return math.nan, -1
    k = int(above[0])
    if k == 0:
        return float(t[0]), 0
    frac = (level - v[k - 1]) / (v[k] - v[k - 1])
    return float(t[k - 1] + frac * (t[k] - t[k - 1])), k


def _at(time_s: FloatArray, values: FloatArray, t: float) -> float:
    return float(np.interp(t, time_s, values))


# --------------------------------------------------------------------------- episode measures


@dataclass(frozen=True)
class EpisodeMeasures:
    """The surrogate safety measures of one episode (the columns of the episode tables).

    Attributes:
        min_ttc_s: Minimum 1-D time to collision [s] (Hayward 1972) over the samples where
            the bodies overlap laterally: bumper gap over closing speed of the follower on
            its leader (whichever vehicle is ahead), 0 while the bodies overlap, ``+inf``
            if they never close in while in one path.
        min_ttc_2d_s: Minimum 2-D time to collision [s] (Guo et al. 2023) over all
            samples, also while in different lanes (:func:`ttc_2d`); 0 at a collision,
            ``+inf`` if the bodies are never on a collision course. Equals
            ``min_ttc_s`` in car-following.
        min_thw_s: Minimum time headway of the VUT [s] (Vogel 2003): gap to the POV ahead
            in its path over the VUT's speed; 0 at overlap, ``+inf`` if the POV is never
            ahead in its path (or the VUT stands).
        max_drac_mps2: Maximum deceleration rate to avoid a crash [m/s², > 0] (Almqvist et
            al. 1991): ``(v_vut - v_pov)² / (2 gap)`` while the VUT closes in on the POV
            ahead in its path with a gap > 0; 0 if it never does.
        vut_max_braking_mps2: The VUT's largest deceleration [m/s², > 0 = braking], from
            the speed change over each decision; 0 if it never slowed.
        vut_max_jerk_mps3: The VUT's largest |jerk| [m/s³]: change between consecutive
            decisions' mean accelerations over the time between their midpoints; NaN with
            fewer than two decisions.
        intrusion_ttc_s: Cut-in: 1-D TTC [s] of the VUT on the POV at the moment the POV's
            body enters the VUT's lane (its near side crosses the lane boundary), speeds
            and positions interpolated to that moment; 0 if the POV's rear is then beside
            the VUT (gap <= 0). NaN without an intrusion (car-following, no lane change).
        intrusion_gap_m: Cut-in: the gap POV rear minus VUT front [m] at that moment
            (< 0: beside the VUT). NaN without an intrusion.
        pet_s: Cut-in: post-encroachment time [s] (Allen et al. 1978): from the intrusion
            (the POV's rear at point x_c of the VUT's lane) until the VUT's front reaches
            x_c. NaN where undefined: no intrusion, the POV's rear was beside or behind the
            VUT's front at the intrusion, or the VUT did not reach x_c within the episode
            (PET longer than the rest of the episode).
        impact_speed_mps: Collision: magnitude of the relative velocity [m/s] (longitudinal
            and lateral) at the first sample that shows the collision (the end of the SUMO
            step in which the bodies first overlapped). NaN without a collision. Harm:
            each equal-mass vehicle's delta-V is half of it (Joksch 1993).
        r157_ttc_lane_intrusion_s: Cut-in: 1-D TTC [s] when the POV's near side is 0.3 m
            inside the VUT's lane (:mod:`sumo_ayss.analysis.r157`); NaN without it.
        r157_must_avoid: 1 if the R157 cut-in condition says the collision must be avoided
            (:func:`sumo_ayss.analysis.r157.must_avoid`, constant 0.35 s), 0 if not, NaN
            without an intrusion 0.3 m deep.
        r157_closing_mps: Cut-in: ``v_vut - v_pov`` [m/s] at that intrusion (> 0 closing
            in), so that the condition can be read with another constant; NaN without it.
    """

    min_ttc_s: float
    min_ttc_2d_s: float
    min_thw_s: float
    max_drac_mps2: float
    vut_max_braking_mps2: float
    vut_max_jerk_mps3: float
    intrusion_ttc_s: float = math.nan
    intrusion_gap_m: float = math.nan
    pet_s: float = math.nan
    impact_speed_mps: float = math.nan
    r157_ttc_lane_intrusion_s: float = math.nan
    r157_must_avoid: float = math.nan
    r157_closing_mps: float = math.nan

    def as_row(self) -> dict[str, float]:
        """``{column name: value}`` for a table row."""
        return {f.name: float(getattr(self, f.name)) for f in fields(self)}


#: Column names of :class:`EpisodeMeasures`, in order.
MEASURE_NAMES: tuple[str, ...] = tuple(f.name for f in fields(EpisodeMeasures))


def _min(values: FloatArray, empty: float) -> float:
    return float(values.min()) if values.size else empty


def _longitudinal_ttc(tr: PairTrajectory) -> FloatArray:
    """1-D TTC at each sample where the bodies overlap laterally (+inf elsewhere)."""
    ahead = tr.pov_x_m >= tr.vut_x_m  # the POV's front ahead: the VUT follows
    gap = np.where(ahead, tr.pov_ahead_gap_m(), tr.vut_x_m - tr.vut_length_m - tr.pov_x_m)
    closing = np.where(
        ahead, tr.vut_speed_mps - tr.pov_speed_mps, tr.pov_speed_mps - tr.vut_speed_mps
    )
    ttc = np.asarray(time_to_collision(gap, closing), dtype=float).reshape(-1)
    return np.where(tr.in_path(), ttc, np.inf)


def _following(tr: PairTrajectory) -> NDArray[np.bool_]:
    """The VUT follows the POV in one path (the POV's front ahead of the VUT's)."""
    return tr.in_path() & (tr.pov_x_m >= tr.vut_x_m)


def _headway(tr: PairTrajectory) -> FloatArray:
    gap = np.maximum(tr.pov_ahead_gap_m(), 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        thw = np.where(gap > 0.0, gap / tr.vut_speed_mps, 0.0)
    thw = np.where(np.isnan(thw), np.inf, thw)
    return thw[_following(tr)]


def _drac(tr: PairTrajectory) -> FloatArray:
    gap, closing = tr.pov_ahead_gap_m(), tr.vut_speed_mps - tr.pov_speed_mps
    use = _following(tr) & (gap > 0.0) & (closing > 0.0)
    return closing[use] ** 2 / (2.0 * gap[use])


def _braking_and_jerk(tr: PairTrajectory) -> tuple[float, float]:
    if tr.n < 2:
        return 0.0, math.nan
    dt = np.diff(tr.time_s)
    accel = np.diff(tr.vut_speed_mps) / dt
    braking = max(0.0, float(-accel.min()))
    if accel.size < 2:
        return braking, math.nan
    mid = tr.time_s[:-1] + 0.5 * dt
    jerk = np.diff(accel) / np.diff(mid)
    return braking, float(np.abs(jerk).max())


def _intrusion_depth_m(tr: PairTrajectory) -> FloatArray:
    """How far the POV's near side reaches into the VUT's lane [m] (> 0 = inside)."""
    assert tr.vut_lane_edge_y_m is not None
    side = 1.0 if tr.pov_y_m[0] >= tr.vut_y_m[0] else -1.0  # the POV comes from the left
    near = tr.pov_y_m - side * 0.5 * tr.pov_width_m
    return side * (tr.vut_lane_edge_y_m - near)


def state_at(tr: PairTrajectory, t: float) -> tuple[float, float]:
    """``(gap POV rear - VUT front [m], closing speed v_vut - v_pov [m/s])`` at time ``t``,
    interpolated linearly between the samples."""
    gap = _at(tr.time_s, tr.pov_ahead_gap_m(), t)
    closing = _at(tr.time_s, tr.vut_speed_mps - tr.pov_speed_mps, t)
    return gap, closing


class Intrusion(NamedTuple):
    """The state when the POV's near side is a given depth inside the VUT's lane.

    Attributes:
        time_s: When [s] (interpolated between samples).
        gap_m: POV rear minus VUT front [m] then (< 0: beside the VUT).
        closing_mps: ``v_vut - v_pov`` [m/s] then, > 0 when the VUT closes in.
        ttc_s: The VUT's 1-D TTC on the POV then [s] (0 when ``gap_m <= 0``).
    """

    time_s: float
    gap_m: float
    closing_mps: float
    ttc_s: float


_NO_INTRUSION = Intrusion(math.nan, math.nan, math.nan, math.nan)


def intrusion(tr: PairTrajectory, depth_m: float = 0.0) -> Intrusion:
    """The moment the POV's near side is ``depth_m`` inside the VUT's lane (first time).

    All NaN if it never is, or the trajectory has no lane edge (car-following).
    """
    if tr.vut_lane_edge_y_m is None:
        return _NO_INTRUSION
    t, _ = crossing_time(tr.time_s, _intrusion_depth_m(tr), depth_m)
    if math.isnan(t):
        return _NO_INTRUSION
    gap, closing = state_at(tr, t)
    return Intrusion(t, gap, closing, float(time_to_collision(gap, closing)))


def _pet(tr: PairTrajectory, t_in: float) -> float:
    if math.isnan(t_in):
        return math.nan
    x_c = _at(tr.time_s, tr.pov_x_m, t_in) - tr.pov_length_m  # the POV's rear at entry
    if _at(tr.time_s, tr.vut_x_m, t_in) >= x_c:
        return math.nan  # entered beside or behind the VUT's front: no encroachment ahead
    later = tr.time_s > t_in
    times = np.concatenate([[t_in], tr.time_s[later]])
    xs = np.concatenate([[_at(tr.time_s, tr.vut_x_m, t_in)], tr.vut_x_m[later]])
    t_arrive, _ = crossing_time(times, xs, x_c)
    return t_arrive - t_in


def episode_measures(tr: PairTrajectory) -> EpisodeMeasures:
    """All :class:`EpisodeMeasures` of one episode's trajectory."""
    half_l = 0.5 * (tr.pov_length_m + tr.vut_length_m)
    half_w = 0.5 * (tr.pov_width_m + tr.vut_width_m)
    dx = (tr.pov_x_m - 0.5 * tr.pov_length_m) - (tr.vut_x_m - 0.5 * tr.vut_length_m)
    ttc2 = ttc_2d(
        dx,
        tr.pov_y_m - tr.vut_y_m,
        tr.pov_speed_mps - tr.vut_speed_mps,
        tr.pov_lat_speed_mps - tr.vut_lat_speed_mps,
        half_l,
        half_w,
    )
    braking, jerk = _braking_and_jerk(tr)
    entry = intrusion(tr)
    r157 = intrusion(tr, depth_m=R157_INTRUSION_DEPTH_M)
    impact = math.nan
    if tr.collided:
        impact = math.hypot(
            tr.vut_speed_mps[-1] - tr.pov_speed_mps[-1],
            tr.vut_lat_speed_mps[-1] - tr.pov_lat_speed_mps[-1],
        )
    return EpisodeMeasures(
        min_ttc_s=_min(_longitudinal_ttc(tr), math.inf),
        min_ttc_2d_s=_min(ttc2, math.inf),
        min_thw_s=_min(_headway(tr), math.inf),
        max_drac_mps2=float(_drac(tr).max(initial=0.0)),
        vut_max_braking_mps2=braking,
        vut_max_jerk_mps3=jerk,
        intrusion_ttc_s=entry.ttc_s,
        intrusion_gap_m=entry.gap_m,
        pet_s=_pet(tr, entry.time_s),
        impact_speed_mps=impact,
        r157_ttc_lane_intrusion_s=r157.ttc_s,
        r157_must_avoid=must_avoid(r157.ttc_s, r157.closing_mps),
        r157_closing_mps=r157.closing_mps,
    )
