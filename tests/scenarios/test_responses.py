"""One-step VUT responses measured in real SUMO, many pairs per simulation."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from examples.acc_controller import TimeGapACC
from sumo_ayss.config import PROJECT_ROOT, EnvConfig, load_experiment
from sumo_ayss.envs.car_following import CarFollowingEnv
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.scenarios.responses import measure_responses
from sumo_ayss.util.errors import ConfigError
from sumo_ayss.vuts.catalog import ControllerSpec, VehicleType
from sumo_ayss.vuts.controllers import ControllerInput, bound_acceleration, commanded_speed

pytestmark = pytest.mark.sumo

#: (v_pov, v_vut, h): closing, opening, standstill POV, near contact, free-ish.
STATES = np.array(
    [
        [10.0, 20.0, 4.0],
        [30.0, 10.0, 1.0],
        [0.0, 3.0, 2.0],
        [15.0, 15.0, 0.3],
        [25.0, 5.0, 5.0],
        [12.0, 12.5, 3.3],
    ]
)


def _measure(cfg: EnvConfig, vut: str, **kw: object):  # type: ignore[no-untyped-def]
    return measure_responses(cfg, vut, STATES[:, 0], STATES[:, 1], STATES[:, 2], **kw)  # type: ignore[arg-type]


def test_response_is_the_speed_change_of_the_single_env_step() -> None:
    """Same numbers as placing one pair with the single env, stepping once and reading the
    VUT's speed change over the step (the POV holds its speed)."""
    cfg = EnvConfig(case="car_following")
    r = _measure(cfg, "pi1", n_pairs=4)  # fewer pairs than states: pairs are reused
    expected = []
    env = CarFollowingEnv(cfg)
    try:
        for v_pov, v_vut, h in STATES:
            obs, _ = env.reset(
                seed=0, options={"initial_condition": InitialCondition(v_pov, v_vut, h)}
            )
            assert obs[1] == pytest.approx(v_vut, abs=1e-4)
            obs2, _, _, _, info = env.step(CarFollowingEnv.RESPONSE_ACTION)
            assert obs2[0] == pytest.approx(v_pov, abs=1e-4)  # the POV held its speed
            expected.append((float(obs2[1]) - v_vut) / cfg.sim.step_length_s)
            assert info["vut_accel_mps2"] == pytest.approx(expected[-1], abs=1e-3)
    finally:
        env.close()
    np.testing.assert_allclose(r.accel_mps2, expected, atol=1e-3)  # float32 observations
    assert r.steps == 1 and not r.collided.any()
    # SUMO's IDM brakes at its emergencyDecel floor (6 m/s²) at the closing 4 m state.
    assert r.accel_mps2[0] == pytest.approx(-6.0, abs=1e-9)


def test_pairs_per_simulation_do_not_change_the_result() -> None:
    cfg = EnvConfig(case="car_following")
    one = _measure(cfg, "pi2", n_pairs=1)
    many = _measure(cfg, "pi2", n_pairs=64)
    np.testing.assert_array_equal(one.accel_mps2, many.accel_mps2)


def test_controller_vut_through_its_controller_path() -> None:
    spec = ControllerSpec(
        "examples.acc_controller:TimeGapACC", 3.0, 6.0, params={"time_gap_s": 1.5}
    )
    cfg = EnvConfig(case="car_following", vut="acc", vuts={"acc": VehicleType(controller=spec)})
    r = _measure(cfg, "acc")
    ctrl, dt = TimeGapACC(time_gap_s=1.5), cfg.sim.step_length_s
    for (v_pov, v_vut, h), got in zip(STATES, r.accel_mps2, strict=True):
        a = bound_acceleration(
            ctrl.acceleration(ControllerInput(0.0, dt, v_vut, h, v_pov - v_vut, 0)), 3.0, 6.0
        )
        _, realised = commanded_speed(v_vut, a, dt, spec.max_speed_mps)
        assert got == pytest.approx(realised, abs=1e-6)


def test_cut_in_first_step_is_free_driving_second_is_not() -> None:
    """In the first 0.2 s of a 1 s cut-in the POV is still in its own lane: SUMO's IDM VUTs
    drive freely, so pi1 and pi2 respond alike; over two decisions they do not."""
    cfg = EnvConfig(case="cut_in")
    r1 = {v: _measure(cfg, v).accel_mps2 for v in ("pi1", "pi2")}
    np.testing.assert_array_equal(r1["pi1"], r1["pi2"])
    assert (r1["pi1"] >= 0).all()  # no braking: nothing in the VUT's lane yet
    r2 = {v: _measure(cfg, v, decisions=2) for v in ("pi1", "pi2")}
    assert r2["pi1"].steps == 2
    assert np.abs(r2["pi1"].accel_mps2 - r2["pi2"].accel_mps2).max() > 0.5


def test_bad_arguments_are_refused() -> None:
    cfg = EnvConfig()
    with pytest.raises(ConfigError, match="vut must be one of"):
        measure_responses(cfg, "pi9", [1.0], [1.0], [1.0])
    with pytest.raises(ConfigError, match="decisions must be an integer >= 1"):
        measure_responses(cfg, "pi1", [1.0], [1.0], [1.0], decisions=0)
    with pytest.raises(ConfigError, match="same length"):
        measure_responses(cfg, "pi1", [1.0, 2.0], [1.0], [1.0])
    empty = measure_responses(cfg, "pi1", [], [], [])
    assert len(empty.accel_mps2) == 0 and not math.isnan(empty.step_length_s)


def test_highway_env_vut_matches_the_fidelity_env_step() -> None:
    """Paper-fidelity config (highway-env POV law, highway-env IDM VUT): the measurement
    runs the POV on the clipped law (it holds its speed either way); the VUT's response
    equals the single env's step under the config's own highway-env POV law."""
    exp = load_experiment(PROJECT_ROOT / "configs" / "car_following_fidelity.yaml")
    cfg = dataclasses.replace(exp.env, vut="hwenv_pi1")
    assert cfg.actuator.mode == "highway_env"
    r = _measure(cfg, "hwenv_pi1")
    env = CarFollowingEnv(cfg)
    try:
        for (v_pov, v_vut, h), got in zip(STATES, r.accel_mps2, strict=True):
            ic = InitialCondition(v_pov, v_vut, h)
            env.reset(seed=0, options={"initial_condition": ic})
            obs, _, _, _, info = env.step(CarFollowingEnv.RESPONSE_ACTION)
            assert obs[0] == pytest.approx(v_pov, abs=1e-4)
            assert got == pytest.approx(info["vut_accel_mps2"], abs=1e-9)
    finally:
        env.close()
