"""The env takes its vehicle laws as objects (:mod:`sumo_ayss.laws`) and calls them."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from sumo_ayss.config import EnvConfig
from sumo_ayss.envs import make_env
from sumo_ayss.envs.car_following import CarFollowingEnv
from sumo_ayss.envs.cut_in import LANE_CHANGE, CutInEnv
from sumo_ayss.laws import PovLaw, VehicleLaws, VutLaw, build_laws
from sumo_ayss.sim.pair import VehiclePair

pytestmark = pytest.mark.sumo


class SpyPov(PovLaw):
    """Our clipped POV law, with every call the env makes logged."""

    def __init__(self, inner: PovLaw, log: list[str]) -> None:
        self.inner, self.log = inner, log

    def start(self, pair: VehiclePair, speed_mps: float) -> None:
        self.log.append("pov.start")
        self.inner.start(pair, speed_mps)

    def command(self, pair: VehiclePair, target_speed_mps: float) -> None:
        self.log.append("pov.command")
        self.inner.command(pair, target_speed_mps)

    def sync(self, pair: VehiclePair) -> None:
        self.log.append("pov.sync")

    def accel_mps2(self, pair: VehiclePair) -> float:
        return self.inner.accel_mps2(pair)

    def substep_states(self, pair: VehiclePair) -> Any:
        return self.inner.substep_states(pair)

    def change_lane(self, pair: VehiclePair, lane: int, request_s: float) -> None:
        self.log.append(f"pov.change_lane({lane})")
        self.inner.change_lane(pair, lane, request_s)

    def lane_motion(self, *args: float) -> tuple[float, float, bool]:
        return self.inner.lane_motion(*args)


class SpyVut(VutLaw):
    def __init__(self, inner: VutLaw, log: list[str]) -> None:
        self.inner, self.log = inner, log

    def start(self, pair: VehiclePair, speed_mps: float) -> None:
        self.log.append("vut.start")
        self.inner.start(pair, speed_mps)

    def command(self, pair: VehiclePair, pov: PovLaw) -> None:
        self.log.append("vut.command")
        self.inner.command(pair, pov)

    def sync(self, pair: VehiclePair) -> None:
        self.log.append("vut.sync")

    def accel_mps2(self, pair: VehiclePair) -> float:
        return self.inner.accel_mps2(pair)

    def collided(self, sumo_collided: bool) -> bool:
        self.log.append("vut.collided")
        return self.inner.collided(sumo_collided)


def run(env: Any, actions: list[int]) -> list[Any]:
    out: list[Any] = [env.reset(seed=3)[0]]
    for a in actions:
        obs, r, term, trunc, info = env.step(a)
        out.append((obs, r, term, trunc, info["pov_accel_mps2"], info["vut_accel_mps2"]))
    env.close()
    return out


@pytest.mark.parametrize(("env_class", "first"), [(CarFollowingEnv, 2), (CutInEnv, LANE_CHANGE)])
def test_the_env_calls_the_laws_it_is_given_in_order(env_class: type, first: int) -> None:
    config = EnvConfig(case=env_class.CASE)
    log: list[str] = []
    laws = build_laws(config)
    spy = VehicleLaws(SpyPov(laws.pov, log), SpyVut(laws.vut, log))
    actions = [first, 5, 5]
    got = run(env_class(config, sumo_seed=0, laws=spy), actions)
    want = run(make_env(config, sumo_seed=0), actions)
    np.testing.assert_equal(got, want)  # the laws it was given are the ones it builds
    step = ["pov.command", "vut.command", "pov.sync", "vut.sync", "vut.collided"]
    lane_change = ["pov.change_lane(0)"] if first == LANE_CHANGE else []
    assert log == ["vut.start", "pov.start", *lane_change, *step, *step, *step]
