"""Crash labels with real SUMO: the replay reproduces the POV, and the labels mean what they say."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import numpy.typing as npt
import pytest

from sumo_ayss.config import EnvConfig
from sumo_ayss.envs import make_env
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.scenarios.preventability import (
    label_crashes,
    reference_config,
)
from sumo_ayss.scenarios.rollout import run_episode
from sumo_ayss.util.errors import ConfigError
from sumo_ayss.vuts.catalog import ControllerSpec, VehicleType
from sumo_ayss.vuts.reference_types import REFERENCE_VUTS

#: A VUT that never brakes (holds its speed whatever happens).
BLIND = VehicleType(
    model="IDM",
    params={"length": 5.0},
    description="holds its speed",
    controller=ControllerSpec(
        target="tests.scenarios.test_preventability:Blind",
        params={},
        max_accel_mps2=3.0,
        max_decel_mps2=6.0,
    ),
)


class Blind:
    """A controller that never brakes."""

    def acceleration(self, state: object) -> float:
        return 0.0


def _config(case: str, vut: str, vt: VehicleType | None = None) -> EnvConfig:
    cfg = EnvConfig(case=case)
    vuts = dict(cfg.vuts)
    if vt is not None:
        vuts[vut] = vt
    elif vut in REFERENCE_VUTS:
        vuts[vut] = REFERENCE_VUTS[vut]
    return dataclasses.replace(cfg, vuts=vuts, vut=vut)


def _brake(obs: npt.NDArray[np.float32]) -> npt.NDArray[np.int64]:
    """Car-following: action 0, target speed 0 (brake as hard as the actuator allows)."""
    return np.zeros(len(obs), dtype=np.int64)


def _scenarios() -> list[InitialCondition]:
    # Both at 20 m/s; gaps from "no driver can stop in time" to "plenty of room".
    return [InitialCondition(20.0, 20.0, g) for g in (1.0, 3.0, 8.0, 20.0, 30.0)]


def _run(cfg: EnvConfig, scenarios: list[InitialCondition]) -> list:
    env = make_env(cfg, sumo_seed=7)
    try:
        return [run_episode(env, _brake, ic) for ic in scenarios]
    finally:
        env.close()


def test_replay_reproduces_the_pov_trajectory_up_to_the_crash() -> None:
    """The reference's replay moves the POV exactly as in the original episode."""
    cfg = _config("car_following", "blind", BLIND)
    ic = InitialCondition(20.0, 20.0, 8.0)
    env = make_env(cfg, sumo_seed=7)
    try:
        obs, info = env.reset(options={"initial_condition": ic})
        original, actions = [], []
        done = False
        while not done:
            actions.append(int(_brake(obs[None, :])[0]))
            obs, _r, term, trunc, info = env.step(actions[-1])
            original.append((info["pov_pos_m"], info["pov_speed_mps"]))
            done = term or trunc
        assert info["collision"], "the blind VUT must crash here for the test to mean anything"
    finally:
        env.close()
    ref = make_env(reference_config(cfg, "cc_driver"), sumo_seed=7)
    try:
        ref.reset(options={"initial_condition": ic})
        replayed = []
        for a in actions:
            _o, _r, term, _t, info = ref.step(a)
            replayed.append((info["pov_pos_m"], info["pov_speed_mps"]))
            if term:
                break
    finally:
        ref.close()
    n = len(original)
    assert replayed[:n] == original[: len(replayed)]
    assert len(replayed) == n  # the reference survived at least as long


def test_labels_blind_vut_crashes_preventable_where_the_reference_stops_in_time() -> None:
    cfg = _config("car_following", "blind", BLIND)
    scenarios = _scenarios()
    episodes = _run(cfg, scenarios)
    collided = [e.collided for e in episodes]
    assert all(collided), "the blind VUT crashes into a POV braking to a stop every time"
    labels = label_crashes(cfg, scenarios, collided, [e.actions for e in episodes], sumo_seed=7)
    # At 1 m no reaction can help; with 20 m and 30 m the careful driver stops in time.
    assert labels[0] == 0.0
    assert labels[3] == 1.0 and labels[4] == 1.0
    assert set(labels.tolist()) <= {0.0, 1.0}


def test_a_vut_identical_to_the_reference_has_no_preventable_crash() -> None:
    cfg = _config("car_following", "cc_driver")
    scenarios = _scenarios()
    episodes = _run(cfg, scenarios)
    collided = [e.collided for e in episodes]
    assert any(collided), "some of these scenarios must crash even the careful driver"
    labels = label_crashes(cfg, scenarios, collided, [e.actions for e in episodes], sumo_seed=7)
    crashed = labels[np.array(collided)]
    assert crashed.size and (crashed == 0.0).all()
    assert np.isnan(labels[~np.array(collided)]).all()


def test_cut_in_labels_run_and_no_crash_starts_no_replay() -> None:
    cfg = _config("cut_in", "blind", BLIND)
    ic = InitialCondition(15.0, 20.0, 4.0)

    def cut(obs: npt.NDArray[np.float32]) -> npt.NDArray[np.int64]:
        return np.zeros(len(obs), dtype=np.int64)  # lane change, then keep the speed

    env = make_env(cfg, sumo_seed=3)
    try:
        e = run_episode(env, cut, ic)
    finally:
        env.close()
    assert e.collided
    labels = label_crashes(cfg, [ic], [True], [e.actions], sumo_seed=3)
    assert labels[0] in (0.0, 1.0)
    none = label_crashes(cfg, [ic], [False], [e.actions], sumo_seed=3)
    assert math.isnan(none[0])


def test_unknown_reference_is_a_clear_error() -> None:
    with pytest.raises(ConfigError, match=r"one of \['cc_driver', 'fsm', 'rss'\]"):
        reference_config(EnvConfig(case="car_following"), "superhuman")
