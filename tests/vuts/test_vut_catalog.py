"""Every SUMO car-following model as a VUT: the catalog matches SUMO 1.28, bad values are
refused with their range, and each model drives an episode of both envs.

The SUMO checks run the ``sumo`` binary of the pip package on tiny files (a few ms each) or
one short env episode per (model, case).
"""

from __future__ import annotations

import math
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

from sumo_ayss.config import EnvConfig
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.util.errors import ConfigError
from sumo_ayss.vuts.catalog import (
    COMMON_PARAMS,
    MODEL_PARAMS,
    PARAM_SPECS,
    REQUIRED_PARAMS,
    VehicleType,
)

ALL_PARAMS = COMMON_PARAMS.union(*MODEL_PARAMS.values())
MODELS = sorted(MODEL_PARAMS)
#: Lanes of each case's built-in road (the CC model must be told).
LANES = {"car_following": 1, "cut_in": 2}
#: SUMO stores speedDev inside its speedFactor distribution, not as an attribute of its own.
NOT_ECHOED = frozenset({"speedDev"})


def valid_value(name: str) -> float:
    """A value inside the parameter's allowed range (1 where the range allows it)."""
    spec = PARAM_SPECS[name]
    if spec.integer:
        low = 1.0 if spec.low is None else spec.low + (1.0 if spec.low_open else 0.0)
        return 2.0 if spec.high is None and low < 2.0 else low
    if spec.low is not None and spec.high is not None:
        return 0.5 * (spec.low + spec.high)
    if spec.high is not None:
        return spec.high - 1.0
    return 1.0 if spec.low is None or spec.low < 1.0 else spec.low + 1.0


def sumo_vtype_run(
    tmp_path: Path, model: str, attrs: dict[str, float]
) -> subprocess.CompletedProcess[str]:
    """Load one vType (and a vehicle of it) in ``sumo`` for 1 s and save the state at 0.4 s."""
    from sumo_ayss.sim.network import network_path, sumo_binary

    text = " ".join(f'{k}="{v!r}"' for k, v in sorted(attrs.items()))
    (tmp_path / "t.add.xml").write_text(
        f'<additional><vType id="t" carFollowModel="{model}" {text}/>'
        '<route id="r" edges="road"/><vehicle id="v" type="t" route="r" depart="0"/>'
        "</additional>\n"
    )
    cmd = [
        str(sumo_binary("sumo")),
        "--net-file", str(network_path("cut_in")),
        "--additional-files", "t.add.xml",
        "--step-length", "0.2",
        "--end", "1",
        "--save-state.times", "0.4",
        "--save-state.files", "state.xml",
        "--no-step-log", "true",
        "--no-warnings", "true",
    ]  # fmt: skip
    return subprocess.run(cmd, cwd=tmp_path, capture_output=True, text=True, timeout=60)


# --------------------------------------------------------------------------- the tables


def test_every_parameter_has_unit_meaning_and_range() -> None:
    assert set(PARAM_SPECS) == ALL_PARAMS
    for name, spec in PARAM_SPECS.items():
        assert spec.unit and spec.meaning, name
        assert spec.violation(valid_value(name)) is None, name
    assert "IIDM" not in MODEL_PARAMS and "SKOrig" not in MODEL_PARAMS  # not SUMO models
    assert {"CC", "W99", "EIDM", "ACC", "CACC", "Krauss", "IDM"} <= set(MODEL_PARAMS)


@pytest.mark.sumo
@pytest.mark.parametrize("model", MODELS)
def test_sumo_reads_exactly_the_catalog_parameters(model: str, tmp_path: Path) -> None:
    """Give SUMO every parameter of every model: it keeps exactly this model's (1.28)."""
    attrs = {name: valid_value(name) for name in ALL_PARAMS}
    attrs["emergencyDecel"] = attrs["decel"]  # >= decel
    result = sumo_vtype_run(tmp_path, model, attrs)
    assert result.returncode == 0, result.stderr
    root = ET.parse(tmp_path / "state.xml").getroot()
    vtype = next(v for v in root.iter("vType") if v.get("id") == "t")
    kept = set(vtype.attrib) & ALL_PARAMS
    assert kept == (COMMON_PARAMS | MODEL_PARAMS[model]) - NOT_ECHOED


def sumo_refused_cases() -> list[tuple[str, str, float]]:
    """(model, parameter, value) for every range SUMO itself enforces, just outside it."""
    cases = []
    for name, spec in sorted(PARAM_SPECS.items()):
        if spec.source != "SUMO":
            continue
        model = next((m for m in MODELS if name in MODEL_PARAMS[m]), "Krauss")
        bad = (spec.high + 0.5) if spec.high is not None else (spec.low or 0.0) - 1.0
        if spec.low_open and spec.low is not None:
            bad = spec.low  # the bound itself
        cases.append((model, name, bad))
    return cases


@pytest.mark.sumo
@pytest.mark.parametrize(("model", "name", "bad"), sumo_refused_cases())
def test_ranges_marked_sumo_are_refused_by_sumo_too(
    model: str, name: str, bad: float, tmp_path: Path
) -> None:
    attrs = dict.fromkeys(REQUIRED_PARAMS.get(model, ()), 2.0) | {name: bad}
    result = sumo_vtype_run(tmp_path, model, attrs)
    assert result.returncode != 0 and "Error" in result.stderr, (name, bad, result.stderr)
    with pytest.raises(ConfigError, match=rf"vut\.params\.{name} must be .*allowed: "):
        VehicleType(model, attrs).validate("vut")


# --------------------------------------------------------------------------- refusals


@pytest.mark.parametrize(
    ("model", "params", "match"),
    [
        ("Krauss", {"sigma": 1.5}, r"sigma must be in \[0, 1\], got 1\.5; allowed: \[0, 1\] -"),
        ("IDM", {"delta": 0}, r"delta must be > 0, got 0; allowed: \(0, inf\) -"),
        ("IDM", {"tau": -1.0}, r"tau must be > 0, got -1\.0; allowed: \(0, inf\) s"),
        ("W99", {"cc1": 0.0}, r"cc1 must be > 0, got 0\.0; allowed: \(0, inf\) s"),
        ("W99", {"cc8": -2}, r"cc8 must be > 0, got -2; allowed: \(0, inf\) m/s²"),
        ("W99", {"cc2": -1}, r"cc2 must be >= 0, got -1; allowed: \[0, inf\) m"),
        ("EIDM", {"ccoolness": 2}, r"ccoolness must be in \[0, 1\]"),
        ("EIDM", {"maxvehpreview": 2.5}, r"maxvehpreview must be an integer.*integers in \[1"),
        ("EIDM", {"jerkmax": 0}, r"jerkmax must be > 0.*m/s³"),
        ("PWagner2009", {"apProb": 1.1}, r"apProb must be in \[0, 1\]"),
        ("CC", {"lanesCount": 0}, r"lanesCount must be >= 1, got 0"),
        ("CC", {}, r"vut\.params\.lanesCount is required by SUMO model CC"),
        ("IDM", {"sigma": 0.5}, r"sigma is not a parameter of SUMO model IDM"),
        ("IDMM", {"delta": 4}, r"delta is not a parameter of SUMO model IDMM"),
        ("ACC", {"speedControlGainSpeed": 1}, r"did you mean 'speedControlGain"),
        ("Rail", {}, r"Rail is a train model"),
        ("IIDM", {}, r"model must be one of .*got 'IIDM'"),
        ("IDM", {"accel": math.inf}, r"accel must be finite"),
    ],
)
def test_invalid_parameter_is_refused_with_its_range(
    model: str, params: dict[str, float], match: str
) -> None:
    with pytest.raises(ConfigError, match=match):
        VehicleType(model, params).validate("vut")


def test_env_config_refuses_a_bad_vut_by_its_field() -> None:
    with pytest.raises(ConfigError, match=r"env\.vuts\.x\.params\.sigma must be in \[0, 1\]"):
        EnvConfig(vut="x", vuts={"x": VehicleType("KraussPS", {"sigma": -0.1})})


# --------------------------------------------------------------------------- episodes


def model_params(model: str, case: str) -> dict[str, float]:
    return {"lanesCount": float(LANES[case])} if model in REQUIRED_PARAMS else {}


@pytest.mark.sumo
@pytest.mark.parametrize("case", ["car_following", "cut_in"])
@pytest.mark.parametrize("model", MODELS)
def test_model_drives_an_episode(model: str, case: str) -> None:
    """One episode with SUMO's default parameters of ``model`` as the VUT.

    Car-following: the POV brakes towards half its speed (action 1) for the whole episode.
    Cut-in: the POV cuts in 8 m ahead, then holds 20 m/s. Sane = SUMO runs without error,
    every observation is finite and inside the observation space, the VUT's speed stays in
    [0, 50] m/s and its acceleration is finite; in car-following the VUT brakes.
    """
    cfg = EnvConfig(case=case, vut="x", vuts={"x": VehicleType(model, model_params(model, case))})  # type: ignore[arg-type]
    env_id = "sumo_ayss/CarFollowing-v0" if case == "car_following" else "sumo_ayss/CutIn-v0"
    env = gym.make(env_id, config=cfg, sumo_seed=7)
    try:
        obs, _ = env.reset(options={"initial_condition": InitialCondition(20.0, 22.0, 8.0)})
        assert env.observation_space.contains(obs)
        actions = [1] * 25 if case == "car_following" else [0] + [21] * 24
        accels = []
        for action in actions:
            obs, reward, terminated, truncated, info = env.step(action)
            assert np.all(np.isfinite(obs)) and env.observation_space.contains(obs), obs
            assert math.isfinite(float(reward)) and math.isfinite(info["vut_accel_mps2"])
            assert 0.0 <= obs[1] <= 50.0
            accels.append(info["vut_accel_mps2"])
            if terminated or truncated:
                break
        assert terminated or truncated
        if case == "car_following":
            assert min(accels) < 0.0, "the VUT never reacted to its braking leader"
    finally:
        env.close()
