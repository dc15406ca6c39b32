"""An FMU as the VUT: real FMUs built here (C against fmpy's FMI headers, and pythonfmu),
driven through SUMO; identical episodes to the same law as a Python controller; every bad
input a one-line error naming the FMU and the variable."""

from __future__ import annotations

import dataclasses
import math
import zipfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from sumo_ayss.util.errors import ConfigError, ControllerError
from sumo_ayss.vuts.catalog import VehicleType, controller_imports
from sumo_ayss.vuts.controllers import ControllerInput
from sumo_ayss.vuts.fmu_spec import FmuSpec
from tests.vuts.episodes import episodes, python_acc

ACC_INPUTS = {
    "v_ego": "speed_mps",
    "gap": "gap_m",
    "v_rel": "rel_speed_mps",
    "has_lead": "has_leader",
}


def acc_fmu(path: Path, time_gap_s: float = 2.0, **kw: Any) -> FmuSpec:
    kw.setdefault("outputs", {"acceleration_mps2": "a_cmd"})
    kw.setdefault("inputs", ACC_INPUTS)
    return FmuSpec(
        max_accel_mps2=3.0,
        max_decel_mps2=6.0,
        path=str(path),
        parameters={"time_gap_s": time_gap_s},
        **kw,
    )


def state(speed: float = 20.0, gap: float = 30.0, rel: float = -3.0) -> ControllerInput:
    return ControllerInput(0.0, 0.2, speed, gap, rel, 0)


# ------------------------------------------------------------------ identical episodes


@pytest.mark.sumo
@pytest.mark.parametrize("case", ["car_following", "cut_in"])
def test_c_fmus_and_the_python_controller_drive_identical_episodes(
    case: str, c_fmu: Callable[[int], Path]
) -> None:
    reference = episodes(python_acc(), case)
    assert any(min(s[3] for s in e[1:]) < -1.0 for e in reference)  # the ACC brakes
    assert episodes(acc_fmu(c_fmu(2)), case) == reference
    assert episodes(acc_fmu(c_fmu(3)), case) == reference


@pytest.mark.sumo
def test_pythonfmu_fmu_and_reset_modes_drive_identical_episodes(
    py_fmu: Callable[[str], Path], c_fmu: Callable[[int], Path]
) -> None:
    reference = episodes(python_acc(), "car_following")
    assert episodes(acc_fmu(py_fmu("acc")), "car_following") == reference
    assert episodes(acc_fmu(c_fmu(2), reset="reset"), "car_following") == reference


@pytest.mark.sumo
def test_a_commanded_speed_output_drives_the_same_law(c_fmu: Callable[[int], Path]) -> None:
    """``outputs: {speed_mps: v_cmd}``: v' = v + a·dt, read back as (v' - v)/dt (equal to
    the acceleration's episodes up to rounding)."""
    reference = episodes(python_acc(), "car_following", n=1)[0]
    by_speed = episodes(acc_fmu(c_fmu(2), outputs={"speed_mps": "v_cmd"}), "car_following", 1)[0]
    assert len(by_speed) == len(reference)
    for a, b in zip(reference[1:], by_speed[1:], strict=True):
        assert a[3] == pytest.approx(b[3], abs=1e-9)


# ------------------------------------------------------------------ time and reset


@pytest.mark.parametrize("mode", ["reinstantiate", "reset"])
def test_fmu_time_starts_at_zero_every_episode(mode: str, py_fmu: Callable[[str], Path]) -> None:
    spec = FmuSpec(
        max_accel_mps2=3.0,
        max_decel_mps2=6.0,
        path=str(py_fmu("probe")),
        inputs={"v": "speed_mps"},
        outputs={"acceleration_mps2": "a"},
        reset=mode,  # type: ignore[arg-type]
    )
    fmu = spec.build("vut")
    try:
        clocks = []
        for _ in range(2):
            fmu.reset()
            clocks.append([(fmu.acceleration(state()), _read(fmu, "fmu_time")) for _ in range(3)])
        assert clocks[0] == clocks[1] == [(0.0, pytest.approx(0.2 * k)) for k in (1, 2, 3)]
    finally:
        fmu.close()
        fmu.close()  # safe twice


def _read(fmu: Any, name: str) -> float:
    var = fmu._variables[name]
    return float(fmu._fmu.getReal([var.valueReference])[0])


def test_a_closed_fmu_reopens_at_the_next_episode(c_fmu: Callable[[int], Path]) -> None:
    fmu = acc_fmu(c_fmu(2)).build("vut")
    first = fmu.acceleration(state())
    fmu.close()
    with pytest.raises(ControllerError, match="after close"):
        fmu.acceleration(state())
    fmu.reset()
    assert fmu.acceleration(state()) == first
    fmu.close()


# ------------------------------------------------------------------ configuration


def test_fmu_vut_reads_from_yaml_relative_to_the_file_and_round_trips(tmp_path: Path) -> None:
    from sumo_ayss.config import load_experiment

    exp = tmp_path / "exp.yaml"
    exp.write_text(
        "env:\n  vut: acc\n  vuts:\n    acc:\n      fmu:\n        path: fmus/acc.fmu\n"
        "        inputs: {v_ego: speed_mps, gap: gap_m}\n"
        "        outputs: {acceleration_mps2: a_cmd}\n"
        "        parameters: {time_gap_s: 2.0}\n"
        "        max_accel_mps2: 3.0\n        max_decel_mps2: 6.0\n        call_deadline_s: 0.5\n"
    )
    vt = load_experiment(exp).env.vut_type
    assert isinstance(vt.controller, FmuSpec)
    assert vt.controller.path == str(tmp_path / "fmus" / "acc.fmu")
    assert vt.controller.call_deadline_s == 0.5
    data = vt.to_dict()
    assert set(data) == {"model", "params", "description", "fmu"}
    assert VehicleType.from_mapping(data, "x") == vt


@pytest.mark.parametrize(
    ("fmu", "match"),
    [
        (
            {"inputs": {"v": "speed"}},
            r"x\.fmu\.inputs\.v must name a signal .*did you mean 'speed_mps'",
        ),
        (
            {"outputs": {"accel": "a"}},
            r"x\.fmu\.outputs must have exactly one of \['acceleration_mps2'",
        ),
        ({"reset": "reboot"}, r"x\.fmu\.reset must be one of"),
        ({"max_decel_mps2": 0}, r"x\.fmu\.max_decel_mps2 must be > 0"),
        ({"call_deadline_s": -1}, r"x\.fmu\.call_deadline_s must be > 0"),
        ({"parameters": {"v": 1.0}}, r"both mapped to a signal .* and given a value"),
        ({"pth": "a.fmu"}, r"x\.fmu.*pth"),
    ],
)
def test_fmu_config_errors_name_the_field(fmu: dict[str, Any], match: str) -> None:
    base = {
        "path": "a.fmu",
        "inputs": {"v": "speed_mps"},
        "outputs": {"acceleration_mps2": "a"},
        "max_accel_mps2": 3.0,
        "max_decel_mps2": 6.0,
    }
    with pytest.raises(ConfigError, match=match):
        VehicleType.from_mapping({"fmu": {**base, **fmu}}, "x")


def test_a_vut_names_one_driver() -> None:
    fmu = {"path": "a.fmu", "inputs": {"v": "speed_mps"}, "outputs": {"speed_mps": "v"}}
    ctl = {"target": "m:C", "max_accel_mps2": 3.0, "max_decel_mps2": 6.0}
    with pytest.raises(
        ConfigError, match=r"x names \['controller', 'fmu'\]: a VUT is driven by one"
    ):
        VehicleType.from_mapping({"controller": ctl, "fmu": fmu}, "x")


def test_an_untrusted_run_folder_does_not_load_its_fmu(c_fmu: Callable[[int], Path]) -> None:
    with controller_imports(False), pytest.raises(ConfigError, match="--trust-controller"):
        acc_fmu(c_fmu(2)).build("env.vuts.acc.fmu")


# ------------------------------------------------------------------ bad FMUs: one-line errors


def _one_line(match: str, build: Callable[[], Any], error: type[Exception] = ConfigError) -> str:
    with pytest.raises(error, match=match) as info:
        built = build()
        built.reset()
        built.acceleration(state())
    message = str(info.value)
    assert "\n" not in message
    return message


def test_bad_fmu_files_are_one_line_errors(tmp_path: Path, c_fmu: Callable[[int], Path]) -> None:
    from examples.fmu.build_fmu import build_acc_fmu

    text = tmp_path / "notes.fmu"
    text.write_text("not a zip")
    _one_line(r"FMU 'notes.fmu' is not an FMU: an FMU is a zip archive", acc_fmu(text).build)
    _one_line(r"no FMU file at", acc_fmu(tmp_path / "missing.fmu").build)
    me = build_acc_fmu(tmp_path / "me.fmu", 2, interface="ModelExchange")
    _one_line(
        r"FMU 'me.fmu' has no co-simulation interface \(only \['modelExchange'\]\)",
        acc_fmu(me).build,
    )
    v1 = build_acc_fmu(tmp_path / "v1.fmu", 1)
    _one_line(r"FMU 'v1.fmu' is FMI 1.0; supported: FMI 2.0 and 3.0", acc_fmu(v1).build)
    bare = build_acc_fmu(tmp_path / "bare.fmu", 2, binary=False)
    _one_line(r"FMU 'bare.fmu' has no binary for this platform \(binaries/", acc_fmu(bare).build)
    broken = tmp_path / "broken.fmu"
    with zipfile.ZipFile(broken, "w") as zf:
        zf.writestr("modelDescription.xml", "<fmiModelDescription")
    _one_line(r"FMU 'broken.fmu' has no readable modelDescription\.xml", acc_fmu(broken).build)


@pytest.mark.parametrize(
    ("change", "match"),
    [
        (
            {"inputs": {**ACC_INPUTS, "v_eg0": "speed_mps"}},
            r"inputs\.v_eg0: FMU 'acc_fmi2\.fmu' has no variable 'v_eg0'; "
            r"its input variables: \['gap', 'has_lead', 'v_ego', 'v_rel'\]",
        ),
        (
            {"inputs": {**ACC_INPUTS, "a_cmd": "speed_mps"}},
            r"inputs\.a_cmd: .* variable 'a_cmd' has causality 'output', not 'input'",
        ),
        (
            {"inputs": {**ACC_INPUTS, "has_lead": "speed_mps"}},
            r"inputs\.has_lead: .* input 'has_lead' is Boolean; "
            r"signal 'speed_mps' \(real\) feeds \['Real'\]",
        ),
        (
            {"inputs": {"v_ego": "speed_mps"}},
            r"inputs: .* inputs \['gap', 'has_lead', 'v_rel'\] are not mapped",
        ),
        (
            {"outputs": {"acceleration_mps2": "gap_gain"}},
            r"outputs: .* variable 'gap_gain' has causality 'parameter', not 'output'",
        ),
        (
            {"parameters": {"time_gap_s": "2 s"}},
            r"parameters\.time_gap_s: .* variable 'time_gap_s' is Real, got '2 s'",
        ),
        ({"parameters": {"tau": 1.0}}, r"parameters\.tau: .* has no variable 'tau'"),
    ],
)
def test_mapping_errors_name_the_fmu_and_the_variable(
    change: dict[str, Any], match: str, c_fmu: Callable[[int], Path]
) -> None:
    spec = dataclasses.replace(acc_fmu(c_fmu(2)), **change)
    _one_line(r"vut\." + match, lambda: spec.build("vut"))


def test_a_boolean_output_is_refused(py_fmu: Callable[[str], Path]) -> None:
    spec = FmuSpec(
        max_accel_mps2=3.0,
        max_decel_mps2=6.0,
        path=str(py_fmu("probe")),
        inputs={"v": "speed_mps"},
        outputs={"acceleration_mps2": "flag"},
    )
    _one_line(
        r"output 'flag' is Boolean; the command must be a real number", lambda: spec.build("vut")
    )


@pytest.mark.parametrize(
    ("parameters", "match"),
    [
        (
            {"nan_at_call": 2},
            r"FMU 'Probe\.fmu': output 'a' is nan after the step at FMU time 0\.2 s",
        ),
        (
            {"fail_at_call": 1},
            r"FMU 'Probe\.fmu': fmi2DoStep failed with status 2 \(discard\) at FMU time 0 s",
        ),
    ],
)
def test_step_failures_and_nan_outputs_stop_the_run(
    parameters: dict[str, int], match: str, py_fmu: Callable[[str], Path]
) -> None:
    from sumo_ayss.vuts.controllers import ControlledVut

    spec = FmuSpec(
        max_accel_mps2=3.0,
        max_decel_mps2=6.0,
        path=str(py_fmu("probe")),
        inputs={"v": "speed_mps"},
        outputs={"acceleration_mps2": "a"},
        parameters=parameters,
    )
    fmu = spec.build("vut")

    class Pair:  # what ControlledVut needs of a pair, without SUMO
        def vut_sensing(self, _range: float) -> Any:
            from sumo_ayss.sim.pair import VutSensing

            return VutSensing(0.0, 20.0, 0, math.inf, math.nan)

        def command_vut_speed(self, _v: float) -> None:
            pass

    driver = ControlledVut(fmu, spec, 0.2)
    with pytest.raises(ControllerError, match=match) as info:
        for _ in range(3):
            driver.before_step(Pair())  # type: ignore[arg-type]
    assert "\n" not in str(info.value)
    fmu.close()
