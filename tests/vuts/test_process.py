"""An external process as the VUT: the reference client drives episodes identical to the
Python controller; a process that dies, answers late, answers garbage or never answers is
a one-line error naming it."""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path
from typing import Any

import pytest

from sumo_ayss.config import PROJECT_ROOT
from sumo_ayss.util.errors import ConfigError, ControllerError
from sumo_ayss.vuts.catalog import VehicleType, controller_imports
from sumo_ayss.vuts.controllers import ControllerInput
from sumo_ayss.vuts.process import format_value
from sumo_ayss.vuts.process_spec import ProcessSpec
from tests.vuts.episodes import episodes, python_acc

CLIENT = str(PROJECT_ROOT / "examples" / "process_vut.py")
MISBEHAVE = str(PROJECT_ROOT / "tests" / "data" / "process" / "misbehave.py")


def acc_process(time_gap_s: float = 2.0, **kw: Any) -> ProcessSpec:
    return ProcessSpec(
        max_accel_mps2=3.0,
        max_decel_mps2=6.0,
        command=(sys.executable, CLIENT, "--time-gap", str(time_gap_s)),
        signals=("speed_mps", "gap_m", "rel_speed_mps", "has_leader"),
        **kw,
    )


def misbehaving(mode: str, **kw: Any) -> ProcessSpec:
    kw.setdefault("call_deadline_s", 0.5)
    kw.setdefault("start_timeout_s", 0.5)
    return ProcessSpec(
        max_accel_mps2=3.0,
        max_decel_mps2=6.0,
        command=(sys.executable, MISBEHAVE, "--mode", mode),
        **kw,
    )


STATE = ControllerInput(0.0, 0.2, 20.0, 30.0, -3.0, 0)


@pytest.mark.sumo
def test_reference_client_drives_episodes_identical_to_the_python_controller() -> None:
    assert episodes(acc_process(), "cut_in") == episodes(python_acc(), "cut_in")


def test_values_are_written_exactly() -> None:
    assert [format_value(v) for v in (0.1 + 0.2, math.inf, 3, True, False)] == [
        "0.30000000000000004",
        "inf",
        "3",
        "1",
        "0",
    ]


@pytest.mark.parametrize(
    ("mode", "match"),
    [
        (
            "die",
            r"process '.*misbehave\.py --mode die' exited \(code 3\) before answering step; "
            r"its last stderr: lost the sensor bus",
        ),
        ("hang", r"no answer to step within 0\.5 s \(call_deadline_s\); the process was stopped"),
        (
            "garbage",
            r"answered 'accelerate please' to step; protocol sumo_ayss-vut 1 expects "
            r"'accel <number>'",
        ),
        ("error", r"reported an error at step: radar blinded"),
    ],
)
def test_a_misbehaving_process_is_a_one_line_error(mode: str, match: str) -> None:
    vut = misbehaving(mode).build("vut")
    try:
        vut.reset()
        assert vut.acceleration(STATE) == 0.5  # two good steps, then the fault
        assert vut.acceleration(STATE) == 0.5
        start = time.monotonic()
        with pytest.raises(ControllerError, match=match) as info:
            vut.acceleration(STATE)
        assert "\n" not in str(info.value)
        assert time.monotonic() - start < 3.0  # a hung process is not waited for
        assert vut._live() is None  # stopped
    finally:
        vut.close()


@pytest.mark.parametrize(
    ("spec", "match"),
    [
        (
            misbehaving("silent"),
            r"vut: process .* no answer to the hello within 0\.5 s "
            r"\(start_timeout_s\)",
        ),
        (misbehaving("version"), r"vut: process .* reported an error at the hello: version 1"),
        (
            ProcessSpec(max_accel_mps2=3.0, max_decel_mps2=6.0, command=("no-such-vut-binary",)),
            r"vut\.command: cannot start process 'no-such-vut-binary' \(FileNotFoundError",
        ),
    ],
)
def test_a_process_that_cannot_start_is_a_one_line_config_error(
    spec: ProcessSpec, match: str
) -> None:
    with pytest.raises(ConfigError, match=match) as info:
        spec.build("vut")
    assert "\n" not in str(info.value)


def test_instances_of_one_config_share_one_process() -> None:
    """The pairs of a vectorised env: one process, one instance number k each."""
    first, second = acc_process().build("vut"), acc_process().build("vut")
    conn = first._conn
    assert conn is not None and second._conn is conn and (first._k, second._k) == (0, 1)
    first.reset()
    second.reset()
    assert first.acceleration(STATE) == second.acceleration(STATE)
    proc = conn.proc
    assert proc is not None
    first.close()
    assert proc.poll() is None  # still serving the second
    second.close()
    assert proc.wait(timeout=5) == 0  # quit on the last close


def test_a_closed_process_restarts_at_the_next_episode() -> None:
    vut = acc_process().build("vut")
    first = vut.acceleration(STATE)
    vut.close()
    vut.reset()
    assert vut.acceleration(STATE) == first
    vut.close()
    vut.close()


def test_process_vut_config_reads_relative_to_the_yaml_and_round_trips(tmp_path: Path) -> None:
    from sumo_ayss.config import load_experiment

    exp = tmp_path / "exp.yaml"
    exp.write_text(
        "env:\n  vut: p\n  vuts:\n    p:\n      process:\n"
        "        command: [python, client.py]\n        signals: [speed_mps, gap_m]\n"
        "        max_accel_mps2: 3.0\n        max_decel_mps2: 6.0\n"
    )
    vt = load_experiment(exp).env.vut_type
    assert isinstance(vt.controller, ProcessSpec) and vt.controller.cwd == str(tmp_path)
    assert VehicleType.from_mapping(vt.to_dict(), "x") == vt
    with pytest.raises(ConfigError, match=r"x\.process\.signals\[1\] must name a signal"):
        VehicleType.from_mapping(
            {"process": {**vt.to_dict()["process"], "signals": ["speed_mps", "gapp"]}}, "x"
        )
    with controller_imports(False), pytest.raises(ConfigError, match="--trust-controller"):
        vt.controller.build("x")


def test_the_object_list_is_offered_by_slot() -> None:
    from sumo_ayss.sim.pair import SensedObject
    from sumo_ayss.vuts.signals import SIGNALS

    pov = SensedObject(-2.0, 2.1, -1.5, -0.6, 5.0, 1.8)
    seen = ControllerInput(0.0, 0.2, 20.0, math.inf, 0.0, 0, (pov,), 3.2)
    values = {
        name: SIGNALS[name].read(seen)
        for name in ("n_objects", "objects.0.present", "objects.0.gap_m",
                     "objects.0.lateral_offset_m", "objects.0.lateral_speed_mps",
                     "objects.1.present", "objects.1.gap_m", "lane_width_m")
    }  # fmt: skip
    assert values == {
        "n_objects": 1,
        "objects.0.present": True,
        "objects.0.gap_m": -2.0,
        "objects.0.lateral_offset_m": 2.1,
        "objects.0.lateral_speed_mps": -0.6,
        "objects.1.present": False,
        "objects.1.gap_m": math.inf,
        "lane_width_m": 3.2,
    }
    line = " ".join(format_value(SIGNALS[n].read(seen)) for n in ("objects.0.gap_m", "n_objects"))
    assert line == "-2.0 1"
