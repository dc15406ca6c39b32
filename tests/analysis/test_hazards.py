"""Hazards a VUT causes (issue 33), on hand-built trajectories: each rule can fail."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sumo_ayss.analysis.hazards import (
    HARD_BRAKING_MPS2,
    REACTION_WINDOW_S,
    FollowerTrack,
    episode_hazards,
    fsm_unsafe_distance_m,
    r157_min_following_distance_m,
    unjustified_braking,
)
from sumo_ayss.analysis.safety_measures import PairTrajectory

DT = 0.2


def _traj(vut_v, pov_v, gap0, pov_y=0.0, pov_lat=0.0) -> PairTrajectory:  # type: ignore[no-untyped-def]
    """Car-following on one lane: VUT front at 0, POV rear ``gap0`` ahead; speeds per sample."""
    vut_v, pov_v = np.asarray(vut_v, float), np.asarray(pov_v, float)
    n = vut_v.size
    t = np.arange(n) * DT
    # positions by the trapezoid of the speeds (good enough for the rules tested)
    vut_x = np.concatenate([[0.0], np.cumsum(0.5 * (vut_v[1:] + vut_v[:-1]) * DT)])
    pov_x = 5.0 + gap0 + np.concatenate([[0.0], np.cumsum(0.5 * (pov_v[1:] + pov_v[:-1]) * DT)])
    zeros = np.zeros(n)
    return PairTrajectory(
        time_s=t,
        vut_x_m=vut_x,
        pov_x_m=pov_x,
        vut_y_m=zeros,
        pov_y_m=zeros + pov_y,
        vut_speed_mps=vut_v,
        pov_speed_mps=pov_v,
        vut_lat_speed_mps=zeros,
        pov_lat_speed_mps=zeros + pov_lat,
        collided=False,
        vut_length_m=5.0,
        pov_length_m=5.0,
        vut_width_m=1.8,
        pov_width_m=1.8,
    )


def _braking(v0: float, decel: float, n: int) -> np.ndarray:
    return np.maximum(v0 - decel * DT * np.arange(n), 0.0)


def test_hard_braking_behind_a_cruising_far_leader_is_unjustified() -> None:
    tr = _traj(_braking(20.0, 6.0, 6), [20.0] * 6, gap0=35.0)
    assert fsm_unsafe_distance_m(np.array(20.0), np.array(20.0)) < 35.0  # not proximity
    ub = unjustified_braking(tr)
    assert ub == pytest.approx([6.0] * 5)
    h = episode_hazards(tr, None)
    assert h.unjustified_braking == 1.0 and h.unjustified_braking_max_mps2 == pytest.approx(6.0)
    assert math.isnan(h.rear_end) and math.isnan(h.follower_min_ttc_s)


def test_without_any_leader_hard_braking_is_unjustified() -> None:
    tr = _traj(_braking(20.0, 5.0, 4), [30.0] * 4, gap0=-300.0)  # the POV far behind
    assert (unjustified_braking(tr) > 0).all()


def test_gentle_braking_is_never_counted() -> None:
    tr = _traj(_braking(20.0, HARD_BRAKING_MPS2 - 0.4, 6), [20.0] * 6, gap0=35.0)
    assert not unjustified_braking(tr).any()


def test_braking_as_hard_as_a_braking_leader_is_justified() -> None:
    pov = _braking(20.0, 6.0, 7)
    vut = np.concatenate([[20.0], _braking(20.0, 6.0, 6)])  # one decision later, as hard
    tr = _traj(vut, pov, gap0=60.0)
    assert not unjustified_braking(tr)[1:].any()


def test_braking_at_a_short_ttc_is_justified() -> None:
    # closing in at 12 m/s on a stopped POV 23.5 m ahead: TTC 1.96 s < 2 s, while the gap is
    # outside the FSM's unsafe distance (23 m): the TTC rule alone justifies it
    assert fsm_unsafe_distance_m(np.array(12.0), np.array(0.0)) < 23.5
    tr = _traj(_braking(12.0, 6.0, 2), [0.0] * 2, gap0=23.5)
    assert not unjustified_braking(tr)[0]
    far = _traj(_braking(12.0, 6.0, 2), [0.0] * 2, gap0=24.5)  # TTC 2.04 s: not critical
    assert unjustified_braking(far)[0] > 0


def test_braking_inside_the_fsm_unsafe_distance_is_justified() -> None:
    # equal speeds, 8 m at 20 m/s: the FSM careful driver brakes here too
    assert fsm_unsafe_distance_m(np.array(20.0), np.array(20.0)) > 8.0
    tr = _traj(_braking(20.0, 5.0, 2), [20.0] * 2, gap0=8.0)
    assert not unjustified_braking(tr).any()


def test_r157_minimum_following_distance_by_hand() -> None:
    # 1.0 s + 0.01 s per km/h from 10 km/h; 1.0 + (v - 2)/7.8 s below; at least 2 m
    v = np.array([0.0, 2.0, 10.0, 100 / 3.6])
    expected = [2.0, 2.0, 10.0 * 1.36, 100 / 3.6 * 2.0]
    assert r157_min_following_distance_m(v) == pytest.approx(expected)
    assert r157_min_following_distance_m(np.array(10 / 3.6)) == pytest.approx(10 / 3.6 * 1.1)


def test_braking_inside_r157s_following_distance_is_justified() -> None:
    # 28 m at 20 m/s, the POV as fast: outside the FSM's unsafe distance (21.8 m), TTC
    # infinite, but inside R157's minimum following distance (34.4 m): opening it is necessary
    assert fsm_unsafe_distance_m(np.array(20.0), np.array(20.0)) < 28.0
    assert r157_min_following_distance_m(np.array(20.0)) > 28.0
    tr = _traj(_braking(20.0, 5.0, 2), [20.0] * 2, gap0=28.0)
    assert not unjustified_braking(tr).any()
    assert unjustified_braking(tr, following_distance=False).all()  # the clause does it
    beyond = _traj(_braking(20.0, 5.0, 2), [20.0] * 2, gap0=35.0)  # beyond it: for nothing
    assert unjustified_braking(beyond).all()


def test_a_leader_that_braked_within_the_reaction_window_justifies_braking() -> None:
    # the POV brakes at 6 m/s² for one decision, then holds; the VUT, 60 m behind (far beyond
    # every distance), brakes as hard k decisions later: an answer within 1.15 s, else not
    def run(k: int, window_s: float = REACTION_WINDOW_S) -> float:
        pov = np.array([20.0, 18.8] + [18.8] * (k + 1))
        vut = np.array([20.0] * (k + 1) + [20.0 - 6.0 * DT, 20.0 - 6.0 * DT])
        return float(unjustified_braking(_traj(vut, pov, gap0=60.0), reaction_window_s=window_s)[k])

    assert int(REACTION_WINDOW_S / DT + 1e-9) == 5  # decisions that started 0.2 .. 1.0 s before
    for k in range(1, 6):
        assert run(k) == 0.0, k
    assert run(6) == pytest.approx(6.0)  # 1.2 s later: no longer an answer
    assert run(1, window_s=0.0) == 0.0  # the first rule: the decision just before only
    assert run(3, window_s=0.0) == pytest.approx(6.0)


def test_a_cut_in_moving_toward_the_vut_at_short_ttc_justifies_braking() -> None:
    # the POV one lane left (3.2 m), moving right at 1.5 m/s, 6 m ahead, 8 m/s slower
    tr = _traj(_braking(28.0, 6.0, 2), [20.0] * 2, gap0=6.0, pov_y=3.2, pov_lat=-1.5)
    assert not unjustified_braking(tr).any()
    away = _traj(_braking(28.0, 6.0, 2), [20.0] * 2, gap0=6.0, pov_y=3.2, pov_lat=1.5)
    assert unjustified_braking(away).all()  # moving away from the VUT's lane: nothing ahead


def test_follower_measures_by_hand() -> None:
    tr = _traj([20.0, 20.0, 20.0], [20.0] * 3, gap0=50.0)
    # follower 10 m behind the VUT's rear at 25 m/s, then 24, 22
    gaps = np.array([10.0, 9.0, 8.4])
    fol = FollowerTrack(tr.vut_x_m - 5.0 - gaps, np.array([25.0, 24.0, 22.0]), rear_end=False)
    h = episode_hazards(tr, fol)
    assert h.follower_min_ttc_s == pytest.approx(min(10 / 5, 9 / 4, 8.4 / 2))
    assert h.follower_min_thw_s == pytest.approx(min(10 / 25, 9 / 24, 8.4 / 22))
    assert h.follower_max_braking_mps2 == pytest.approx(10.0)  # 24 -> 22 in 0.2 s
    assert h.follower_max_drac_mps2 == pytest.approx(max(25 / 20, 16 / 18, 4 / 16.8))
    assert h.rear_end == 0.0 and h.rear_end_unjustified == 0.0


def _rear_end(vut_v, pov_v, gap0) -> FollowerTrack:  # type: ignore[no-untyped-def]
    tr = _traj(vut_v, pov_v, gap0)
    x = tr.vut_x_m - 5.0 - 3.0
    x[-1] = np.nan  # gone after the hit
    v = np.array(vut_v, float) + 2.0
    v[-1] = np.nan
    return FollowerTrack(x, v, rear_end=True)


def test_a_rear_end_after_unjustified_braking_counts_against_the_vut() -> None:
    vut, pov = _braking(20.0, 6.0, 6), [20.0] * 6
    h = episode_hazards(_traj(vut, pov, 35.0), _rear_end(vut, pov, 35.0))
    assert h.rear_end == 1.0 and h.rear_end_unjustified == 1.0
    assert h.follower_min_ttc_s == 0.0


def test_a_rear_end_after_necessary_braking_does_not() -> None:
    pov = _braking(20.0, 6.0, 7)
    vut = np.concatenate([[20.0], _braking(20.0, 6.0, 6)])
    h = episode_hazards(_traj(vut, pov, 60.0), _rear_end(vut, pov, 60.0))
    assert h.rear_end == 1.0 and h.rear_end_unjustified == 0.0


# --------------------------------------------------------------------------- per VUT, flag


def test_overbraking_flags_the_vut_far_above_the_median() -> None:
    from sumo_ayss.analysis.hazards import overbraking_flags

    flags = overbraking_flags({"pi1": 1.0, "pi2": 2.8, "over": 6.2})
    assert flags == {"pi1": False, "pi2": False, "over": True}
    # 1.5 x the median exactly is not above it; a pool that hardly brakes flags nobody
    assert not overbraking_flags({"a": 2.0, "b": 2.0, "c": 3.0})["c"]
    # (the floor: one 0.2 s decision of hard braking, 3.4 m/s², per episode = 0.68 m/s)
    assert overbraking_flags({"a": 0.01, "b": 0.1, "c": 0.6}) == dict.fromkeys("abc", False)
    assert overbraking_flags({"a": 0.01, "b": 0.1, "c": 0.75})["c"]
    assert overbraking_flags({"a": 5.0, "b": math.nan}) == {"a": False, "b": False}


def test_the_mean_speed_rule_misses_what_the_new_one_catches() -> None:
    """Issue 33's case: the over-braker kept 86 % of the median speed (TIMID said nothing)."""
    from sumo_ayss.analysis.harm import vut_outcomes

    hazards = {
        v: {"unjustified_dv_mps": dv, "unjustified_braking": 0.5}
        for v, dv in (("pi1", 1.0), ("pi2", 2.8), ("over", 6.2))
    }
    out = vut_outcomes(
        {"pi1": (3, 100, 17.0), "pi2": (3, 100, 16.0), "over": (3, 100, 0.86 * 16.0)},
        hazards=hazards,
    )
    assert not out["over"].timid  # mean speed: 86 % of the median, above the 80 % floor
    assert out["over"].overbraking and not out["pi2"].overbraking
    assert out["over"].hazards == hazards["over"]
    assert not vut_outcomes({"a": (0, 10, 1.0), "b": (0, 10, 1.0)})["a"].overbraking


def test_vut_hazards_means_and_not_recorded() -> None:
    from sumo_ayss.analysis.hazards import VUT_HAZARD_COLUMNS, vut_hazards

    vut = np.array(["a", "a", "b", "b"])
    cols = {c: np.array([1.0, 0.0, np.nan, 3.0]) for c in VUT_HAZARD_COLUMNS}
    got = vut_hazards(vut, cols)
    assert got is not None
    assert got["a"]["rear_end"] == 0.5 and got["b"]["unjustified_dv_mps"] == 3.0
    nan = {c: np.full(4, np.nan) for c in VUT_HAZARD_COLUMNS}
    assert vut_hazards(vut, nan) is None  # a table written before the hazards


def test_a_caused_rear_end_is_a_crash_for_the_harm_score() -> None:
    from sumo_ayss.analysis.hazards import harm_crash

    collided = np.array([False, True, False, False])
    caused = np.array([1.0, 0.0, 0.0, np.nan])
    assert harm_crash(collided, caused).tolist() == [True, True, False, False]
    assert harm_crash(collided, None).tolist() == collided.tolist()


def test_leaderboard_cells() -> None:
    from sumo_ayss.analysis.harm import VutOutcome
    from sumo_ayss.report.sections.common import hazards_cell, unjustified_cell

    h = {
        "unjustified_braking": 0.9,
        "unjustified_dv_mps": 6.16,
        "rear_end": 0.02,
        "rear_end_unjustified": 0.01,
        "follower_max_braking_mps2": 4.58,
        "follower_max_drac_mps2": 0.6,
    }
    o = VutOutcome(1, 100, 0.0, 0.1, 14.6, False, h, True)
    assert unjustified_cell(o) == "90 % of episodes, 6.2 m/s shed (OVER-BRAKING)"
    assert hazards_cell(o) == "rear-ends 2.0 % (caused 1.0 %), follower braking 4.6 m/s²"
    old = VutOutcome(1, 100, 0.0, 0.1, 14.6, False)
    assert unjustified_cell(old) == "—" and hazards_cell(old) == "—"
