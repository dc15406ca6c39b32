"""CutInEnv against a real SUMO (libsumo): spaces, reset, lane change, VUT reaction, crashes.

libsumo holds one simulation per process, so every env here is closed before the next one
starts (the ``make_env`` fixture closes the previous env and, at teardown, the last one).

Tolerances: positions, gaps and speeds read back after reset equal the request to 1e-6 m
and 1e-6 m/s (float64 info; the float32 observation to float32 rounding, rtol 1e-6);
lateral speeds and positions during a lane change match lane width / duration to 1e-9.
"""

from __future__ import annotations

import itertools
import math
import warnings
from collections.abc import Callable, Iterator
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env as gym_check_env
from stable_baselines3.common.env_checker import check_env as sb3_check_env

from sumo_ayss.analysis.metrics import delta_v_bar
from sumo_ayss.config import EnvConfig, OddConfig, SimConfig
from sumo_ayss.envs.cut_in import (
    FIRST_SPEED_ACTION,
    LANE_CHANGE,
    N_ACTIONS,
    POV_LANE,
    VUT_LANE,
    CutInEnv,
    target_speed_mps,
)
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.envs.rewards import adversarial_reward
from sumo_ayss.sim.network import LANE_WIDTH_M, SPEED_LIMIT_MPS
from sumo_ayss.util.errors import ActionError

pytestmark = pytest.mark.sumo

ENV_ID = "sumo_ayss/CutIn-v0"

#: World y of the lane centre lines on the built-in two-lane road (lane 0 right, lane 1 left).
LANE0_Y_M = -1.5 * LANE_WIDTH_M
LANE1_Y_M = -0.5 * LANE_WIDTH_M
#: The line between the two lanes.
LANE_BOUNDARY_Y_M = -LANE_WIDTH_M
#: SUMO's default passenger-car width [m] (neither built-in vType sets a width).
CAR_WIDTH_M = 1.8
CAR_LENGTH_M = 5.0
DT_S = 0.2


def hold(speed_mps: float) -> int:
    """The speed action that asks for ``speed_mps`` (an integer)."""
    return FIRST_SPEED_ACTION + round(speed_mps)


@pytest.fixture
def make_env() -> Iterator[Callable[..., CutInEnv]]:
    """A factory of CutInEnvs that keeps at most one (one libsumo per process) open."""
    opened: list[CutInEnv] = []

    def factory(config: EnvConfig | None = None, sumo_seed: int = 7) -> CutInEnv:
        for old in opened:
            old.close()
        env = CutInEnv(config, sumo_seed=sumo_seed)
        opened.append(env)
        return env

    yield factory
    for env in opened:
        env.close()


@pytest.fixture
def env(make_env: Callable[..., CutInEnv]) -> CutInEnv:
    return make_env()


def run(
    env: CutInEnv, ic: InitialCondition, actions: list[int]
) -> tuple[list[np.ndarray], list[float], list[dict[str, Any]], bool]:
    """One episode from ``ic``: observations (reset included), rewards, infos, terminated."""
    obs, info = env.reset(seed=0, options={"initial_condition": ic})
    observations, rewards, infos = [obs], [], [info]
    terminated = False
    for a in actions:
        obs, reward, terminated, truncated, info = env.step(a)
        observations.append(obs)
        rewards.append(float(reward))
        infos.append(info)
        if terminated or truncated:
            break
    return observations, rewards, infos, terminated


def cfg(**sim: Any) -> EnvConfig:
    return EnvConfig(case="cut_in", sim=SimConfig(**sim))


# ---------------------------------------------------------------------------- spaces


def test_action_layout() -> None:
    assert N_ACTIONS == 42
    assert LANE_CHANGE == 0
    assert [target_speed_mps(a) for a in (1, 2, 41)] == [0.0, 1.0, 40.0]
    for bad in (LANE_CHANGE, N_ACTIONS):
        with pytest.raises(ActionError):
            target_speed_mps(bad)


def test_spaces(env: CutInEnv) -> None:
    assert env.action_space == gym.spaces.Discrete(42)
    space = env.observation_space
    assert isinstance(space, gym.spaces.Box)
    assert space.shape == (4,) and space.dtype == np.float32
    assert np.all(np.isfinite(space.low)) and np.all(np.isfinite(space.high))
    assert space.low[3] == 0.0 and space.high[3] == 1.0


def test_gymnasium_env_checker(env: CutInEnv) -> None:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        gym_check_env(env.unwrapped, skip_render_check=True)
    assert [str(w.message) for w in caught] == []


def test_sb3_env_checker(env: CutInEnv) -> None:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sb3_check_env(env, warn=True)
    assert [str(w.message) for w in caught] == []


def test_registration() -> None:
    if ENV_ID not in gym.registry:
        gym.register(id=ENV_ID, entry_point="sumo_ayss.envs.cut_in:CutInEnv")
    env = gym.make(ENV_ID, sumo_seed=1)
    try:
        assert isinstance(env.unwrapped, CutInEnv)
        obs, _ = env.reset(seed=3)
        assert env.observation_space.contains(obs)
    finally:
        env.close()


# ---------------------------------------------------------------------------- reset


def check_reset_state(obs: np.ndarray, info: dict[str, Any], ic: InitialCondition) -> None:
    assert info["pov_speed_mps"] == pytest.approx(ic.pov_speed_mps, abs=1e-6)
    assert info["vut_speed_mps"] == pytest.approx(ic.vut_speed_mps, abs=1e-6)
    assert info["headway_m"] == pytest.approx(ic.gap_m, abs=1e-6)
    assert (info["pov_lane"], info["vut_lane"]) == (POV_LANE, VUT_LANE)
    assert info["pov_y_m"] == pytest.approx(LANE1_Y_M, abs=1e-9)
    assert info["vut_y_m"] == pytest.approx(LANE0_Y_M, abs=1e-9)
    assert not info["same_lane"] and not info["lane_changing"]
    expected = np.array([ic.pov_speed_mps, ic.vut_speed_mps, ic.gap_m, 0.0], dtype=np.float32)
    np.testing.assert_allclose(obs, expected, rtol=1e-6, atol=1e-6)


def test_reset_reproduces_sampled_initial_condition(make_env: Callable[..., CutInEnv]) -> None:
    odd = OddConfig(pov_speed_mps=(0.0, 30.0), vut_speed_mps=(0.0, 30.0), gap_m=(0.0, 25.0))
    env = make_env(EnvConfig(case="cut_in", odd=odd))
    gaps = []
    for seed in range(60):
        obs, info = env.reset(seed=seed)
        ic = info["initial_condition"]
        check_reset_state(obs, info, ic)
        gaps.append(ic.gap_m)
        if seed % 3 == 0:  # a few steps in between, so resets start from a used simulation
            env.step(LANE_CHANGE)
            env.step(hold(0))
    assert min(gaps) < 3.0 and max(gaps) > 22.0  # the draws span the ODD


@pytest.mark.parametrize(
    "ic",
    [
        InitialCondition(0.0, 0.0, 0.0),
        InitialCondition(30.0, 30.0, 25.0),
        InitialCondition(40.0, 0.0, 0.5),
        InitialCondition(0.0, 30.0, 25.0),
        InitialCondition(20.0, 20.0, -4.0),  # side by side (given, not sampled)
        InitialCondition(25.0, 15.0, -12.0),  # POV entirely behind
    ],
)
def test_reset_reproduces_given_initial_condition(env: CutInEnv, ic: InitialCondition) -> None:
    obs, info = env.reset(seed=1, options={"initial_condition": ic})
    check_reset_state(obs, info, ic)


# ---------------------------------------------------------------------------- lane change


@pytest.mark.parametrize("duration_s", [1.0, 2.0])
def test_lane_change_moves_pov_into_vut_lane_within_duration(
    make_env: Callable[..., CutInEnv], duration_s: float
) -> None:
    env = make_env(cfg(lanechange_duration_s=duration_s))
    n_change = round(duration_s / DT_S)
    ic = InitialCondition(20.0, 20.0, 15.0)
    obs, rewards, infos, _ = run(env, ic, [hold(20), LANE_CHANGE] + [hold(20)] * n_change)
    lat_speed = -LANE_WIDTH_M / duration_s  # to the right
    ys = [i["pov_y_m"] for i in infos]
    change = infos[2 : 2 + n_change]  # the decisions during which the POV moves sideways
    assert infos[2]["lane_change_started"] and infos[2]["target_speed_mps"] == 20.0
    for k, info in enumerate(change, start=2):
        assert info["pov_lateral_speed_mps"] == pytest.approx(lat_speed, abs=1e-9)
        assert (ys[k] - ys[k - 1]) / DT_S == pytest.approx(lat_speed, abs=1e-9)
        assert info["lane_changing"] and info["reward_phase"] == "lane_change"
        assert rewards[k - 1] == pytest.approx(
            adversarial_reward(info["headway_m"], env.config.reward.lane_change)
        )
    # Centred in the VUT's lane after exactly the configured duration, then at rest sideways.
    assert ys[1 + n_change] == pytest.approx(LANE0_Y_M, abs=1e-9)
    after = infos[-1]  # one decision later
    assert after["pov_y_m"] == pytest.approx(LANE0_Y_M, abs=1e-9)
    assert after["pov_lateral_speed_mps"] == 0.0 and not after["lane_changing"]
    assert after["reward_phase"] == "same_lane"
    assert rewards[-1] == pytest.approx(
        adversarial_reward(after["headway_m"], env.config.reward.same_lane)
    )
    # same_lane (SUMO's lane of the POV's front centre) flips when the centre crosses the
    # lane boundary, and only then.
    for o, info in zip(obs, infos, strict=True):
        centre_in_vut_lane = info["pov_y_m"] <= LANE_BOUNDARY_Y_M + 1e-9  # at or past it
        assert o[3] == (1.0 if centre_in_vut_lane else 0.0)
        assert info["same_lane"] == centre_in_vut_lane
    # Reset, the first hold, and the change steps that end short of half-way.
    assert [o[3] for o in obs].count(0.0) == 1 + math.ceil(n_change / 2)


def test_vut_drives_freely_until_pov_reaches_its_lane(make_env: Callable[..., CutInEnv]) -> None:
    env = make_env()
    ic = InitialCondition(20.0, 20.0, 10.0)  # POV slower than the accelerating VUT
    n = 7
    _, _, free, _ = run(env, ic, [hold(20)] * n)
    _, _, cut, _ = run(env, ic, [hold(20), hold(20), LANE_CHANGE] + [hold(20)] * (n - 3))
    # Reference: SUMO's IDM on a free road, a = accel·(1 - (v / v0)^delta) with v0 = 30 m/s,
    # i.e. SUMO's "no overtaking on the right" rule does not slow the VUT beside the POV.
    vut = env.config.vut_type.params
    for before, after in itertools.pairwise(free):
        v = before["vut_speed_mps"]
        idm_free = vut["accel"] * (1.0 - (v / SPEED_LIMIT_MPS) ** vut["delta"])
        assert after["vut_accel_mps2"] == pytest.approx(idm_free, abs=1e-9)
    # With the cut-in: identical to free driving in every step that ends with the POV's body
    # outside the VUT's lane, braking hard in the first step that ends with it inside.
    first_inside = None
    for k in range(1, n + 1):
        inside = cut[k]["pov_y_m"] - CAR_WIDTH_M / 2 < LANE_BOUNDARY_Y_M
        if not inside:
            assert cut[k]["vut_accel_mps2"] == free[k]["vut_accel_mps2"]
        elif first_inside is None:
            first_inside = k
            assert cut[k]["vut_accel_mps2"] < free[k]["vut_accel_mps2"] - 3.0
    assert first_inside == 4  # 2nd step of the change: 1.28 m sideways, edge 0.58 m inside
    assert not cut[first_inside]["same_lane"]  # before the POV's lane index flips


def test_delta_v_bar_matches_metrics_and_is_negative_when_cutting_in(
    env: CutInEnv,
) -> None:
    _, _, infos, _ = run(env, InitialCondition(20.0, 20.0, 6.0), [LANE_CHANGE] + [hold(20)] * 5)
    for info in infos:
        # Centres: front minus half a length; x_pov_front = x_vut_front + h + L_pov.
        rel_pos = (-info["headway_m"] - CAR_LENGTH_M, info["vut_y_m"] - info["pov_y_m"])
        rel_vel = (
            info["vut_speed_mps"] - info["pov_speed_mps"],
            info["vut_lateral_speed_mps"] - info["pov_lateral_speed_mps"],
        )
        assert info["delta_v_bar_mps"] == pytest.approx(delta_v_bar(rel_pos, rel_vel), abs=1e-9)
    assert infos[1]["lane_changing"] and infos[1]["delta_v_bar_mps"] < -1.0  # closing in


# ---------------------------------------------------------------------------- collisions


def bodies_overlap(info: dict[str, Any]) -> bool:
    """Geometric overlap of the two bodies (rectangles along the road) from a step's info."""
    h = info["headway_m"]  # POV rear - VUT front; the bodies overlap along x for -10 < h < 0
    return -2 * CAR_LENGTH_M < h < 0.0 and abs(info["pov_y_m"] - info["vut_y_m"]) < CAR_WIDTH_M


def test_side_swipe_is_a_collision_with_minimum_reward(env: CutInEnv) -> None:
    ic = InitialCondition(20.0, 20.0, -2.0)  # POV rear 2 m behind the VUT front: side by side
    _, rewards, infos, terminated = run(env, ic, [LANE_CHANGE] + [hold(20)] * 6)
    assert terminated and len(rewards) == 3  # 1.92 m sideways: the bodies overlap
    assert infos[-1]["collision"] and rewards[-1] == env.config.reward.min_reward
    assert infos[-1]["reward_adversarial"] == 0.0 and infos[-1]["reward_collision"] == -1.0
    assert bodies_overlap(infos[-1]) and not any(bodies_overlap(i) for i in infos[:-1])
    assert all(r > env.config.reward.min_reward for r in rewards[:-1])


@pytest.mark.parametrize(
    ("ic", "n_steps"),
    [
        (InitialCondition(18.0, 20.0, -2.0), 7),
        (InitialCondition(16.0, 20.0, -1.0), 7),
    ],
)
def test_sumo_flags_side_swipe_when_bodies_overlap_before_lane_flips(
    make_env: Callable[..., CutInEnv], ic: InitialCondition, n_steps: int
) -> None:
    # A 3 s change moves 0.2133 m per step: the bodies (1.8 m wide) overlap sideways from
    # 1.4 m (step 7, 1.49 m), the POV's lane index flips only at 1.6 m (step 8). SUMO counts
    # a changing vehicle on both lanes and flags the overlap itself, in step 7.
    env = make_env(cfg(lanechange_duration_s=3.0))
    actions = [LANE_CHANGE] + [hold(ic.pov_speed_mps)] * 10
    _, rewards, infos, terminated = run(env, ic, actions)
    assert terminated and len(rewards) == n_steps
    assert infos[-1]["collision"] and rewards[-1] == env.config.reward.min_reward
    assert infos[-1]["pov_lane"] == POV_LANE  # not flipped yet
    assert bodies_overlap(infos[-1]) and not any(bodies_overlap(i) for i in infos[:-1])


def test_cut_in_ahead_with_room_does_not_collide(env: CutInEnv) -> None:
    _, _, infos, terminated = run(env, InitialCondition(20.0, 20.0, 3.0), [LANE_CHANGE] * 8)
    assert not terminated and not any(i["collision"] for i in infos[1:])


def test_pov_entirely_behind_earns_nothing(env: CutInEnv) -> None:
    ic = InitialCondition(10.0, 30.0, 0.0)
    actions = [hold(0)] * 4 + [LANE_CHANGE] + [hold(0)] * 6
    _, rewards, infos, terminated = run(env, ic, actions)
    assert not terminated
    assert infos[-1]["same_lane"] and infos[-1]["headway_m"] < -2 * CAR_LENGTH_M
    assert infos[-1]["reward_phase"] == "behind" and rewards[-1] == 0.0


# ---------------------------------------------------------------------------- no-ops, errors


def test_lane_change_during_change_and_in_vut_lane_is_a_flagged_noop(env: CutInEnv) -> None:
    ic = InitialCondition(18.0, 20.0, 8.0)
    actions = [LANE_CHANGE, LANE_CHANGE, hold(25)] + [LANE_CHANGE] * 5
    _, _, infos, terminated = run(env, ic, actions)
    assert not terminated
    assert infos[1]["lane_change_started"] and not infos[1]["lane_change_ignored"]
    assert infos[1]["target_speed_mps"] == 18.0  # lane change keeps the last target (initial)
    assert infos[2]["lane_change_ignored"] and infos[2]["lane_changing"]  # during the change
    assert infos[3]["target_speed_mps"] == 25.0  # speed actions act during the change
    for info in infos[4:]:
        assert info["lane_change_ignored"] and not info["lane_change_started"]
        assert info["target_speed_mps"] == 25.0  # kept
    assert infos[-1]["same_lane"] and not infos[-1]["lane_changing"]
    assert infos[-1]["pov_y_m"] == pytest.approx(LANE0_Y_M, abs=1e-9)


@pytest.mark.parametrize("action", [-1, N_ACTIONS, 1.5, "0", None, np.array([1, 2])])
def test_out_of_range_action_raises(env: CutInEnv, action: Any) -> None:
    env.reset(seed=0)
    with pytest.raises(ActionError):
        env.step(action)


def test_step_before_reset_raises(env: CutInEnv) -> None:
    with pytest.raises(ActionError):
        env.step(0)


# ---------------------------------------------------------------------------- determinism


def episode(env: CutInEnv, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    actions = rng.integers(FIRST_SPEED_ACTION, N_ACTIONS, size=25)
    actions[rng.integers(0, 10)] = LANE_CHANGE
    obs, _ = env.reset(seed=seed)
    observations, rewards = [obs], []
    for a in actions:
        obs, reward, terminated, truncated, _ = env.step(int(a))
        observations.append(obs)
        rewards.append(float(reward))
        if terminated or truncated:
            break
    return np.stack(observations), np.array(rewards)


def test_same_seed_same_episode_different_seed_different(
    make_env: Callable[..., CutInEnv],
) -> None:
    env = make_env(sumo_seed=5)
    first = episode(env, 11)
    again = episode(env, 11)  # same simulation, later episode
    other = episode(env, 12)
    env = make_env(sumo_seed=5)  # closes the first env, starts a fresh simulation
    fresh = episode(env, 11)
    for run_ in (again, fresh):
        assert np.array_equal(run_[0], first[0]) and np.array_equal(run_[1], first[1])
    assert first[0].shape != other[0].shape or not np.array_equal(first[0], other[0])


def test_config_must_be_cut_in() -> None:
    with pytest.raises(ValueError, match="cut_in"):
        CutInEnv(EnvConfig(case="car_following"))
