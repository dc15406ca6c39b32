"""The episode-phase protocol (envs/protocol.py) that PairVecEnv drives is public and kept."""

from __future__ import annotations

import inspect

import numpy as np
import pytest

from sumo_ayss.envs.car_following import CarFollowingEnv
from sumo_ayss.envs.cut_in import CutInEnv
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.envs.pair_env import PairEnv
from sumo_ayss.envs.protocol import EpisodePhases

PHASES = [
    name
    for name, member in inspect.getmembers(EpisodePhases, inspect.isfunction)
    if not name.startswith("_")
]


def test_the_protocol_names_the_six_phases() -> None:
    assert sorted(PHASES) == sorted(
        [
            "join_shared",
            "begin_reset",
            "start_episode",
            "begin_decision",
            "command_pov",
            "end_decision",
        ]
    )


@pytest.mark.parametrize("env_class", [CarFollowingEnv, CutInEnv])
def test_both_cases_implement_it_with_its_signatures(env_class: type[PairEnv]) -> None:
    env = env_class(sumo_seed=0)
    assert isinstance(env, EpisodePhases)
    for name in PHASES:
        want = inspect.signature(getattr(EpisodePhases, name))
        got = inspect.signature(getattr(env_class, name))
        assert list(got.parameters) == list(want.parameters), name
    env.close()


@pytest.mark.sumo
def test_step_and_reset_are_the_phases_in_the_documented_order(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The single env's ``reset``/``step`` call the phases in the protocol's order."""
    calls: list[str] = []
    for name in ("begin_reset", "start_episode", "begin_decision", "command_pov"):
        original = getattr(CarFollowingEnv, name)

        def spy(self: PairEnv, *args: object, _name: str = name, _f: object = original) -> object:
            calls.append(_name)
            return _f(self, *args)  # type: ignore[operator]

        monkeypatch.setattr(CarFollowingEnv, name, spy)
    original_end = CarFollowingEnv.end_decision

    def end(self: PairEnv, collided: bool) -> object:
        calls.append("end_decision")
        return original_end(self, collided)

    monkeypatch.setattr(CarFollowingEnv, "end_decision", end)
    env = CarFollowingEnv(sumo_seed=0)
    try:
        ic = InitialCondition(gap_m=30.0, pov_speed_mps=20.0, vut_speed_mps=20.0)
        env.reset(seed=0, options={"initial_condition": ic})
        env.step(np.int64(0))
    finally:
        env.close()
    steps = env.config.steps_per_decision
    assert calls == [
        "begin_reset",
        "start_episode",
        "begin_decision",
        *["command_pov"] * steps,
        "end_decision",
    ]
