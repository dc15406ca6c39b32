"""The follower behind the VUT (issue 33), with real SUMO.

It is placed where its start says; it never changes the VUT-POV episode (every VUT law,
stochastic ones too: the same observations, rewards and crashes as without it); a rear-end
collision is recorded and neither ends the episode nor counts as a VUT-POV crash; the same
scenario and seed give the same follower.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from sumo_ayss.config import EnvConfig, FollowerConfig
from sumo_ayss.envs import make_env
from sumo_ayss.envs.odd import InitialCondition, sample_initial_conditions, with_followers
from sumo_ayss.envs.pair_env import PairEnv
from sumo_ayss.util.errors import ConfigError
from sumo_ayss.vuts.catalog import VehicleType

pytestmark = pytest.mark.sumo

NOISY = VehicleType(model="Krauss", params={"sigma": 0.9, "minGap": 5.0, "tau": 1.0})
ON = FollowerConfig(enabled=True)


def _cfg(case: str, vut: str = "pi1", follower: bool = True) -> EnvConfig:
    from sumo_ayss.vuts.catalog import BUILTIN_VUTS
    from sumo_ayss.vuts.reference_types import OVERBRAKER_VUT

    vuts = {**BUILTIN_VUTS, "noisy": NOISY, "overbraker": OVERBRAKER_VUT}
    return EnvConfig(
        case=case,
        vuts=vuts,  # type: ignore[arg-type]
        vut=vut,
        follower=ON if follower else FollowerConfig(),
    )


def _run(env: PairEnv, ic: InitialCondition, actions: list[int]) -> tuple[list, list]:
    obs, info = env.reset(options={"initial_condition": ic})
    trace, infos = [obs], [info]
    for a in actions:
        obs, r, term, trunc, info = env.step(a)
        trace.append(np.append(obs, [r, float(term)]))
        infos.append(info)
        if term or trunc:
            break
    return trace, infos


@pytest.mark.parametrize(
    ("case", "vut", "actions"),
    [
        ("car_following", "pi1", [0, 2, 4, 0, 1, 2] * 5),
        ("car_following", "noisy", [0, 2, 4, 0, 1, 2] * 5),
        ("cut_in", "pi2", [0, 20, 15, 10, 5] * 6),
        ("cut_in", "noisy", [0, 20, 15, 10, 5] * 6),
        ("car_following", "overbraker", [0, 2, 4, 0, 1, 2] * 5),
        ("cut_in", "overbraker", [0, 20, 15, 10, 5] * 6),
    ],
)
def test_the_follower_never_changes_the_vut_pov_episode(case, vut, actions) -> None:  # type: ignore[no-untyped-def]
    on, off = _cfg(case, vut, True), _cfg(case, vut, False)
    ics = with_followers(sample_initial_conditions(on.odd, 4, 7), on.follower, 7)
    assert all(ic.follower_gap_m is not None for ic in ics)
    bare = [dataclasses.replace(ic, follower_gap_m=None, follower_speed_mps=None) for ic in ics]
    runs = []
    for cfg, starts in ((on, ics), (off, bare)):  # one libsumo simulation at a time
        env = make_env(cfg, sumo_seed=3)
        try:
            runs.append([_run(env, ic, actions) for ic in starts])
        finally:
            env.close()
    for (a, infos), (b, _) in zip(*runs, strict=True):
        assert "follower_pos_m" in infos[-1]  # it was there
        assert len(a) == len(b)
        for x, y in zip(a, b, strict=True):
            np.testing.assert_array_equal(x, y)


def test_the_follower_starts_where_its_start_says() -> None:
    cfg = _cfg("car_following")
    ic = InitialCondition(20.0, 20.0, 10.0, follower_gap_m=30.0, follower_speed_mps=18.0)
    env = make_env(cfg, sumo_seed=1)
    try:
        _, info = env.reset(options={"initial_condition": ic})
    finally:
        env.close()
    gap = info["vut_pos_m"] - cfg.vut_type.length_m - info["follower_pos_m"]
    assert gap == pytest.approx(30.0, abs=1e-9)
    assert info["follower_speed_mps"] == pytest.approx(18.0, abs=1e-9)
    assert info["rear_end"] is False


def test_a_rear_end_is_recorded_and_is_not_a_vut_pov_crash() -> None:
    """A follower closing in fast on a VUT that stops hits it: recorded, the episode goes on."""
    cfg = _cfg("car_following")
    # The POV stops at once (action 0) 3 m ahead; the VUT brakes hard; the follower, 2.5 m
    # behind at 8 m/s more, reacts after its 1 s action step: a rear-end.
    ic = InitialCondition(20.0, 20.0, 3.0, follower_gap_m=2.5, follower_speed_mps=28.0)
    env = make_env(cfg, sumo_seed=1)
    try:
        _, infos = _run(env, ic, [2] * 25)
    finally:
        env.close()
    rear = [i["rear_end"] for i in infos]
    assert any(rear), "the follower should have hit the VUT"
    assert not any(i.get("collision", False) for i in infos)
    assert len(infos) == 26  # not ended by the rear-end: the full 25 decisions
    hit = rear.index(True)
    assert np.isnan(infos[-1]["follower_pos_m"])  # removed after the rear-end
    assert hit < 25


def test_the_same_scenario_gives_the_same_follower_for_every_vut() -> None:
    cfg = _cfg("car_following")
    ics = sample_initial_conditions(cfg.odd, 6, 4242)
    a = with_followers(ics, cfg.follower, 4242)
    b = with_followers(ics, cfg.follower, 4242)
    assert a == b
    assert [dataclasses.replace(x, follower_gap_m=None, follower_speed_mps=None) for x in a] == ics
    thw = [x.follower_gap_m / x.vut_speed_mps for x in a]  # type: ignore[operator]
    assert all(1.0 <= t <= 2.0 for t in thw)
    assert with_followers(ics, FollowerConfig(), 4242) == ics  # off: unchanged


def test_a_follower_starting_inside_the_vut_is_refused() -> None:
    cfg = _cfg("car_following")
    env = make_env(cfg, sumo_seed=1)
    try:
        for gap in (0.0, -3.0):
            ic = InitialCondition(20.0, 20.0, 10.0, follower_gap_m=gap, follower_speed_mps=20.0)
            with pytest.raises(ConfigError, match="follower_gap_m must be > 0"):
                env.reset(options={"initial_condition": ic})
    finally:
        env.close()


def test_same_scenario_and_seed_give_the_same_follower_and_hazards() -> None:
    """Reproducibility with the follower on: a stochastic VUT, twice on fresh envs."""
    from sumo_ayss.scenarios.rollout import run_episode

    cfg = _cfg("car_following", "noisy")
    ics = with_followers(sample_initial_conditions(cfg.odd, 3, 11), cfg.follower, 11)

    def policy(obs):  # type: ignore[no-untyped-def]
        return np.array([0 if obs[0, 2] > 8.0 else 2])

    runs = []
    for _ in range(2):
        env = make_env(cfg, sumo_seed=5)
        try:
            runs.append([run_episode(env, policy, ic) for ic in ics])
        finally:
            env.close()
    for a, b in zip(*runs, strict=True):
        assert a == b and a.hazards == b.hazards and a.measures == b.measures
        assert a.hazards is not None and np.isfinite(a.hazards.follower_max_braking_mps2)
        assert a.hazards.rear_end in (0.0, 1.0)
