"""Training runs end to end with real SUMO: run folder, candidates, selection, resume."""

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
import yaml

from sumo_ayss.config import load_experiment
from sumo_ayss.run_folder import read_eval_table
from sumo_ayss.train import train
from sumo_ayss.training.selection import select_spcp
from sumo_ayss.util.errors import CheckpointError
from tests.helpers import TINY_AGENT

pytestmark = pytest.mark.sumo

#: A tiny learner so that tests spend their time in the machinery, not in gradient steps.
TINY = {"agent": TINY_AGENT, "train": {"n_eval_scenarios": 10, "progress_bar": False}}


def tiny_config(tmp_path: Path, total: int, every: int) -> Path:
    data = json.loads(json.dumps(TINY))
    data["train"].update(total_timesteps=total, eval_every=every)
    path = tmp_path / "tiny.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def test_train_writes_a_complete_run_folder(tmp_path: Path) -> None:
    cfg = load_experiment(tiny_config(tmp_path, 600, 200)).with_vut("pi2")
    run = train(cfg, seed=3, out=tmp_path / "runs", argv=["--seed", "3"])
    assert run == tmp_path / "runs" / "car_following" / "pi2" / "seed_3"
    for name in ("config.yaml", "command.txt", "versions.json", "seeds.json", "eval.csv"):
        assert (run / name).is_file(), name
    rows = read_eval_table(run / "eval.csv")
    assert len(rows) == 3
    assert [r["step"] for r in rows] == sorted(r["step"] for r in rows)
    assert all(r["n_episodes"] == 10 for r in rows)
    spcp = json.loads((run / "spcp.json").read_text())
    assert spcp["step"] == select_spcp(rows).step  # the argmax of the table on disk
    assert (run / "spcp.zip").is_file()
    resolved = yaml.safe_load((run / "config.yaml").read_text())
    assert resolved["env"]["vut"] == "pi2" and resolved["seed"] == 3
    assert "vut" not in resolved  # the VUT is written once, as env.vut
    assert resolved["agent"]["feature_net_arch"] == [32]
    versions = json.loads((run / "versions.json").read_text())
    assert versions["libsumo"] == "1.28.0"
    assert list((run / "tb").rglob("events.out.tfevents.*"))
    with pytest.raises(CheckpointError, match="already holds a run"):
        train(cfg, seed=3, out=tmp_path / "runs")


def test_resume_with_another_config_is_refused(tmp_path: Path) -> None:
    cfg = load_experiment(tiny_config(tmp_path, 400, 200))
    train(cfg, seed=0, out=tmp_path / "runs")
    with pytest.raises(CheckpointError, match="differs from the requested configuration"):
        other = dataclasses.replace(cfg, agent=dataclasses.replace(cfg.agent, gamma=0.9))
        train(other, seed=0, out=tmp_path / "runs", resume=True)


def test_sigkilled_training_resumes_and_keeps_earlier_candidates(tmp_path: Path) -> None:
    config = tiny_config(tmp_path, 2400, 300)
    out = tmp_path / "runs"
    cmd = [sys.executable, "-m", "sumo_ayss.train", "--config", str(config), "--seed", "0"]
    cmd += ["--out", str(out), "--no-progress"]
    run = out / "car_following" / "pi1" / "seed_0"
    latest = run / "checkpoints" / "latest.json"
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            if latest.is_file() and json.loads(latest.read_text())["step"] >= 900:
                break
            assert proc.poll() is None, "training ended before it could be killed"
            time.sleep(0.05)
        os.kill(proc.pid, signal.SIGKILL)
    finally:
        proc.wait()
    assert proc.returncode == -signal.SIGKILL
    before = {p: p.read_bytes() for p in run.glob("checkpoints/step_*/model.zip")}
    killed_at = json.loads(latest.read_text())["step"]
    assert not (run / "spcp.json").exists()

    done = subprocess.run([*cmd, "--resume"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    rows = read_eval_table(run / "eval.csv")
    steps = [r["step"] for r in rows]
    # The resumed run ends where the uninterrupted one would (tests/training/test_resume_exact.py).
    assert steps == sorted(set(steps)) and steps[-1] == 2400
    assert len(rows) == 8  # one candidate per 300 steps, none lost, none doubled
    for path, data in before.items():  # candidates written before the kill are kept as-is
        assert path.read_bytes() == data
    assert any(s <= killed_at for s in steps) and (run / "spcp.json").is_file()
    replay_files = list(run.glob("checkpoints/step_*/replay.pkl"))
    assert len(replay_files) == 1  # only the latest checkpoint keeps a replay buffer
