"""What a VUT does to the traffic behind it (issue 33): the follower's measures and the
VUT's unjustified hard braking, per episode (pure numpy, no SUMO).

**The follower's measures** (the follower is SUMO's human-like driver behind the VUT,
:mod:`sumo_ayss.config.follower`), read on its samples while it is in the simulation:

* ``follower_min_ttc_s``: minimum TTC of the follower on the VUT, gap / closing speed, the
  gap VUT rear minus follower front (inf: never closing in);
* ``follower_min_thw_s``: minimum time headway, gap / the follower's speed;
* ``follower_max_braking_mps2``: the follower's largest deceleration between samples;
* ``follower_max_drac_mps2``: its largest DRAC on the VUT, closing² / (2 gap) (0: never
  closing in);
* ``rear_end``: 1 if the follower ran into the VUT (SUMO's collision pair), else 0.

**Unjustified hard braking.** The VUT brakes harder than :data:`HARD_BRAKING_MPS2` over a
decision while nothing ahead was critical at its start (the state it decided on) and no
leader had braked as hard just before; with two POVs (``lead_and_cut_in``), against
either of them (:func:`episode_hazards`' ``others``). Critical means, for the POV ahead of
the VUT's front, in its path or moving sideways toward it:

* its TTC (1-D in one path, or 2-D) below :data:`CRITICAL_TTC_S`, or
* the gap inside the Fuzzy Safety Model's unsafe distance (PFS = 1: the careful driver model
  proposed for R157 already brakes there), or
* the gap shorter than R157's minimum following distance
  (:func:`r157_min_following_distance_m`: a vehicle that close must open the gap).

And braking is answered, not unjustified, when the POV braked at least as hard over any
decision that started within :data:`REACTION_WINDOW_S` before this one (a leader's braking,
matched by a driver with a human reaction delay, is never "for nothing").

The numbers: 3.4 m/s² is AASHTO's design deceleration for stopping sight distance (*A
Policy on Geometric Design of Highways and Streets*, the "Green Book": "a comfortable
deceleration for most drivers": "A deceleration rate of 3.4 m/s² (11.2 ft/s²) is used to
determine stopping sight distance", the Green Book's text as quoted at
http://www.primidi.com/deceleration_rate, checked in session 9); TTC 2.0 s is UN
R157's criticality gate of the competent and careful driver (cut-in), and the FSM's
parameters (0.75 s reaction, 6 m/s² own and 7 m/s² leader braking, 2 m margin) are JRC's
(Mattas et al. 2020); the minimum following distance is R157 §5.2.3.3's (time gap
1.0 s + 0.01 s per km/h, at least 2 m; esmini ``Regulation::MinDist``); the reaction window
1.15 s is the careful driver's 0.4 s risk perception plus 0.75 s reaction (esmini's ECE
reference driver waits 0.75 + 0.4 s). All in ``../shared/research/reference-drivers.md``
§1.1, §1.3 and §1.4.

Why these clauses (issue 33, measured in ``benchmarks/unjustified_braking.py``): with only
the first two and the POV's braking in the one decision before, SUMO's IDM VUTs braked
"unjustifiably" in most episodes, almost all of it at time headways well below R157's
minimum following distance (a gap the POV had just closed by braking) while the gap was
already opening; the over-braker's excess is braking beyond that distance.

``unjustified_braking`` is 1 if any decision of the episode was such braking,
``unjustified_braking_max_mps2`` the hardest of them (0: none) and ``unjustified_dv_mps``
the speed shed in them, the sum of braking × decision period [m/s]: how much braking for
nothing, not only whether. ``rear_end_unjustified`` is
1 for a rear-end preceded, within :data:`REAR_END_WINDOW_S`, by unjustified braking: the
rear-end the VUT caused; a rear-end after necessary braking is 0 (and is the follower's).
Without a follower the follower columns and ``rear_end*`` are NaN.

Imports neither SUMO nor torch; reads no file.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import astuple, dataclass, fields

import numpy as np
from numpy.typing import NDArray

from sumo_ayss.analysis.safety_measures import PairTrajectory, ttc_2d

__all__ = [
    "CRITICAL_TTC_S",
    "HARD_BRAKING_MPS2",
    "HAZARD_NAMES",
    "OVERBRAKING_FACTOR",
    "OVERBRAKING_FLOOR_MPS",
    "REACTION_WINDOW_S",
    "REAR_END_WINDOW_S",
    "VUT_HAZARD_COLUMNS",
    "FollowerTrack",
    "HazardMeasures",
    "episode_hazards",
    "fsm_unsafe_distance_m",
    "harm_crash",
    "overbraking_flags",
    "r157_min_following_distance_m",
    "unjustified_braking",
    "vut_hazards",
]

FloatArray = NDArray[np.float64]

#: Hard braking [m/s²]: AASHTO's "comfortable for most drivers" design deceleration.
HARD_BRAKING_MPS2 = 3.4
#: TTC below which the situation ahead is critical [s] (R157's careful-driver gate).
CRITICAL_TTC_S = 2.0
#: A leader's braking this long before a decision [s] still justifies matching it: R157's
#: careful driver's risk perception 0.4 s plus reaction 0.75 s (reference-drivers.md §1.1).
REACTION_WINDOW_S = 1.15
#: A rear-end counts against the VUT when it braked unjustifiably this long before [s]:
#: the follower's 1 s reaction plus 2 s of its braking.
REAR_END_WINDOW_S = 3.0
#: The Fuzzy Safety Model's parameters (JRC; reference-drivers.md §1.4).
_FSM_TAU_S, _FSM_B_R_MAX, _FSM_B_L, _FSM_MARGIN_M = 0.75, 6.0, 7.0, 2.0


def fsm_unsafe_distance_m(v_rear_mps: FloatArray, v_lead_mps: FloatArray) -> FloatArray:
    """FSM's ``d_unsafe`` plus its margin [m]: below it the proactive fuzzy safety is 1.

    ``u_r·τ + u_r²/(2·b_r,max) - u_l²/(2·b_l) + margin_dist`` (JRC ``fuzzy_functs.py``).
    """
    v_r, v_l = np.asarray(v_rear_mps, float), np.asarray(v_lead_mps, float)
    return v_r * _FSM_TAU_S + v_r**2 / (2 * _FSM_B_R_MAX) - v_l**2 / (2 * _FSM_B_L) + _FSM_MARGIN_M


def r157_min_following_distance_m(v_mps: FloatArray) -> FloatArray:
    """UN R157 §5.2.3.3's minimum following distance at speed ``v_mps`` [m].

    Time gap 1.0 + v[km/h]/100 s from 10 km/h, 1.0 + (v[m/s] - 2)/7.8 s below, at least
    2 m (esmini ``Regulation::MinDist``; reference-drivers.md §1.3).
    """
    v = np.asarray(v_mps, float)
    gap_s = np.where(v * 3.6 >= 10.0, 1.0 + v * 3.6 / 100.0, 1.0 + (v - 2.0) / 7.8)
    distance_m: NDArray[np.float64] = np.maximum(v * gap_s, 2.0)
    return distance_m


@dataclass(frozen=True)
class FollowerTrack:
    """The follower's samples, at the trajectory's times.

    Attributes:
        x_m: Front-bumper position along the road [m]; NaN once it is gone (after a rear-end).
        speed_mps: Speed [m/s]; NaN once gone.
        rear_end: It ran into the VUT.
    """

    x_m: FloatArray
    speed_mps: FloatArray
    rear_end: bool


@dataclass(frozen=True)
class HazardMeasures:
    """One episode's hazards to others (see the module docstring for each field)."""

    follower_min_ttc_s: float
    follower_min_thw_s: float
    follower_max_braking_mps2: float
    follower_max_drac_mps2: float
    rear_end: float
    unjustified_braking: float
    unjustified_braking_max_mps2: float
    unjustified_dv_mps: float
    rear_end_unjustified: float

    def as_row(self) -> dict[str, float]:
        return dict(zip(HAZARD_NAMES, astuple(self), strict=True))


#: The hazard columns, in field order.
HAZARD_NAMES: tuple[str, ...] = tuple(f.name for f in fields(HazardMeasures))


def unjustified_braking(
    tr: PairTrajectory,
    *,
    reaction_window_s: float = REACTION_WINDOW_S,
    following_distance: bool = True,
) -> FloatArray:
    """The VUT's deceleration over each decision [m/s²] where it was unjustified, else 0.

    Args:
        tr: The episode (uniform sample times).
        reaction_window_s: The POV's braking over a decision that started this long before
            still justifies (at least one decision: the one before).
        following_distance: Inside R157's minimum following distance is critical.
            ``reaction_window_s=0, following_distance=False`` is session 9's first rule
            (kept to measure the change against, ``benchmarks/unjustified_braking.py``).

    Returns:
        Shape ``(n - 1,)``: entry ``k`` is the decision from sample ``k`` to ``k + 1``.
    """
    if tr.n < 2:
        return np.zeros(0)
    dt = np.diff(tr.time_s)
    braking = -np.diff(tr.vut_speed_mps) / dt
    gap = tr.pov_ahead_gap_m()
    closing = tr.vut_speed_mps - tr.pov_speed_mps
    side = np.sign(tr.pov_y_m - tr.vut_y_m)
    toward = -side * (tr.pov_lat_speed_mps - tr.vut_lat_speed_mps) > 0.0
    ahead = tr.pov_x_m > tr.vut_x_m
    relevant = ahead & (tr.in_path() | toward)
    with np.errstate(divide="ignore", invalid="ignore"):
        ttc_1d = np.where(closing > 0.0, np.maximum(gap, 0.0) / closing, np.inf)
    dx = (tr.pov_x_m - 0.5 * tr.pov_length_m) - (tr.vut_x_m - 0.5 * tr.vut_length_m)
    ttc2 = ttc_2d(
        dx,
        tr.pov_y_m - tr.vut_y_m,
        tr.pov_speed_mps - tr.vut_speed_mps,
        tr.pov_lat_speed_mps - tr.vut_lat_speed_mps,
        0.5 * (tr.pov_length_m + tr.vut_length_m),
        0.5 * (tr.pov_width_m + tr.vut_width_m),
    )
    close = gap < fsm_unsafe_distance_m(tr.vut_speed_mps, tr.pov_speed_mps)
    if following_distance:
        close |= gap < r157_min_following_distance_m(tr.vut_speed_mps)
    critical = relevant & ((np.minimum(ttc_1d, ttc2) < CRITICAL_TTC_S) | close)
    critical = critical[:-1] | (_leader_braked(tr, reaction_window_s) >= braking - 1e-6)
    hard = braking > HARD_BRAKING_MPS2
    return np.where(hard & ~critical, braking, 0.0)


def _leader_braked(tr: PairTrajectory, window_s: float) -> FloatArray:
    """Per decision ``k``, the POV's hardest braking over the decisions ``k - w .. k - 1``
    that started within ``window_s`` before it (``w`` >= 1; 0 before the first) [m/s²]."""
    dt = np.diff(tr.time_s)
    pov_braking = -np.diff(tr.pov_speed_mps) / dt
    w = max(1, math.floor(window_s / float(dt[0]) + 1e-9))
    padded = np.concatenate([np.zeros(w), pov_braking[:-1]])  # padded[k + j]: decision k - w + j
    worst: NDArray[np.float64] = np.lib.stride_tricks.sliding_window_view(padded, w).max(axis=1)
    return worst


def _follower(tr: PairTrajectory, f: FollowerTrack) -> tuple[float, float, float, float]:
    gap = tr.vut_x_m - tr.vut_length_m - f.x_m
    closing = f.speed_mps - tr.vut_speed_mps
    here = np.isfinite(gap) & (gap > 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        ttc = np.where(here & (closing > 0.0), gap / closing, np.inf)
        thw = np.where(here & (f.speed_mps > 0.0), gap / f.speed_mps, np.inf)
        drac = np.where(here & (closing > 0.0), closing**2 / (2.0 * gap), 0.0)
    if f.rear_end:  # the sample it hit at is gone (NaN): contact, TTC and headway 0
        ttc, thw = np.append(ttc, 0.0), np.append(thw, 0.0)
    decel = -np.diff(f.speed_mps) / np.diff(tr.time_s)
    decel = decel[np.isfinite(decel)]
    return (
        float(ttc.min(initial=math.inf)),
        float(thw.min(initial=math.inf)),
        max(0.0, float(decel.max(initial=0.0))),
        float(drac.max(initial=0.0)),
    )


def episode_hazards(
    tr: PairTrajectory, follower: FollowerTrack | None, others: Sequence[PairTrajectory] = ()
) -> HazardMeasures:
    """The :class:`HazardMeasures` of one episode (``follower`` None: no follower).

    ``others``: the same episode seen against each further POV (``lead_and_cut_in``'s
    supporting POV, in ``tr``'s POV fields): braking is unjustified only where it is so
    against every POV (any of them ahead and critical, or braking, justifies it).
    """
    ub = unjustified_braking(tr)
    for other in others:
        ub = np.where(unjustified_braking(other) > 0.0, ub, 0.0)
    any_ub = bool(np.any(ub > 0.0))
    if follower is None:
        fol = (math.nan, math.nan, math.nan, math.nan)
        rear, caused = math.nan, math.nan
    else:
        fol = _follower(tr, follower)
        rear = float(follower.rear_end)
        caused = 0.0
        if follower.rear_end:
            alive = np.flatnonzero(np.isfinite(follower.x_m))
            t_hit = tr.time_s[min(int(alive[-1]) + 1, tr.n - 1)] if alive.size else 0.0
            start = tr.time_s[:-1]
            window = (start >= t_hit - REAR_END_WINDOW_S) & (start < t_hit)
            caused = float(np.any(ub[window] > 0.0))
    return HazardMeasures(
        *fol,
        rear_end=rear,
        unjustified_braking=float(any_ub),
        unjustified_braking_max_mps2=float(ub.max(initial=0.0)),
        unjustified_dv_mps=float(np.sum(ub * np.diff(tr.time_s))) if tr.n > 1 else 0.0,
        rear_end_unjustified=caused,
    )


# --------------------------------------------------------------------------- per VUT

#: The per-episode columns averaged per VUT for the leaderboard (a rate for the 0/1 ones).
VUT_HAZARD_COLUMNS: tuple[str, ...] = (
    "unjustified_braking",
    "unjustified_dv_mps",
    "rear_end",
    "rear_end_unjustified",
    "follower_max_braking_mps2",
    "follower_max_drac_mps2",
)

#: OVER-BRAKING: a VUT sheds more than this factor × the median VUT's speed in unjustified
#: hard braking per episode (over the same episodes) ...
OVERBRAKING_FACTOR = 1.5
#: ... and more than this much [m/s per episode]: one decision (the paper's 0.2 s) of hard
#: braking per episode on average, so a pool that hardly brakes for nothing flags nobody.
#: (1.0 m/s under the first rule; the revised rule calls far less braking unjustified: with
#: the scripted POV of ``benchmarks/unjustified_braking.py`` the over-braker shed 0.87 m/s
#: per episode in cut-in, the IDM VUTs 0.01 and 0.11.)
OVERBRAKING_FLOOR_MPS = HARD_BRAKING_MPS2 * 0.2


def vut_hazards(
    vut: NDArray[np.str_] | list[str], columns: dict[str, NDArray[np.float64]]
) -> dict[str, dict[str, float]] | None:
    """Per VUT, the mean of each of :data:`VUT_HAZARD_COLUMNS` over its episodes (NaN
    episodes, not recorded, left out; NaN where none is recorded). None when no episode
    recorded any: a table written before the hazards."""
    names = np.asarray(vut).astype(str)
    present = [c for c in VUT_HAZARD_COLUMNS if c in columns]
    if not present or all(np.isnan(np.asarray(columns[c], float)).all() for c in present):
        return None
    out: dict[str, dict[str, float]] = {}
    for v in dict.fromkeys(names.tolist()):
        mine = names == v
        row = {}
        for c in VUT_HAZARD_COLUMNS:
            values = np.asarray(columns[c], float)[mine] if c in columns else np.array([])
            values = values[np.isfinite(values)]
            row[c] = float(values.mean()) if values.size else math.nan
        out[v] = row
    return out


def overbraking_flags(dv_mps: dict[str, float]) -> dict[str, bool]:
    """Which VUTs brake for nothing far more than the others: mean unjustified Δv per
    episode above :data:`OVERBRAKING_FACTOR` × the median VUT's and above
    :data:`OVERBRAKING_FLOOR_MPS`. Never flagged without two recorded values."""
    known = [v for v in dv_mps.values() if math.isfinite(v)]
    if len(known) < 2:
        return dict.fromkeys(dv_mps, False)
    median = float(np.median(known))
    limit = max(OVERBRAKING_FACTOR * median, OVERBRAKING_FLOOR_MPS)
    return {name: math.isfinite(v) and v > limit for name, v in dv_mps.items()}


def harm_crash(
    collided: NDArray[np.bool_], rear_end_unjustified: NDArray[np.float64] | None
) -> NDArray[np.bool_]:
    """The episodes the harm score counts as a crash (harm 1): a collision with the POV, or
    a rear-end the VUT caused by unjustified braking (NaN, not recorded: not one)."""
    crash = np.asarray(collided, dtype=bool)
    if rear_end_unjustified is None:
        return crash
    caused = np.nan_to_num(np.asarray(rear_end_unjustified, float), nan=0.0) == 1.0
    harmed: NDArray[np.bool_] = crash | caused
    return harmed
