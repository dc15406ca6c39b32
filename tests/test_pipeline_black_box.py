"""Black-box VUTs through the whole pipeline: a C FMU, a pythonfmu FMU and a process, each
trained against, evaluated, cross-played (its diagonal checked against its outcome table)
and reported; and a process that dies mid-job fails that job alone, keeping what it wrote."""

from __future__ import annotations

import json
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import yaml

from sumo_ayss.commands.pipeline import run_pipeline
from sumo_ayss.config import PROJECT_ROOT
from sumo_ayss.pipeline import load_pipeline
from tests.helpers import TINY_AGENT

ACC_INPUTS = {
    "v_ego": "speed_mps",
    "gap": "gap_m",
    "v_rel": "rel_speed_mps",
    "has_lead": "has_leader",
}


def fmu_vut(path: Path, time_gap_s: float) -> dict[str, Any]:
    return {
        "description": f"time-gap ACC FMU {path.name}, T = {time_gap_s} s",
        "fmu": {
            "path": str(path),
            "inputs": ACC_INPUTS,
            "outputs": {"acceleration_mps2": "a_cmd"},
            "parameters": {"time_gap_s": time_gap_s},
            "max_accel_mps2": 3.0,
            "max_decel_mps2": 6.0,
        },
    }


def process_vut(*args: str) -> dict[str, Any]:
    return {
        "description": "time-gap ACC behind the line protocol",
        "process": {
            "command": [sys.executable, *args],
            "signals": ["speed_mps", "gap_m", "rel_speed_mps", "has_leader"],
            "max_accel_mps2": 3.0,
            "max_decel_mps2": 6.0,
        },
    }


def write_configs(tmp_path: Path, vuts: dict[str, Any]) -> Path:
    exp = yaml.safe_load((PROJECT_ROOT / "configs" / "car_following.yaml").read_text())
    exp["agent"] = TINY_AGENT
    exp["train"].update(n_eval_scenarios=5)
    exp["env"]["vuts"] = vuts
    (tmp_path / "cf.yaml").write_text(yaml.safe_dump(exp))
    pipe = {
        "grid": {"cases": ["car_following"], "vuts": list(vuts), "seeds": [0]},
        "experiments": {"car_following": "cf.yaml"},
        "out": "runs",
        "total_timesteps": 400,
        "eval_every": 200,
        "evaluate": {"n_outcome": 10, "n_ayss": 500},
        "workers": 1,
    }
    path = tmp_path / "pipe.yaml"
    path.write_text(yaml.safe_dump(pipe))
    return path


@pytest.mark.sumo
def test_fmu_and_process_vuts_train_evaluate_crossplay_and_report(
    tmp_path: Path, c_fmu: Callable[[int], Path], py_fmu: Callable[[str], Path]
) -> None:
    client = str(PROJECT_ROOT / "examples" / "process_vut.py")
    vuts = {
        "acc_c": fmu_vut(c_fmu(3), 0.6),
        "acc_py": fmu_vut(py_fmu("acc"), 2.0),
        "acc_proc": process_vut(client, "--time-gap", "1.2"),
    }
    cfg = load_pipeline(write_configs(tmp_path, vuts))
    statuses, report, *_ = run_pipeline(cfg, live=False)
    assert [s.state for s in statuses] == ["done"] * 3, [s.error for s in statuses]
    case = cfg.out / "car_following"
    record = json.loads((case / "crossplay.json").read_text())  # the diagonal passed
    assert sorted(o["vut"] for o in record["opponents"]) == sorted(vuts)
    assert report is not None
    text = report.read_text(encoding="utf-8")
    assert all(name in text for name in vuts)
    run = yaml.safe_load((case / "acc_c" / "seed_0" / "config.yaml").read_text())
    assert run["env"]["vuts"]["acc_c"]["fmu"]["path"] == str(c_fmu(3))


@pytest.mark.sumo
@pytest.mark.slow  # 2 jobs, discriminability of 2 controller-kind VUTs: 1-2 min
def test_a_process_that_dies_mid_job_fails_that_job_and_keeps_the_others(tmp_path: Path) -> None:
    misbehave = str(PROJECT_ROOT / "tests" / "data" / "process" / "misbehave.py")
    vuts = {
        "dies": process_vut(misbehave, "--mode", "die", "--after", "150"),
        "acc_proc": process_vut(str(PROJECT_ROOT / "examples" / "process_vut.py")),
    }
    cfg = load_pipeline(write_configs(tmp_path, vuts))
    statuses, report, *_ = run_pipeline(cfg, live=False)
    by_vut = {s.spec.vut: s for s in statuses}
    assert by_vut["acc_proc"].state == "done"
    dead = by_vut["dies"]
    assert dead.state == "failed" and dead.attempts == 1  # a ControllerError: not retried
    assert "exited (code 3) before answering step" in (dead.error or "")
    assert "lost the sensor bus" in (dead.error or "")
    run = cfg.out / "car_following" / "dies" / "seed_0"
    assert (run / "config.yaml").is_file() and (run / "job.log").is_file()  # kept
    assert report is not None and report.is_file()
