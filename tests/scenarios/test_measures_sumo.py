"""The rollout records each episode's trajectory and its safety measures (real SUMO).

Known answers come from SUMO's lane-change physics (DESIGN.md, "SUMO facts"): a forced
change with ``--lanechange.duration 1.0`` moves the POV sideways at 3.2 m/s from the first
step on. The POV (w = 1.8 m wide, SUMO's default) starts centred in the left lane (3.2 m
wide), its near side 1.6 - w/2 = 0.7 m from the VUT's lane: its body enters that lane
0.7 / 3.2 = 0.21875 s after the change starts.
"""

from __future__ import annotations

import math

import libsumo
import numpy as np
import pytest

from sumo_ayss.analysis.safety_measures import episode_measures, intrusion
from sumo_ayss.config import EnvConfig
from sumo_ayss.envs import make_env
from sumo_ayss.envs.cut_in import LANE_CHANGE
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.scenarios.rollout import run_episode
from sumo_ayss.scenarios.trajectory import body_width_m, trajectory_from_infos

pytestmark = pytest.mark.sumo


def _cut_in_then_hold(speed_mps: int):
    """Cut in at the first decision, then target ``speed_mps``."""
    calls = {"n": 0}

    def policy(obs: np.ndarray) -> np.ndarray:
        calls["n"] += 1
        return np.array([LANE_CHANGE if calls["n"] == 1 else 1 + speed_mps])

    return policy


def test_a_cut_in_enters_the_lane_when_the_physics_says() -> None:
    env = make_env(EnvConfig(case="cut_in"), sumo_seed=1)
    base = env.unwrapped
    ic = InitialCondition(pov_speed_mps=20.0, vut_speed_mps=20.0, gap_m=10.0)
    try:
        result = run_episode(env, _cut_in_then_hold(20), ic)
        _, reset_info = base.reset(options={"initial_condition": ic})
        policy, infos, done = _cut_in_then_hold(20), [], False
        obs = None
        while not done:
            action = int(policy(obs)[0])
            obs, _, terminated, truncated, info = base.step(action)
            infos.append(info)
            done = terminated or truncated
    finally:
        env.close()
    tr = trajectory_from_infos(base.config, reset_info, infos)
    entry = intrusion(tr)
    near_side_to_edge_m = 1.6 - 0.5 * body_width_m(base.config.pov)
    assert entry.time_s == pytest.approx(near_side_to_edge_m / 3.2, abs=1e-6)
    assert tr.pov_ahead_gap_m()[1] <= entry.gap_m <= tr.pov_ahead_gap_m()[0]
    # the rollout's measures are those of this recording (same SUMO seed, same actions)
    assert result.measures == episode_measures(tr)
    assert not result.collided and result.lane_changed
    assert result.measures.intrusion_gap_m == pytest.approx(entry.gap_m)
    assert math.isnan(result.measures.impact_speed_mps)  # no collision


def test_a_side_swipe_hits_with_the_lateral_speed() -> None:
    """Side by side, the cut-in hits the VUT: the relative speed at impact holds the
    change's lateral 3.2 m/s besides the longitudinal difference SUMO reports then."""
    env = make_env(EnvConfig(case="cut_in"), sumo_seed=1)
    try:
        ic = InitialCondition(pov_speed_mps=20.0, vut_speed_mps=20.0, gap_m=-2.5)
        result = run_episode(env, _cut_in_then_hold(20), ic)
        last = env.unwrapped._pair.longitudinal()  # SUMO's speeds at impact
    finally:
        env.close()
    m = result.measures
    assert m is not None and result.collided
    dv_long = last[3] - last[1]  # v_vut - v_pov
    assert m.impact_speed_mps == pytest.approx(math.hypot(dv_long, 3.2), abs=1e-6)
    assert m.min_ttc_2d_s == 0.0
    assert m.intrusion_gap_m < 0.0 and m.intrusion_ttc_s == 0.0  # entered beside the VUT
    assert math.isnan(m.pet_s)


def test_the_recorded_trajectory_matches_sumo() -> None:
    """Gaps of the trajectory equal the env's headway; the body widths equal SUMO's."""
    env = make_env(EnvConfig(case="car_following"), sumo_seed=2)
    base = env.unwrapped
    try:
        ic = InitialCondition(pov_speed_mps=15.0, vut_speed_mps=25.0, gap_m=20.0)
        _, reset_info = base.reset(options={"initial_condition": ic})
        pair = base._pair  # the test reads SUMO's own widths
        assert libsumo.vehicle.getWidth(pair.vut) == body_width_m(base.config.vut_type)
        assert libsumo.vehicle.getWidth(pair.pov) == body_width_m(base.config.pov)
        infos = []
        for _ in range(5):
            *_, info = base.step(10)  # target = 1.0·v_pov
            infos.append(info)
        tr = trajectory_from_infos(base.config, reset_info, infos)
    finally:
        env.close()
    headway = [reset_info["headway_m"], *(i["headway_m"] for i in infos)]
    np.testing.assert_allclose(tr.pov_ahead_gap_m(), headway, atol=1e-9)
    np.testing.assert_allclose(tr.time_s, np.arange(6) * 0.2)
    assert tr.vut_speed_mps[0] == pytest.approx(25.0) and tr.pov_speed_mps[0] == pytest.approx(15.0)
