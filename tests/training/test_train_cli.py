"""The train command as a person meets it: no silent default run, a resume that names what
differs (and ignores display options), Ctrl-C that says how to continue."""

from __future__ import annotations

import dataclasses
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from sumo_ayss.config import ExperimentConfig, to_dict
from sumo_ayss.run_folder import RunConfig, RunFolder, write_run_config
from sumo_ayss.train import main
from sumo_ayss.training.config_check import check_same_config, config_differences
from sumo_ayss.util.errors import CheckpointError
from tests.training.test_train import tiny_config


def test_train_without_config_refuses_and_names_the_paper_configs(tmp_path: Path) -> None:
    with pytest.raises(SystemExit) as info:
        main(["--out", str(tmp_path / "runs"), "--no-progress"])
    code = info.value.code
    assert isinstance(code, str) and code.startswith("error: --config: ")
    assert "configs/car_following.yaml" in code and "not the paper's configuration" in code
    assert not (tmp_path / "runs").exists()


def test_config_differences_name_the_field_and_skip_display_options() -> None:
    base = ExperimentConfig()
    quiet = dataclasses.replace(base, train=dataclasses.replace(base.train, progress_bar=False))
    assert config_differences(base, quiet) == []
    other = dataclasses.replace(quiet, agent=dataclasses.replace(base.agent, gamma=0.9))
    assert config_differences(base, other) == [f"agent.gamma: {base.agent.gamma!r} -> 0.9"]


def _stored_run(tmp_path: Path, cfg: ExperimentConfig, seed: int = 0) -> Path:
    run = tmp_path / "run"
    run.mkdir()
    write_run_config(RunFolder(run).config, RunConfig(cfg.env.vut, seed, to_dict(cfg)))
    return run


def test_resume_check_accepts_a_display_change_and_names_a_real_one(tmp_path: Path) -> None:
    cfg = ExperimentConfig()
    run = _stored_run(tmp_path, cfg)
    quiet = dataclasses.replace(cfg, train=dataclasses.replace(cfg.train, progress_bar=False))
    check_same_config(RunFolder(run), quiet, 0)  # --no-progress alone: allowed
    longer = dataclasses.replace(cfg, train=dataclasses.replace(cfg.train, total_timesteps=300_000))
    with pytest.raises(CheckpointError, match=r"train\.total_timesteps: 200000 -> 300000"):
        check_same_config(RunFolder(run), longer, 0)
    with pytest.raises(CheckpointError, match=r"seed: 0 -> 1"):
        check_same_config(RunFolder(run), cfg, 1)


@pytest.mark.sumo
def test_ctrl_c_prints_the_resume_command_not_a_traceback(tmp_path: Path) -> None:
    config = tiny_config(tmp_path, 6000, 300)
    out = tmp_path / "runs"
    args = ["--config", str(config), "--seed", "0", "--out", str(out)]
    cmd = [sys.executable, "-m", "sumo_ayss.train", *args]
    latest = out / "car_following" / "pi1" / "seed_0" / "checkpoints" / "latest.json"
    # A shell that starts the suite in the background (`cmd &`) makes SIGINT ignored, and a
    # child inherits that: give the trainer the default a person at a terminal has.
    proc = subprocess.Popen(
        cmd,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.default_int_handler),
    )
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and not latest.is_file():
            assert proc.poll() is None, "training ended before it could be interrupted"
            time.sleep(0.05)
        assert latest.is_file() and json.loads(latest.read_text())["step"] < 6000
        os.kill(proc.pid, signal.SIGINT)
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, err[-2000:]
    assert "Traceback" not in err
    assert "interrupted: training stopped" in err
    assert f"python -m sumo_ayss.train {' '.join(args)} --resume" in err
