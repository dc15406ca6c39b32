"""LeadAndCutInEnv against a real SUMO: the no-collusion rules on scripted episodes, the
start's reproduction, determinism, and what the case refuses (issue 39, docs/cases.md).

One libsumo simulation per process: each test closes its env (the ``make`` fixture).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env as gym_check_env

from sumo_ayss.config import EnvConfig, ExperimentConfig, TrainConfig
from sumo_ayss.envs import make_env
from sumo_ayss.envs.lead_and_cut_in import (
    CUT_LANE_CHANGE,
    N_ACTIONS,
    PRIMARY_CUT_IN,
    PRIMARY_LEAD,
    SPEED_OFFSETS_MPS,
    LeadAndCutInEnv,
    TwoPovStart,
    decode_action,
    encode_action,
    two_pov_start,
)
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.scenarios.preventability import label_crashes
from sumo_ayss.scenarios.rollout import run_episode
from sumo_ayss.util.errors import ConfigError
from sumo_ayss.vuts.catalog import VehicleType

pytestmark = pytest.mark.sumo

ALPHA_C = 10.0
HOLD = SPEED_OFFSETS_MPS.index(0.0)  # offset 0: hold speed
BRAKE = 0  # offset -5 m/s: the actuator's -6 m/s²
#: A VUT that can brake only 1 m/s² (crashes a careful human would have avoided).
WEAK = VehicleType(
    "IDM", {"accel": 3.0, "decel": 1.0, "emergencyDecel": 1.0, "minGap": 2.0, "tau": 1.0}
)


def config(vut: str = "pi1") -> EnvConfig:
    base = EnvConfig(case="lead_and_cut_in")
    return dataclasses.replace(base, vuts={**base.vuts, "weak": WEAK}, vut=vut)


@pytest.fixture
def make() -> Iterator[Callable[..., LeadAndCutInEnv]]:
    envs: list[LeadAndCutInEnv] = []

    def factory(vut: str = "pi1", sumo_seed: int = 7) -> LeadAndCutInEnv:
        for e in envs:
            e.close()
        env = make_env(config(vut), sumo_seed=sumo_seed)
        assert isinstance(env, LeadAndCutInEnv)
        envs.append(env)
        return env

    yield factory
    for e in envs:
        e.close()


def run(env: LeadAndCutInEnv, start: InitialCondition, action: int) -> tuple[list[Any], Any]:
    """Reset to ``start``, repeat ``action`` to the episode's end: (rewards, last info)."""
    env.reset(options={"initial_condition": start})
    rewards = []
    while True:
        _, r, term, trunc, info = env.step(action)
        rewards.append(float(r))
        if term or trunc:
            return rewards, info


def test_joint_action_layout() -> None:
    assert N_ACTIONS == 42
    assert decode_action(encode_action(3, CUT_LANE_CHANGE)) == (3, CUT_LANE_CHANGE)
    assert sorted(encode_action(i, j) for i in range(6) for j in range(7)) == list(range(42))


def test_gymnasium_checker_and_start_reproduced(make: Callable[..., LeadAndCutInEnv]) -> None:
    env = make()
    gym_check_env(env, skip_render_check=True)
    start = TwoPovStart(
        18.0, 22.0, 7.5, support_speed_mps=16.0, support_gap_m=12.0, primary=PRIMARY_CUT_IN
    )
    obs, info = env.reset(options={"initial_condition": start})
    np.testing.assert_allclose(obs, [18.0, 22.0, 7.5, 0.0, 16.0, 12.0, 1.0], atol=1e-5)
    assert info["pov_lane"] == 1 and info["support_lane"] == 0 and info["primary"] == 1


def test_a_plain_start_always_gets_the_same_supporting_pov() -> None:
    odd = EnvConfig(case="lead_and_cut_in").odd
    ic = InitialCondition(21.3, 17.9, 4.2)
    a, b = two_pov_start(ic, odd), two_pov_start(InitialCondition(21.3, 17.9, 4.2), odd)
    assert a == b and a.as_tuple() == ic.as_tuple()
    other = two_pov_start(InitialCondition(21.3, 17.9, 4.3), odd)
    assert (other.support_gap_m, other.support_speed_mps) != (a.support_gap_m, a.support_speed_mps)
    primaries = {two_pov_start(InitialCondition(20.0, 20.0, g), odd).primary for g in range(10)}
    assert primaries == {PRIMARY_LEAD, PRIMARY_CUT_IN}


def test_same_seed_same_episode(make: Callable[..., LeadAndCutInEnv]) -> None:
    def trajectory(env: LeadAndCutInEnv, seed: int) -> list[float]:
        obs, _ = env.reset(seed=seed)
        out = obs.tolist()
        rng = np.random.default_rng(seed)
        for _ in range(25):
            obs, r, term, trunc, _ = env.step(int(rng.integers(N_ACTIONS)))
            out += [*obs.tolist(), float(r)]
            if term or trunc:
                break
        return out

    env = make()
    first = trajectory(env, 5)
    assert trajectory(env, 5) == first  # used env
    assert trajectory(env, 6) != first
    assert trajectory(make(), 5) == first  # fresh env


def test_primary_crash_is_the_vuts_crash_and_pays_the_safe_term_only(
    make: Callable[..., LeadAndCutInEnv],
) -> None:
    """Lead primary brakes hard 25 m ahead: the weak VUT (1 m/s²) hits it, a careful human
    would have stopped: a crash, -α_C, no penalty, no adversarial pay on that step."""
    start = TwoPovStart(
        20.0, 20.0, 25.0, support_speed_mps=20.0, support_gap_m=60.0, primary=PRIMARY_LEAD
    )
    env = make("weak")
    rewards, info = run(env, start, encode_action(BRAKE, 1 + HOLD))
    assert info["collision"] and not info["pov_failure"]
    assert info["crash_unpreventable"] == 0.0
    assert rewards[-1] == -ALPHA_C and info["reward_adversarial"] == 0.0
    assert max(rewards[:-1]) > 0.0  # the near-miss before it paid


def test_unpreventable_crash_is_penalised_and_matches_the_preventability_replay(
    make: Callable[..., LeadAndCutInEnv],
) -> None:
    """The lead brakes 3 m ahead of a VUT closing at 5 m/s: nobody could stop; the label
    is the one scenarios/preventability.py computes after the fact, for both crashes."""
    hard = TwoPovStart(
        20.0, 25.0, 3.0, support_speed_mps=20.0, support_gap_m=60.0, primary=PRIMARY_LEAD
    )
    soft = TwoPovStart(
        20.0, 20.0, 25.0, support_speed_mps=20.0, support_gap_m=60.0, primary=PRIMARY_LEAD
    )
    action = encode_action(BRAKE, 1 + HOLD)
    env = make("weak")
    rewards, info = run(env, hard, action)
    assert info["collision"] and info["crash_unpreventable"] == 1.0
    assert rewards[-1] == -2 * ALPHA_C
    n_hard = len(rewards)
    n_soft = len(run(env, soft, action)[0])
    assert env.replays == 2
    # A plain start (the supporting POV derived) stays the episode's start after the replay
    # (a training checkpoint stores it as a plain InitialCondition).
    odd = env.config.odd
    gaps = (2.0 + 0.01 * k for k in range(100))
    plain = next(
        ic
        for g in gaps
        if two_pov_start(ic := InitialCondition(20.0, 25.0, g), odd).primary == PRIMARY_LEAD
    )
    assert run(env, plain, action)[1]["collision"] and env.replays == 3
    assert type(env.initial_condition) is InitialCondition
    env.close()
    labels = label_crashes(
        config("weak"),
        [hard, soft],
        [True, True],
        [[action] * n_hard, [action] * n_soft],
        sumo_seed=7,
    )
    assert labels.tolist() == [0.0, 1.0]  # unpreventable, preventable


def test_supporting_pov_touching_the_vut_is_the_povs_failure(
    make: Callable[..., LeadAndCutInEnv],
) -> None:
    """The supporting cut-in POV changes in right in front of a faster VUT: the episode
    ends, not as the VUT's crash, at -α_C, and no online replay runs."""
    start = TwoPovStart(
        25.0, 25.0, 40.0, support_speed_mps=12.0, support_gap_m=0.5, primary=PRIMARY_LEAD
    )
    env = make()
    rewards, info = run(env, start, encode_action(HOLD, CUT_LANE_CHANGE))
    assert info["pov_failure"] and info["vut_contact"] and not info["collision"]
    assert info["support_vut_contact"] and not info["pov_pov_contact"]
    assert rewards[-1] == -ALPHA_C and info["reward_adversarial"] == 0.0
    assert env.replays == 0 and "crash_unpreventable" not in info


def test_pov_pov_contact_is_the_povs_failure_with_both_safe_terms(
    make: Callable[..., LeadAndCutInEnv],
) -> None:
    """The supporting cut-in POV swerves into the lead beside it: -2·α_C, POVs' failure."""
    start = TwoPovStart(
        15.0, 15.0, 6.0, support_speed_mps=15.0, support_gap_m=4.0, primary=PRIMARY_LEAD
    )
    env = make()
    rewards, info = run(env, start, encode_action(HOLD, CUT_LANE_CHANGE))
    assert info["pov_failure"] and not info["collision"] and not info["vut_contact"]
    assert info["pov_pov_contact"] and not info["support_vut_contact"]
    assert rewards[-1] == -2 * ALPHA_C


def test_supporting_pov_never_earns_the_adversarial_reward(
    make: Callable[..., LeadAndCutInEnv],
) -> None:
    """A cut-in primary far away in its lane, the lead supporting 1 m ahead: no pay, since
    the near POV is not the primary (the lead as primary in the same state is paid)."""
    env = make()
    near = dict(support_speed_mps=20.0, support_gap_m=1.0)
    start = TwoPovStart(20.0, 20.0, 60.0, primary=PRIMARY_CUT_IN, **near)  # type: ignore[arg-type]
    env.reset(options={"initial_condition": start})
    _, r, *_ = env.step(encode_action(HOLD, 1 + HOLD))
    assert r == 0.0
    lead = TwoPovStart(
        20.0, 20.0, 1.0, support_speed_mps=20.0, support_gap_m=60.0, primary=PRIMARY_LEAD
    )
    env.reset(options={"initial_condition": lead})
    _, r, *_ = env.step(encode_action(HOLD, 1 + HOLD))
    assert r > 0.0


def test_the_case_refuses_shared_simulations_and_the_highway_env_actuator() -> None:
    with pytest.raises(ConfigError, match="n_envs must be 1"):
        ExperimentConfig(env=EnvConfig(case="lead_and_cut_in"), train=TrainConfig(n_envs=2))
    cfg = EnvConfig(case="lead_and_cut_in")
    actuator = dataclasses.replace(cfg.actuator, mode="highway_env")
    with pytest.raises(ConfigError, match="must be 'clipped'"):
        sim = dataclasses.replace(cfg.sim, lateral_resolution_m=0.1)
        LeadAndCutInEnv(dataclasses.replace(cfg, actuator=actuator, sim=sim))


def test_safety_measures_are_read_per_pov(make: Callable[..., LeadAndCutInEnv]) -> None:
    """The supporting POV's cut-in into a faster VUT: its measures show the contact (TTC
    0), the primary's, 40 m ahead holding speed, do not."""
    start = TwoPovStart(
        25.0, 25.0, 40.0, support_speed_mps=12.0, support_gap_m=0.5, primary=PRIMARY_LEAD
    )
    action = encode_action(HOLD, CUT_LANE_CHANGE)
    episode = run_episode(make(), lambda obs: np.full(len(obs), action), start)
    assert episode.pov_failure and not episode.collided
    assert episode.support_vut_contact and not episode.pov_pov_contact
    assert episode.support_measures is not None and episode.measures is not None
    assert episode.support_measures.min_ttc_s == 0.0
    assert episode.measures.min_ttc_s > 1.0


def test_inevitable_collision_states_use_the_cases_own_worst_plays() -> None:
    """The ICS check drives the case's own joint actions: a lead 3 m ahead of a VUT closing
    at 5 m/s cannot be avoided by full braking; 40 m ahead at equal speeds it can."""
    from sumo_ayss.scenarios.inevitable import ics_flags, pov_strategies

    assert set(pov_strategies("lead_and_cut_in")) == {
        "lead brakes",
        "cut in, brake",
        "cut in, hold speed",
    }
    near = TwoPovStart(
        20.0, 25.0, 0.5, support_speed_mps=20.0, support_gap_m=60.0, primary=PRIMARY_LEAD
    )
    far = TwoPovStart(
        20.0, 20.0, 40.0, support_speed_mps=20.0, support_gap_m=60.0, primary=PRIMARY_LEAD
    )
    assert ics_flags(config(), [near, far]) == [True, False]


def test_braking_for_the_supporting_pov_is_not_unjustified(
    make: Callable[..., LeadAndCutInEnv],
) -> None:
    """The supporting lead 8 m ahead brakes hard, the cut-in primary holds its lane 60 m
    ahead: the VUT's hard braking answers the supporting POV, so it is justified; read
    against the primary alone (session 10's reading) it would count as unjustified."""
    from sumo_ayss.analysis.hazards import episode_hazards
    from sumo_ayss.scenarios.trajectory import trajectory_from_infos

    start = TwoPovStart(
        20.0, 20.0, 60.0, support_speed_mps=20.0, support_gap_m=8.0, primary=PRIMARY_CUT_IN
    )
    env = make()
    action = encode_action(BRAKE, 1 + HOLD)
    episode = run_episode(env, lambda obs: np.full(len(obs), action), start)
    assert episode.hazards is not None and not episode.collided and not episode.pov_failure
    assert episode.hazards.unjustified_braking == 0.0
    # The same episode against the primary only: the braking reads as for nothing.
    _, reset_info = env.reset(options={"initial_condition": start})
    infos = []
    while True:
        *_, term, trunc, info = env.step(action)
        infos.append(info)
        if term or trunc:
            break
    primary_only = episode_hazards(trajectory_from_infos(env.config, reset_info, infos), None)
    assert primary_only.unjustified_braking == 1.0


@pytest.mark.parametrize("penalty", [0.0, 2.0])
def test_a_forbidden_contact_costs_the_failure_penalty(penalty: float) -> None:
    """``env.reward.pov_failure_penalty`` (α_F, in α_C): the supporting POV's cut-in into
    the VUT pays ``-(1 + α_F)·α_C``; the default 0 is session 10's reward."""
    from sumo_ayss.config import RewardConfig

    cfg = dataclasses.replace(config(), reward=RewardConfig(pov_failure_penalty=penalty))
    start = TwoPovStart(
        25.0, 25.0, 40.0, support_speed_mps=12.0, support_gap_m=0.5, primary=PRIMARY_LEAD
    )
    env = make_env(cfg, sumo_seed=7)
    try:
        assert isinstance(env, LeadAndCutInEnv)
        rewards, info = run(env, start, encode_action(HOLD, CUT_LANE_CHANGE))
    finally:
        env.close()
    assert info["pov_failure"] and info["support_vut_contact"]
    assert rewards[-1] == pytest.approx(-(1.0 + penalty) * ALPHA_C)


def test_the_failure_penalty_is_refused_with_one_pov_and_stored_only_when_set() -> None:
    from sumo_ayss.config import RewardConfig
    from sumo_ayss.config.mapping import to_dict

    with pytest.raises(ConfigError, match="pov_failure_penalty"):
        EnvConfig(case="cut_in", reward=RewardConfig(pov_failure_penalty=1.0))
    with pytest.raises(ConfigError, match=">= 0"):
        RewardConfig(pov_failure_penalty=-1.0)
    assert "pov_failure_penalty" not in to_dict(EnvConfig())["reward"]
    assert "pov_failure_penalty" not in repr(EnvConfig())
    set_ = EnvConfig(case="lead_and_cut_in", reward=RewardConfig(pov_failure_penalty=2.0))
    assert to_dict(set_)["reward"]["pov_failure_penalty"] == 2.0
    assert "pov_failure_penalty=2.0" in repr(set_)
