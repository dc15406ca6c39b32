"""The reference drivers on hand-computed trajectories, and FSM against JRC-FSM's numbers."""

from __future__ import annotations

import math

import pytest

from sumo_ayss.sim.pair import SensedObject
from sumo_ayss.util.errors import ConfigError
from sumo_ayss.vuts.controllers import ControllerInput, bound_acceleration, commanded_speed
from sumo_ayss.vuts.reference import (
    G_MPS2,
    CarefulDriver,
    FuzzySafetyDriver,
    RssDriver,
    braking_distance_m,
    rss_lateral_safe_distance_m,
    rss_safe_distance_m,
)
from sumo_ayss.vuts.reference_types import REFERENCE_VUTS

DT = 0.2
LANE_W = 3.2
A_CC = 0.774 * G_MPS2


def _drive(driver, lead, v0: float, gap0: float, steps: int, lateral=None, max_decel=9.0):
    """Integrate the driver as the testbed does (mean acceleration per step, v' = v + a·dt)
    against a leader given as ``lead(t) -> (speed, position)``; returns the own speeds at
    the step boundaries and the commands. ``lateral(t) -> (offset, lateral speed)``."""
    x, v = 0.0, v0
    lead_x0 = gap0
    speeds, cmds = [v], []
    driver.reset()
    for k in range(steps):
        t = k * DT
        v_l, x_l = lead(t)
        offset, v_lat = lateral(t) if lateral else (0.0, 0.0)
        gap = lead_x0 + x_l - x
        obj = SensedObject(gap, offset, v_l - v, v_lat, 5.0, 1.8)
        in_lane = abs(offset) < 0.5 * LANE_W + 0.9
        state = ControllerInput(
            t, DT, v, gap if in_lane else math.inf, (v_l - v) if in_lane else 0.0, 0, (obj,), LANE_W
        )
        a = bound_acceleration(driver.acceleration(state), 3.0, max_decel)
        v_next, _ = commanded_speed(v, a, DT, 40.0)
        x += v_next * DT
        v = v_next
        speeds.append(v)
        cmds.append(a)
    return speeds, cmds


def _stationary(t: float) -> tuple[float, float]:
    return 0.0, 0.0


def _profile_speed(v0: float, t: float, react_from: float, reaction: float, peak: float,
                   ramp: float) -> float:  # fmt: skip
    """Closed form: speed at t of a constant v0 until react_from + reaction, then a linear
    ramp to ``peak`` over ``ramp`` s, then ``peak`` (no foot-off)."""
    t_b = react_from + reaction
    if t <= t_b:
        return v0
    jerk = peak / ramp
    if t <= t_b + ramp:
        return v0 - 0.5 * jerk * (t - t_b) ** 2
    return v0 - 0.5 * peak * ramp - peak * (t - t_b - ramp)


def test_cc_closing_in_reacts_after_075_s_and_ramps_in_06_s_exactly() -> None:
    # Stationary object 30 m ahead at 20 m/s: TTC 1.5 s <= 2 s perceives at t = 0;
    # 0.75 s reaction, a 0.6 s ramp to 0.774 g. Foot-off and AEB off: the pure profile.
    driver = CarefulDriver(release_decel_mps2=0.0, aeb=False)
    speeds, _ = _drive(driver, _stationary, 20.0, 30.0, 10)
    for k, v in enumerate(speeds):
        assert v == pytest.approx(_profile_speed(20.0, k * DT, 0.0, 0.75, A_CC, 0.6), abs=1e-9)
    # By hand at t = 1.0 s: 20 - 0.5 · (7.593/0.6) · 0.25² = 19.6045 m/s.
    assert speeds[5] == pytest.approx(20 - 0.5 * (A_CC / 0.6) * 0.0625, abs=1e-9)


def test_cc_foot_off_during_the_reaction() -> None:
    driver = CarefulDriver(aeb=False)  # release_decel 0.4 m/s² by default
    speeds, cmds = _drive(driver, _stationary, 20.0, 30.0, 3)
    assert cmds[0] == pytest.approx(-0.4) and cmds[1] == pytest.approx(-0.4)
    # Third step (0.4-0.6 s) still within the 0.75 s reaction.
    assert speeds[3] == pytest.approx(20.0 - 0.4 * 0.6)


def test_cc_aeb_arms_below_its_ttc_and_overrides_the_driver() -> None:
    # 20 m/s toward a stationary object 28 m ahead: TTC 1.4 s < 1.5 s arms the AEB at t = 0,
    # which ramps to 0.85 g in 0.6 s without reaction time: first step's mean is
    # 8.34 · (0.2 / 0.6) / 2 = 1.39 m/s² (the driver is still reacting, foot-off off).
    driver = CarefulDriver(release_decel_mps2=0.0)
    _, cmds = _drive(driver, _stationary, 20.0, 28.0, 4)
    a_aeb = 0.85 * G_MPS2
    assert cmds[0] == pytest.approx(-a_aeb * (0.2 / 0.6) / 2)
    assert cmds[3] == pytest.approx(-a_aeb)  # 0.6-0.8 s: full AEB
    # A larger TTC does not arm it.
    no_aeb = CarefulDriver(release_decel_mps2=0.0)
    _, cmds2 = _drive(no_aeb, _stationary, 20.0, 30.0, 1)
    assert cmds2[0] == 0.0


def test_cc_deceleration_case_perceives_04_s_then_reacts_075_s() -> None:
    # Leader at 20 m/s, 20 m ahead (THW 1 s), brakes at 6 m/s² from t = 0.4 s. The first
    # reading that shows it is t = 0.6 s; perception runs from 0.4 s to 0.8 s, then the
    # reaction to 1.55 s, then the ramp. TTC stays above 2 s until then.
    def lead(t: float) -> tuple[float, float]:
        if t <= 0.4:
            return 20.0, 20.0 * t
        tb = t - 0.4
        return 20.0 - 6.0 * tb, 20.0 * t - 3.0 * tb * tb

    driver = CarefulDriver(release_decel_mps2=0.0, aeb=False, decel_perception="threshold")
    speeds, _ = _drive(driver, lead, 20.0, 20.0, 12)
    assert driver.braking_from_s == pytest.approx(1.55)
    for k, v in enumerate(speeds):
        assert v == pytest.approx(_profile_speed(20.0, k * DT, 0.8, 0.75, A_CC, 0.6), abs=1e-9)
    # The default reacts from the brake lights' onset (0.4 s), without the 0.4 s perception.
    onset = CarefulDriver(release_decel_mps2=0.0, aeb=False)
    speeds, _ = _drive(onset, lead, 20.0, 20.0, 12)
    assert onset.braking_from_s == pytest.approx(0.4 + 0.75)
    for k, v in enumerate(speeds):
        assert v == pytest.approx(_profile_speed(20.0, k * DT, 0.4, 0.75, A_CC, 0.6), abs=1e-9)


def test_cc_mild_braking_below_the_trigger_is_caught_by_the_ttc_boundary() -> None:
    # 3 m/s² is below R157's 5 m/s² trigger; the JAMA TTC <= 2 s boundary perceives it.
    def lead(t: float) -> tuple[float, float]:
        return 20.0 - 3.0 * t, 20.0 * t - 1.5 * t * t

    # Brake lights ignored (threshold mode): TTC at the 1.2 s reading is 7.84 / 3.6 = 2.18 s,
    # at 1.4 s 7.06 / 4.2 = 1.68 s <= 2: the reaction starts there.
    driver = CarefulDriver(aeb=False, decel_perception="threshold")
    _drive(driver, lead, 20.0, 10.0, 8)
    assert driver.braking_from_s == pytest.approx(1.4 + 0.75)


def test_cc_cut_in_distance_mode_times_the_perception_by_lateral_motion() -> None:
    # An object 12 m ahead in the next lane (offset 3.2 m), 5 m/s slower, moves toward the
    # lane at 3.2 m/s from t = 0. Wandering 0.375 m is passed at 0.1172 s, the further
    # 0.72 m at (0.375 + 0.72) / 3.2 = 0.3422 s, seen at the 0.4 s reading, where the gap has
    # closed to 12 - 5 · 0.4 = 10 m: TTC 2.0 s, not < 2 (the cut-in gate fails), but the
    # closing-in boundary (TTC <= 2 s) reacts at that reading.
    def lead(t: float) -> tuple[float, float]:
        return 15.0, 15.0 * t

    def lateral(t: float) -> tuple[float, float]:
        return max(3.2 - 3.2 * t, 0.0), (-3.2 if t < 1.0 else 0.0)

    driver = CarefulDriver(release_decel_mps2=0.0, aeb=False)
    _drive(driver, lead, 20.0, 12.0, 3, lateral)
    assert driver.braking_from_s == pytest.approx(0.4 + 0.75)
    # Farther away (gap 8 m: TTC 1.2 s at 0.4 s) the cut-in gate holds: the reaction starts
    # at the interpolated end of perception, 0.3422 s.
    close = CarefulDriver(release_decel_mps2=0.0, aeb=False)
    _drive(close, lead, 20.0, 8.0 + 5.0 * 0.4, 3, lateral)
    assert close.braking_from_s == pytest.approx((0.375 + 0.72) / 3.2 + 0.75)
    # Time mode: 0.4 s after the wandering threshold (0.517 s), gap 12.5 m: TTC 2.1 s at the
    # 0.4 s reading (not closing in enough), 1.9 s at 0.6 s: the gate holds.
    timed = CarefulDriver(release_decel_mps2=0.0, aeb=False, perception="time")
    _drive(timed, lead, 20.0, 12.5, 4, lateral)
    assert timed.braking_from_s == pytest.approx(0.375 / 3.2 + 0.4 + 0.75)


def test_cc_holds_speed_without_a_threat_and_releases_when_it_is_over() -> None:
    def lead(t: float) -> tuple[float, float]:
        return 25.0, 25.0 * t

    speeds, cmds = _drive(CarefulDriver(), lead, 20.0, 30.0, 10)
    assert set(cmds) == {0.0} and speeds[-1] == 20.0


def test_cc_rejects_bad_parameters() -> None:
    with pytest.raises(ConfigError, match="perception must be one of"):
        CarefulDriver(perception="sometimes")
    with pytest.raises(ConfigError, match="reaction_s"):
        CarefulDriver(reaction_s=-1.0)


def test_braking_distance_matches_the_research_notes_table() -> None:
    # ../shared/research/reference-drivers.md §1.1: 30 km/h -> 13.2 m, 100 km/h -> 79.9 m
    # (T = 0.75 s); 60 km/h, T = 1.15 s -> 42.3 m.
    assert braking_distance_m(30 / 3.6, 0.75) == pytest.approx(13.2, abs=0.05)
    assert braking_distance_m(100 / 3.6, 0.75) == pytest.approx(79.9, abs=0.05)
    assert braking_distance_m(60 / 3.6, 1.15) == pytest.approx(42.3, abs=0.05)


# JRC-FSM's own PFS / CFS (ec-jrc/JRC-FSM, utility/fuzzy_functs.py at commit
# 01b05c29dc9a1a410d3f9de1ed3f1a6dfe978116, run here on these inputs with its defaults rt
# 0.75, br_min 4, br_max 6, bl 7, margins 2 + 2): (gap, u_r, u_l, a_r) -> (PFS, CFS).
JRC_FSM_GOLDEN = [
    ((20, 20, 20, 0), 1, 0),
    ((40, 20, 20, 0), 0.022959183673469497, 0),
    ((30, 25, 15, 0), 1, 0),
    ((15, 25, 15, -2), 1, 0.3217993079584774),
    ((10, 25, 10, -6), 1, 1),
    ((50, 30, 10, -1), 1, 0.7149603643110134),
    ((8, 12, 11, -5), 1, 0),
]


@pytest.mark.parametrize(("inputs", "pfs", "cfs"), JRC_FSM_GOLDEN)
def test_fsm_pfs_cfs_equal_jrc_fsm(inputs: tuple[float, ...], pfs: float, cfs: float) -> None:
    gap, u_r, u_l, a_r = inputs
    fsm = FuzzySafetyDriver()
    assert fsm.pfs(gap, u_r, u_l) == pytest.approx(pfs, abs=1e-12)
    assert fsm.cfs(gap, u_r, u_l, a_r) == pytest.approx(cfs, abs=1e-12)


def test_fsm_reacts_after_its_reaction_time_at_the_jerk_limit() -> None:
    driver = FuzzySafetyDriver()
    _, cmds = _drive(driver, _stationary, 20.0, 40.0, 8)
    # Unsafe from the first reading: nothing until 0.75 s; 0.6-0.8 s brakes for 0.05 s at
    # 12.65 m/s³ (the step's end deceleration is applied); then +2.53 m/s² per step.
    assert cmds[:3] == [0.0, 0.0, 0.0]
    assert cmds[3] == pytest.approx(-12.65 * 0.05)
    assert cmds[4] == pytest.approx(-(12.65 * 0.05 + 12.65 * 0.2))
    assert min(cmds) >= -A_CC - 1e-9


def test_rss_safe_distance_by_hand() -> None:
    # v_r = v_f = 20: 20·1 + 3.5/2 + 23.5²/8 - 20²/16 = 65.78125 m.
    assert rss_safe_distance_m(20.0, 20.0) == pytest.approx(65.78125)
    assert rss_safe_distance_m(0.0, 30.0) == 0.0
    # Lateral, standing still and an object at 1 m/s toward: 0.1 + (0.1 + 0.025) +
    # (1 + 0.1 + 1.2²/1.6) = 0.1 + 0.125 + 2.0 = 2.225 m.
    assert rss_lateral_safe_distance_m(1.0) == pytest.approx(0.1 + 0.125 + 1.0 + 0.1 + 0.9)


def test_rss_brakes_at_b_min_only_inside_the_safe_distance() -> None:
    driver = RssDriver()
    _, far = _drive(driver, lambda t: (20.0, 20.0 * t), 20.0, 70.0, 1)
    _, near = _drive(driver, lambda t: (20.0, 20.0 * t), 20.0, 60.0, 1)
    assert far == [0.0] and near == [-4.0]


def test_reference_catalog_entries_build_and_validate() -> None:
    assert sorted(REFERENCE_VUTS) == ["cc_driver", "fsm", "rss"]
    for name, vt in REFERENCE_VUTS.items():
        vt.validate(f"vuts.{name}")
        assert vt.controller is not None
        assert hasattr(vt.controller.build(name), "acceleration")
