"""One vehicle everywhere: a VUT is simulated alike by every path that drives it (issue 21).

The property, for VUT definitions drawn across what the catalog accepts (every SUMO
car-following model, SUMO's ``actionStepLength``, ``tau``, ``decel``/``emergencyDecel``,
``minGap``, a user controller, highway-env's law), on common scenarios under a fixed POV
policy, episode for episode and exactly:

* the single env (:func:`~sumo_ayss.scenarios.rollout.run_episodes`),
* the vectorized env, N pairs in one simulation (training's candidate evaluation,
  :func:`~sumo_ayss.training.collectors.evaluate_on_vec`),
* the outcome stage (:func:`~sumo_ayss.scenarios.outcome.run_outcome`),
* the cross-play path (:func:`~sumo_ayss.scenarios.crossplay.run_crossplay`), whose diagonal
  check against the outcome table passes.

Random draws are switched off (``sigma``, ``speedDev``, EIDM's noise): SUMO draws them from
streams shared by all vehicles of a simulation, so one pair among N draws other numbers
than a pair alone. For a stochastic VUT the outcome stage and cross-play still agree
exactly (same path, same SUMO seed), which the last test checks.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from sumo_ayss.config import EnvConfig, SimConfig
from sumo_ayss.envs import make_env
from sumo_ayss.envs.cut_in import LANE_CHANGE
from sumo_ayss.envs.odd import sample_initial_conditions
from sumo_ayss.envs.vec_env import PairVecEnv
from sumo_ayss.scenarios.crossplay import Opponent, diagonal_check, run_crossplay
from sumo_ayss.scenarios.outcome import run_outcome
from sumo_ayss.scenarios.rollout import EpisodeResult, run_episodes
from sumo_ayss.training.collectors import evaluate_on_vec
from sumo_ayss.util.errors import ConfigError
from sumo_ayss.vuts.catalog import ControllerSpec, VehicleType
from sumo_ayss.vuts.vtype_params import ALWAYS_RANDOM_MODELS, MODEL_PARAMS

pytestmark = pytest.mark.sumo

N_SCENARIOS, SCENARIO_SEED, SUMO_SEED = 6, 31, 17

#: Parameters that switch a model's random draws off (SUMO 1.28 names).
NOISE_OFF = {"sigma": 0.0, "sigmaerror": 0.0, "sigmagap": 0.0, "sigmaleader": 0.0}
#: Extra parameters a model needs to be drivable here.
REQUIRED = {"CC": {"lanesCount": 2.0}}
BODY = {"length": 5.0, "speedDev": 0.0, "accel": 3.0, "maxSpeed": 40.0}


def sumo_vut(model: str, **params: float) -> VehicleType:
    """A SUMO model with its noise off, a 5 m body, and ``params``."""
    allowed = MODEL_PARAMS[model]
    noise = {k: v for k, v in NOISE_OFF.items() if k in allowed}
    merged = {**BODY, **noise, **REQUIRED.get(model, {}), **params}
    return VehicleType.from_mapping({"model": model, "params": merged}, f"vuts.{model}")


def acc_vut(time_gap_s: float) -> VehicleType:
    spec = ControllerSpec(
        "examples.acc_controller:TimeGapACC", 3.0, 6.0, params={"time_gap_s": time_gap_s}
    )
    return VehicleType(params={"length": 5.0}, controller=spec)


def policy_for(case: str) -> Any:
    """A fixed, state-dependent POV: brakes hard when close, cuts in when alongside."""

    def car_following(obs: np.ndarray) -> np.ndarray:
        h = obs[:, 2]
        return np.where(h < 6.0, 2, np.where(h < 15.0, 8, 14)).astype(np.int64)

    def cut_in(obs: np.ndarray) -> np.ndarray:
        h, same = obs[:, 2], obs[:, 3]
        act = np.where(h < 8.0, 12, 20)
        return np.where((same < 0.5) & (h < 4.0), LANE_CHANGE, act).astype(np.int64)

    return car_following if case == "car_following" else cut_in


def config_with(case: str, vut: VehicleType) -> EnvConfig:
    base = EnvConfig(case=case)  # type: ignore[arg-type]
    return dataclasses.replace(base, vuts={**base.vuts, "x": vut}, vut="x")


def fields(results: list[EpisodeResult]) -> list[tuple[Any, ...]]:
    """The compared fields (the safety measures are not: the vec env records none)."""
    return [tuple(getattr(r, f.name) for f in dataclasses.fields(r) if f.compare) for r in results]


def assert_one_vehicle(cfg: EnvConfig, *, vec: bool = True) -> list[EpisodeResult]:
    """Every path gives the same episodes; returns them."""
    policy = policy_for(cfg.case)
    scenarios = sample_initial_conditions(cfg.odd, N_SCENARIOS, SCENARIO_SEED)
    env = make_env(cfg, sumo_seed=SUMO_SEED)
    try:
        single = run_episodes(env, policy, scenarios)
    finally:
        env.close()
    if vec:
        venv = PairVecEnv(cfg, n_envs=4, sumo_seed=SUMO_SEED)
        try:
            pairs = evaluate_on_vec(venv, policy, scenarios)
        finally:
            venv.close()
        assert fields(pairs) == fields(single), "vec env"
    env = make_env(cfg, sumo_seed=SUMO_SEED)
    try:
        outcome = run_outcome(env, policy, n=N_SCENARIOS, seed=SCENARIO_SEED).table
    finally:
        env.close()
    assert outcome["episode_return"].tolist() == [r.episode_return for r in single]
    assert outcome["vut_mean_speed_mps"].tolist() == [r.vut_mean_speed_mps for r in single]
    table = run_crossplay(
        {"x": cfg},
        [Opponent("x", SUMO_SEED, lambda e: policy)],
        n=N_SCENARIOS,
        seed=SCENARIO_SEED,
    )
    check = diagonal_check(table, "x", SUMO_SEED, outcome)
    assert check.ok, f"cross-play diagonal: {check}"
    return single


# --------------------------------------------------------------------------- every model


@pytest.mark.parametrize("model", sorted(MODEL_PARAMS))
def test_every_sumo_model_is_one_vehicle_in_car_following(model: str) -> None:
    """Noise off: every path agrees exactly, except that the models SUMO makes draw random
    numbers anyway (ALWAYS_RANDOM_MODELS) agree exactly between outcome and cross-play only,
    and the catalog says so; a model that draws none has no reason listed."""
    vut = sumo_vut(model)
    cfg = config_with("car_following", vut)
    random = model in ALWAYS_RANDOM_MODELS
    assert bool(vut.random_draws()) == random
    assert_one_vehicle(cfg, vec=not random)
    assert seed_dependent(cfg) == random  # the declaration matches SUMO


def seed_dependent(cfg: EnvConfig) -> bool:
    """Whether two SUMO seeds give other episodes on the same scenarios and actions."""
    policy = policy_for(cfg.case)
    scenarios = sample_initial_conditions(cfg.odd, 10, SCENARIO_SEED)
    runs = []
    for seed in (1, 2):
        env = make_env(cfg, sumo_seed=seed)
        try:
            runs.append(fields(run_episodes(env, policy, scenarios)))
        finally:
            env.close()
    return runs[0] != runs[1]


def test_sumo_defaults_that_draw_random_numbers_are_named() -> None:
    """A VUT left at SUMO's defaults draws random numbers (speedDev 0.1, Krauss's sigma 0.5),
    and the catalog names why; the runs then depend on SUMO's seed."""
    vut = VehicleType.from_mapping({"model": "Krauss", "params": {}}, "vuts.k")
    reasons = vut.random_draws()
    assert any(r.startswith("speedDev SUMO's default") for r in reasons)
    assert any(r.startswith("sigma SUMO's default") for r in reasons)
    assert seed_dependent(config_with("car_following", vut))
    assert acc_vut(1.5).random_draws() == ()


# --------------------------------------------------------------------------- drawn VUTs

VUT_DRAWS = st.one_of(
    st.builds(
        lambda model, asl, tau, decel, extra, gap, startup: sumo_vut(
            model,
            actionStepLength=asl,
            tau=tau,
            decel=decel,
            emergencyDecel=decel + extra,
            minGap=gap,
            startupDelay=startup,
        ),
        st.sampled_from(["IDM", "Krauss", "EIDM", "ACC", "CACC", "KraussPS", "IDMM"]),
        st.sampled_from([0.2, 0.4, 0.6, 1.0]),
        st.floats(0.5, 2.0),
        st.floats(3.0, 6.0),
        st.floats(0.0, 4.0),
        st.floats(1.0, 15.0),
        st.sampled_from([0.0, 0.5, 1.0]),
    ),
    st.builds(acc_vut, st.floats(0.8, 2.5)),
    st.sampled_from(["hwenv_pi1", "hwenv_pi2"]),
)


@settings(
    max_examples=30,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(vut=VUT_DRAWS, case=st.sampled_from(["car_following", "cut_in"]), slow=st.booleans())
def test_any_vut_the_catalog_accepts_is_one_vehicle(
    vut: VehicleType | str, case: str, slow: bool
) -> None:
    """``slow``: starts at 0-5 m/s (VUT) and 0-10 m/s (POV), where startupDelay acts."""
    if isinstance(vut, str):  # a built-in: highway-env's law
        cfg = dataclasses.replace(EnvConfig(case=case), vut=vut)  # type: ignore[arg-type]
    else:
        cfg = config_with(case, vut)
    if slow:
        odd = dataclasses.replace(cfg.odd, vut_speed_mps=(0.0, 5.0), pov_speed_mps=(0.0, 10.0))
        cfg = dataclasses.replace(cfg, odd=odd)
    assert_one_vehicle(cfg)


def test_an_action_step_makes_a_difference_the_paths_agree_on() -> None:
    """The regression of issue 21: an IDM VUT with a 1 s action step reacts late (it crashes
    where the same VUT deciding every step does not), identically on every path."""
    quick = assert_one_vehicle(config_with("car_following", sumo_vut("IDM", minGap=5.0)))
    late = assert_one_vehicle(
        config_with("car_following", sumo_vut("IDM", minGap=5.0, actionStepLength=1.0))
    )
    assert fields(quick) != fields(late)


def test_a_stochastic_vut_meets_the_same_numbers_in_outcome_and_crossplay() -> None:
    """Krauss with its default driver imperfection (sigma 0.5) and a random speed factor:
    the single env and N pairs draw other numbers, but the outcome stage and cross-play
    drive the same path on the same SUMO seed, so the diagonal is exact."""
    vut = VehicleType.from_mapping({"model": "Krauss", "params": {"speedDev": 0.1}}, "vuts.k")
    assert_one_vehicle(config_with("car_following", vut), vec=False)


# --------------------------------------------------------------------------- refusals


@pytest.mark.parametrize("asl", [0.1, 0.3, 0.5])
def test_an_action_step_sumo_would_round_is_refused(asl: float) -> None:
    with pytest.raises(ConfigError, match=r"env\.vuts\.x\.params\.actionStepLength must be a"):
        config_with("car_following", sumo_vut("IDM", actionStepLength=asl))


def test_an_action_step_for_the_pov_or_sumo_wide_is_refused() -> None:
    base = EnvConfig()
    pov = VehicleType.from_mapping(
        {"model": "Krauss", "params": {"actionStepLength": 0.4}}, "env.pov"
    )
    with pytest.raises(ConfigError, match=r"env\.pov\.params\.actionStepLength is not allowed"):
        dataclasses.replace(base, pov=pov)
    with pytest.raises(ConfigError, match=r"default\.action-step-length"):
        SimConfig(extra_args=("--default.action-step-length", "1.0"))
