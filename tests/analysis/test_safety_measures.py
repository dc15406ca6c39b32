"""Surrogate safety measures on hand-computed trajectories (sumo_ayss.analysis.safety_measures).

Every expected value below is worked out by hand in the comment beside it.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from sumo_ayss.analysis.r157 import must_avoid, must_avoid_column, r157_share, required_ttc_s
from sumo_ayss.analysis.safety_measures import (
    MEASURE_NAMES,
    PairTrajectory,
    crossing_time,
    episode_measures,
    intrusion,
    ttc_2d,
)
from sumo_ayss.util.errors import ConfigError


def traj(**kw: object) -> PairTrajectory:
    n = len(kw["time_s"])  # type: ignore[arg-type]
    base: dict[str, object] = {
        "vut_y_m": np.zeros(n),
        "pov_y_m": np.zeros(n),
        "vut_lat_speed_mps": np.zeros(n),
        "pov_lat_speed_mps": np.zeros(n),
        "collided": False,
        "vut_length_m": 5.0,
        "pov_length_m": 5.0,
        "vut_width_m": 1.8,
        "pov_width_m": 2.0,
    }
    base.update(kw)
    return PairTrajectory(**base)  # type: ignore[arg-type]


def car_following() -> PairTrajectory:
    # gaps POV rear - VUT front: 20-5-0 = 15, 23-5-4 = 14, 25.6-5-7.8 = 12.8 m
    return traj(
        time_s=[0.0, 0.2, 0.4],
        vut_x_m=[0.0, 4.0, 7.8],
        pov_x_m=[20.0, 23.0, 25.6],
        vut_speed_mps=[20.0, 20.0, 18.0],
        pov_speed_mps=[15.0, 15.0, 13.0],
    )


def test_car_following_measures() -> None:
    m = episode_measures(car_following())
    # closing speed 5 m/s throughout: TTC 15/5, 14/5, 12.8/5 = 3.0, 2.8, 2.56 s
    assert m.min_ttc_s == pytest.approx(2.56)
    # same lane, no lateral motion: the 2-D TTC is the 1-D one
    assert m.min_ttc_2d_s == pytest.approx(2.56)
    # THW 15/20, 14/20, 12.8/18 = 0.75, 0.70, 0.711 s
    assert m.min_thw_s == pytest.approx(0.7)
    # DRAC 5²/(2·15), 5²/(2·14), 5²/(2·12.8) = 0.833, 0.893, 0.977 m/s²
    assert m.max_drac_mps2 == pytest.approx(25 / 25.6)
    # decision accelerations 0 and -10 m/s²: braking 10, jerk (-10 - 0)/0.2 = -50
    assert m.vut_max_braking_mps2 == pytest.approx(10.0)
    assert m.vut_max_jerk_mps3 == pytest.approx(50.0)
    for name in ("intrusion_ttc_s", "intrusion_gap_m", "pet_s", "impact_speed_mps"):
        assert math.isnan(getattr(m, name)), name
    assert math.isnan(m.r157_must_avoid)
    assert list(m.as_row()) == list(MEASURE_NAMES)


def test_rear_end_crash() -> None:
    # gap 8-5-0 = 3 m, then 8.5-5-5 = -1.5 m (overlap): a crash at 22.5 m/s closing
    m = episode_measures(
        traj(
            time_s=[0.0, 0.2],
            vut_x_m=[0.0, 5.0],
            pov_x_m=[8.0, 8.5],
            vut_speed_mps=[25.0, 25.0],
            pov_speed_mps=[2.5, 2.5],
            collided=True,
        )
    )
    assert m.impact_speed_mps == pytest.approx(22.5)
    assert m.min_ttc_s == 0.0 and m.min_ttc_2d_s == 0.0 and m.min_thw_s == 0.0
    assert m.max_drac_mps2 == pytest.approx(22.5**2 / 6.0)  # only the sample with gap 3 m
    assert m.vut_max_braking_mps2 == 0.0
    assert math.isnan(m.vut_max_jerk_mps3)  # one decision: no jerk


def test_no_interaction_gives_the_neutral_values() -> None:
    # the POV pulls away: never closing, TTC +inf, DRAC 0
    m = episode_measures(
        traj(
            time_s=[0.0, 0.2],
            vut_x_m=[0.0, 2.0],
            pov_x_m=[30.0, 34.0],
            vut_speed_mps=[10.0, 10.0],
            pov_speed_mps=[20.0, 20.0],
        )
    )
    assert m.min_ttc_s == math.inf and m.min_ttc_2d_s == math.inf
    assert m.max_drac_mps2 == 0.0
    assert m.min_thw_s == pytest.approx(2.5)  # (30-5-0)/10, (34-5-2)/10 = 2.5, 2.7


def cut_in(pov_x0: float = 20.0) -> PairTrajectory:
    # VUT centred in lane 0 (y = -4.8, 3.2 m wide: left edge -3.2) at 20 m/s; POV (2 m wide)
    # from lane 1's centre (y = -1.6) moving right at 3.2 m/s from t = 0, at 10 m/s.
    t = np.arange(6) * 0.2
    return traj(
        time_s=t,
        vut_x_m=20.0 * t,
        pov_x_m=pov_x0 + 10.0 * t,
        vut_y_m=np.full(6, -4.8),
        pov_y_m=-1.6 - 3.2 * t,
        vut_speed_mps=np.full(6, 20.0),
        pov_speed_mps=np.full(6, 10.0),
        pov_lat_speed_mps=[0.0, -3.2, -3.2, -3.2, -3.2, -3.2],
        vut_lane_edge_y_m=-3.2,
    )


def test_cut_in_measures() -> None:
    tr = cut_in()
    m = episode_measures(tr)
    # near side -1.6 - 1 - 3.2 t reaches the edge -3.2 at t = 0.6/3.2 = 0.1875 s;
    # gap then 15 - 10·0.1875 = 13.125 m, closing 10 m/s: TTC 1.3125 s
    assert intrusion(tr).time_s == pytest.approx(0.1875)
    assert m.intrusion_gap_m == pytest.approx(13.125)
    assert m.intrusion_ttc_s == pytest.approx(1.3125)
    # PET: the POV's rear at entry x_c = 20 + 1.875 - 5 = 16.875 m; the VUT's front gets
    # there at 16.875 / 20 = 0.84375 s: PET = 0.84375 - 0.1875 = 0.65625 s
    assert m.pet_s == pytest.approx(0.65625)
    # in one path once |Δy| = 3.2 - 3.2 t < 1.9, i.e. samples t = 0.6, 0.8, 1.0 with gaps
    # 9, 7, 5 m at closing 10 m/s: 1-D TTC min 0.5 s, THW min 5/20 = 0.25 s, DRAC 100/10
    assert m.min_ttc_s == pytest.approx(0.5)
    assert m.min_thw_s == pytest.approx(0.25)
    assert m.max_drac_mps2 == pytest.approx(10.0)
    assert m.min_ttc_2d_s == pytest.approx(0.5)
    # R157: 0.3 m inside at t = 0.2 + 0.2·(0.3 - 0.04)/0.64 = 0.28125 s; gap 12.1875 m,
    # TTC 1.21875 s > 10/12 + 0.35 = 1.1833 s: must be avoided
    assert m.r157_ttc_lane_intrusion_s == pytest.approx(1.21875)
    assert m.r157_must_avoid == 1.0
    assert m.vut_max_braking_mps2 == 0.0 and m.vut_max_jerk_mps3 == 0.0


def test_cut_in_beside_the_vut() -> None:
    # POV rear 1 m behind the VUT's front at the start: intrusion gap -1 + 10·(-0.1875)...
    m = episode_measures(cut_in(pov_x0=4.0))
    # gap(t) = 4 - 5 + (10 - 20) t = -1 - 10 t: at 0.1875 s, -2.875 m: beside, TTC 0
    assert m.intrusion_gap_m == pytest.approx(-2.875)
    assert m.intrusion_ttc_s == 0.0
    assert math.isnan(m.pet_s)  # no encroachment ahead of the VUT


def test_pet_is_nan_when_the_vut_does_not_arrive() -> None:
    tr = cut_in()
    short = traj(
        **{
            name: getattr(tr, name)[:4]
            for name in (
                "time_s",
                "vut_x_m",
                "pov_x_m",
                "vut_y_m",
                "pov_y_m",
                "vut_speed_mps",
                "pov_speed_mps",
                "pov_lat_speed_mps",
            )
        },
        vut_lane_edge_y_m=-3.2,
    )
    # the VUT's front reaches 16.875 m at 0.84 s, after the last sample (0.6 s)
    assert math.isnan(episode_measures(short).pet_s)


def test_ttc_2d_sees_a_collision_course_across_lanes() -> None:
    # centres 18 m apart along, 2.56 m across; POV 10 m/s slower, moving in at 3.2 m/s;
    # x overlap for t in [1.3, 2.3], y overlap for t in [0.20625, 1.39375]: first 1.3 s
    assert float(ttc_2d(18.0, 2.56, -10.0, -3.2, 5.0, 1.9)) == pytest.approx(1.3)
    # moving away laterally: the y overlap lies in the past, never a contact
    assert float(ttc_2d(18.0, 2.56, -10.0, 3.2, 5.0, 1.9)) == math.inf
    # overlapping now
    assert float(ttc_2d(1.0, 0.5, 0.0, 0.0, 5.0, 1.9)) == 0.0
    # y exit (0.59 s) before x entry (1.3 s): the POV crosses ahead of the VUT's path
    assert float(ttc_2d(18.0, 0.0, -10.0, -3.2, 5.0, 1.9)) == math.inf


def test_crossing_time() -> None:
    assert crossing_time([0.0, 1.0, 2.0], [0.0, 1.0, 3.0], 2.0) == (1.5, 2)
    assert crossing_time([0.0, 1.0], [5.0, 6.0], 2.0) == (0.0, 0)
    t, k = crossing_time([0.0, 1.0], [0.0, 1.0], 2.0)
    assert math.isnan(t) and k == -1


def test_r157_condition() -> None:
    assert required_ttc_s(12.0) == pytest.approx(1.35)  # 12/12 + 0.35
    assert must_avoid(1.4, 12.0) == 1.0
    assert must_avoid(1.35, 12.0) == 0.0  # at the bound: not required
    assert must_avoid(5.0, -1.0) == 0.0  # the POV is faster: not closing in
    assert math.isnan(must_avoid(math.nan, 3.0))
    share = r157_share([1.0, 1.0, 0.0, math.nan, 1.0], [False, True, True, False, False])
    assert (share.n_required, share.n_handled) == (3, 2)
    assert share.share == pytest.approx(2 / 3)
    assert math.isnan(r157_share([0.0], [False]).share)


def test_r157_constant_is_a_parameter_and_old_tables_keep_their_reading() -> None:
    # 12 m/s closing: 1.35 s with c = 0.35, 1.45 s with the implementations' 0.45.
    assert required_ttc_s(12.0, 0.45) == pytest.approx(1.45)
    assert must_avoid(1.4, 12.0, 0.35) == 1.0 and must_avoid(1.4, 12.0, 0.45) == 0.0
    ttc = [1.4, 1.4, math.nan]
    closing = [12.0, math.nan, math.nan]  # the 2nd from a table before r157_closing_mps
    stored = [1.0, 1.0, math.nan]
    assert must_avoid_column(ttc, closing, stored, 0.45).tolist()[0] == 0.0
    assert math.isnan(must_avoid_column(ttc, closing, stored, 0.45)[1])  # not known
    assert must_avoid_column(ttc, closing, stored, 0.35)[1] == 1.0  # the stored 0.35 reading
    assert math.isnan(must_avoid_column(ttc, closing, stored, 0.35)[2])


def test_bad_trajectories_are_refused() -> None:
    with pytest.raises(ConfigError, match="increasing"):
        traj(
            time_s=[0.0, 0.0],
            vut_x_m=[0, 1],
            pov_x_m=[9, 9],
            vut_speed_mps=[1, 1],
            pov_speed_mps=[1, 1],
        )
    with pytest.raises(ConfigError, match="pov_x_m"):
        traj(
            time_s=[0.0, 0.2],
            vut_x_m=[0, 1],
            pov_x_m=[9],
            vut_speed_mps=[1, 1],
            pov_speed_mps=[1, 1],
        )
    with pytest.raises(ConfigError, match="vut_length_m"):
        traj(
            time_s=[0.0],
            vut_x_m=[0],
            pov_x_m=[9],
            vut_speed_mps=[1],
            pov_speed_mps=[1],
            vut_length_m=0.0,
        )
