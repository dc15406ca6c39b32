"""CarFollowing-v0 with real SUMO: the behaviour a user relies on."""

from __future__ import annotations

import math
import warnings

import gymnasium as gym
import numpy as np
import pytest

import sumo_ayss  # noqa: F401  (registers the env ids)
from sumo_ayss.config import EnvConfig, OddConfig
from sumo_ayss.envs.car_following import N_ACTIONS, CarFollowingEnv, target_speed_mps
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.util.errors import ActionError

pytestmark = pytest.mark.sumo

#: Placement tolerance: moveTo/setPreviousSpeed are exact up to float rounding.
TOL = 1e-6
HOLD = 2  # action index that keeps the POV's speed (target = 0.5·2·v_pov)
STOP = 0  # action index that asks the POV to stop


def run(env: CarFollowingEnv, ic: InitialCondition, action: int, steps: int = 25) -> list:
    env.reset(options={"initial_condition": ic})
    out = []
    for _ in range(steps):
        obs, r, term, trunc, info = env.step(action)
        out.append((obs, r, term, trunc, info))
        if term or trunc:
            break
    return out


def test_registered_and_checkers_pass() -> None:
    from gymnasium.utils.env_checker import check_env as gym_check
    from stable_baselines3.common.env_checker import check_env as sb3_check

    env = gym.make("sumo_ayss/CarFollowing-v0")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # any checker warning fails the test
            gym_check(env.unwrapped, skip_render_check=True)
            sb3_check(env.unwrapped, warn=True)
    finally:
        env.close()


def test_reset_reproduces_sampled_initial_condition(cf_env: CarFollowingEnv) -> None:
    odd = cf_env.config.odd
    for seed in range(150):
        obs, info = cf_env.reset(seed=seed)
        ic = info["initial_condition"]
        assert odd.pov_speed_mps[0] <= ic.pov_speed_mps <= odd.pov_speed_mps[1]
        assert odd.gap_m[0] <= ic.gap_m <= odd.gap_m[1]
        np.testing.assert_allclose(obs, ic.as_tuple(), atol=1e-4)  # float32 observation
        assert info["headway_m"] == pytest.approx(ic.gap_m, abs=TOL)


@pytest.mark.parametrize("v_pov", [0.0, 15.0, 30.0, 40.0])
@pytest.mark.parametrize("v_vut", [0.0, 15.0, 30.0, 40.0])
@pytest.mark.parametrize("gap", [0.5, 1.0, 20.0, 60.0])
def test_reset_exact_across_odd_corners(cf_env, v_pov, v_vut, gap) -> None:
    ic = InitialCondition(v_pov, v_vut, gap)
    cf_env.reset(options={"initial_condition": ic})
    k = cf_env._kinematics()
    assert k.pov_speed_mps == pytest.approx(v_pov, abs=TOL)
    assert k.vut_speed_mps == pytest.approx(v_vut, abs=TOL)
    assert k.headway_m == pytest.approx(gap, abs=TOL)


def test_pov_braking_ahead_of_fast_vut_collides_and_terminates(cf_env) -> None:
    steps = run(cf_env, InitialCondition(20.0, 30.0, 2.0), STOP)
    _, r, term, trunc, info = steps[-1]
    assert term and not trunc
    assert info["collision"] is True
    assert r == cf_env.config.reward.min_reward
    assert all(not s[4]["collision"] for s in steps[:-1])
    assert len(steps) < 25


def test_far_pov_never_collides_and_episode_truncates_after_5_s(cf_env) -> None:
    steps = run(cf_env, InitialCondition(25.0, 25.0, 60.0), HOLD)
    assert len(steps) == 25  # 5 s at 5 Hz
    assert steps[-1][3] and not steps[-1][2]
    assert not any(s[4]["collision"] for s in steps)
    assert all(s[1] == 0.0 for s in steps)  # h > 20 m: no adversarial reward


def idm_accel(v, v_lead, gap, s0, a=3.0, b=5.0, t=1.5, delta=4.0, v0=30.0):
    s_star = s0 + max(0.0, v * t + v * (v - v_lead) / (2 * math.sqrt(a * b)))
    return a * (1 - (v / v0) ** delta - (s_star / gap) ** 2)


@pytest.mark.parametrize("vut", ["pi1", "pi2"])
@pytest.mark.parametrize(
    ("v_pov", "v_vut", "gap"), [(20.0, 20.0, 40.0), (25.0, 15.0, 30.0), (10.0, 5.0, 60.0)]
)
def test_vut_first_step_matches_idm_formula(vut, v_pov, v_vut, gap) -> None:
    """SUMO's IDM (one internal iteration at 0.2 s) against the textbook formula.

    Tolerance 0.05 m/s²: SUMO evaluates the same formula; the residual is the speed
    quantisation of its Euler update. Cases are chosen inside [-decel, accel] so that
    SUMO's clipping at emergencyDecel does not apply.
    """
    env = CarFollowingEnv(vut=vut)
    try:
        env.reset(options={"initial_condition": InitialCondition(v_pov, v_vut, gap)})
        _, _, _, _, info = env.step(HOLD)
    finally:
        env.close()
    s0 = env.config.vut_type.params["minGap"]
    expected = idm_accel(v_vut, v_pov, gap, s0)
    assert -5.0 < expected < 3.0
    assert info["vut_accel_mps2"] == pytest.approx(expected, abs=0.05)


def rollout(env: CarFollowingEnv, seed: int, n: int = 60) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(123)
    obs_seq, rew_seq = [], []
    obs, _ = env.reset(seed=seed)
    env.action_space.seed(seed)
    for _ in range(n):
        obs, r, term, trunc, _ = env.step(int(rng.integers(N_ACTIONS)))
        obs_seq.append(obs)
        rew_seq.append(r)
        if term or trunc:
            obs, _ = env.reset()
    return np.array(obs_seq), np.array(rew_seq)


def test_same_seed_bit_identical_different_seed_differs() -> None:
    results = []
    for seed in (7, 7, 8):
        env = CarFollowingEnv(sumo_seed=1)
        try:
            results.append(rollout(env, seed))
        finally:
            env.close()
    (o1, r1), (o2, r2), (o3, _) = results
    assert np.array_equal(o1, o2) and np.array_equal(r1, r2)
    assert not np.array_equal(o1, o3)


def final_gap_behind_stopping_pov(vut: str) -> float:
    env = CarFollowingEnv(vut=vut, config=EnvConfig(episode_s=15.0))
    try:
        steps = run(env, InitialCondition(20.0, 20.0, 40.0), STOP, steps=75)
    finally:
        env.close()
    obs, *_ = steps[-1]
    assert obs[0] == pytest.approx(0.0, abs=1e-6) and obs[1] == pytest.approx(
        0.0, abs=0.05
    )  # both at rest
    return float(obs[2])


def test_pi1_rests_closer_than_pi2_behind_a_stopped_pov() -> None:
    gap1 = final_gap_behind_stopping_pov("pi1")
    gap2 = final_gap_behind_stopping_pov("pi2")
    # At rest IDM sits at (or, after braking at its emergencyDecel limit, just below) s0.
    assert 3.0 < gap1 <= 5.0 + 1e-3  # pi1: SUMO minGap 5 m
    assert 10.0 < gap2 <= 15.0 + 1e-3  # pi2: SUMO minGap 15 m
    assert gap2 - gap1 > 5.0


def test_action_outside_space_is_a_clear_error(cf_env) -> None:
    cf_env.reset(seed=0)
    for bad in (-1, N_ACTIONS, 2.5, "x"):
        with pytest.raises(ActionError, match=r"action must be an integer"):
            cf_env.step(bad)


def test_step_before_reset_is_a_clear_error(cf_env) -> None:
    with pytest.raises(ActionError, match="before reset"):
        cf_env.step(0)


def test_target_speed_and_actuator_bounds(cf_env) -> None:
    assert target_speed_mps(0, 20.0) == 0.0
    assert target_speed_mps(2, 20.0) == 20.0
    assert target_speed_mps(20, 3.0) == 30.0
    cf_env.reset(options={"initial_condition": InitialCondition(25.0, 10.0, 60.0)})
    _, _, _, _, info = cf_env.step(STOP)
    assert info["pov_accel_mps2"] == -6.0  # bounded, not the 125 m/s² SUMO would allow
    obs, *_ = cf_env.step(20)
    assert obs[0] == pytest.approx(25.0 - 1.2 + 1.2, abs=1e-4)  # +6 m/s² for 0.2 s


def test_info_carries_the_documented_keys(cf_env) -> None:
    _, info0 = cf_env.reset(seed=3)
    assert {"headway_m", "ttc_s", "sumo_seed", "initial_condition"} <= set(info0)
    _, _, _, _, info = cf_env.step(HOLD)
    assert {
        "headway_m",
        "ttc_s",
        "pov_accel_mps2",
        "vut_accel_mps2",
        "collision",
        "reward_adversarial",
        "reward_collision",
        "sumo_seed",
    } <= set(info)


def test_narrow_odd_is_respected() -> None:
    odd = OddConfig(pov_speed_mps=(12.0, 12.0), vut_speed_mps=(3.0, 4.0), gap_m=(7.0, 8.0))
    env = CarFollowingEnv(config=EnvConfig(odd=odd))
    try:
        for seed in range(20):
            obs, _ = env.reset(seed=seed)
            assert obs[0] == pytest.approx(12.0)
            assert 3.0 <= obs[1] <= 4.0 and 7.0 <= obs[2] <= 8.0
    finally:
        env.close()
