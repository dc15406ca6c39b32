"""Resume is exact: a run killed anywhere and resumed equals the uninterrupted run.

The kill is simulated in-process by a BaseException raised from SB3's step callback (the
files on disk are then exactly what a SIGKILL at that step leaves, every write being
atomic); ``tests/training/test_train.py`` kills a real process. Compared: every eval.csv
row (but its wall-clock time) and the selected SPCP.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
import yaml

from sumo_ayss.config import ExperimentConfig, load_experiment
from sumo_ayss.run_folder import read_eval_table
from sumo_ayss.train import train
from sumo_ayss.training.callback import CandidateCallback
from tests.helpers import TINY_AGENT

pytestmark = pytest.mark.sumo


class _Killed(BaseException):
    """Stands for SIGKILL: not an Exception, so nothing on the way catches it."""


def _config(
    tmp_path: Path, n_envs: int = 1, total: int = 630, every: int = 210
) -> ExperimentConfig:
    data = {
        "agent": {**TINY_AGENT, "learning_starts": 64, "batch_size": 32},
        "train": {
            "total_timesteps": total,
            "eval_every": every,
            "n_eval_scenarios": 4,
            "progress_bar": False,
            "n_envs": n_envs,
        },
    }
    path = tmp_path / f"exp_{n_envs}.yaml"
    path.write_text(yaml.safe_dump(data))
    return load_experiment(path)


def _rows(run: Path) -> list[dict[str, Any]]:
    return [
        {k: v for k, v in r.items() if k != "wall_s"} for r in read_eval_table(run / "eval.csv")
    ]


def _spcp(run: Path) -> tuple[Any, Any]:
    data = json.loads((run / "spcp.json").read_text())
    return data["step"], data["checkpoint"]


def _killed_then_resumed(
    cfg: ExperimentConfig, out: Path, kill_at: int, monkeypatch: pytest.MonkeyPatch
) -> Path:
    original = CandidateCallback._on_step

    def on_step(self: CandidateCallback) -> bool:
        if self.num_timesteps >= kill_at:
            raise _Killed
        return original(self)

    with monkeypatch.context() as m:
        m.setattr(CandidateCallback, "_on_step", on_step)
        with pytest.raises(_Killed):
            train(cfg, seed=0, out=out)
    return train(cfg, seed=0, out=out, resume=True)


def _assert_same_run(run: Path, reference: Path) -> None:
    got, want = _rows(run), _rows(reference)
    assert [r["step"] for r in got] == [r["step"] for r in want]
    for a, b in zip(got, want, strict=True):
        assert a.pop("checkpoint") == b.pop("checkpoint")
        assert a == pytest.approx(b, rel=1e-6, abs=1e-9), (a, b)
    assert _spcp(run) == _spcp(reference)


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory) -> Path:
    tmp = tmp_path_factory.mktemp("reference")
    return train(_config(tmp), seed=0, out=tmp / "runs")


def test_resume_after_a_kill_between_candidate_and_checkpoint_is_exact(
    reference: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A kill right after the second candidate's evaluation, before its checkpoint."""
    steps = [r["step"] for r in _rows(reference)]
    run = _killed_then_resumed(_config(tmp_path), tmp_path / "runs", steps[1] + 1, monkeypatch)
    _assert_same_run(run, reference)


@pytest.mark.slow
@pytest.mark.parametrize("kill_at", [50, 150, 226, 263, 437, 629])
def test_resume_after_a_kill_anywhere_is_exact(
    reference: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, kill_at: int
) -> None:
    run = _killed_then_resumed(_config(tmp_path), tmp_path / "runs", kill_at, monkeypatch)
    _assert_same_run(run, reference)


@pytest.mark.slow
def test_resume_of_pairs_in_one_simulation_is_exact(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    cfg = _config(tmp_path, n_envs=2)
    ref = train(cfg, seed=0, out=tmp_path / "ref")
    run = _killed_then_resumed(cfg, tmp_path / "runs", 330, monkeypatch)
    _assert_same_run(run, ref)


def test_leftovers_of_a_killed_checkpoint_are_cleaned_up(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    cfg = _config(tmp_path, total=400, every=200)
    out = tmp_path / "runs"
    original = CandidateCallback._on_step

    def on_step(self: CandidateCallback) -> bool:
        if self.num_timesteps >= 300:
            raise _Killed
        return original(self)

    with monkeypatch.context() as m:
        m.setattr(CandidateCallback, "_on_step", on_step)
        with pytest.raises(_Killed):
            train(cfg, seed=0, out=out)
    run = out / "car_following" / "pi1" / "seed_0"
    latest = json.loads((run / "checkpoints" / "latest.json").read_text())["dir"]
    # What a kill during a write leaves: temporary files, and a candidate folder that
    # latest.json does not reach yet.
    leftovers = [
        run / "checkpoints" / latest / ".replay.4242.tmp.pkl",
        run / "checkpoints" / latest / ".state.json.4242.tmp",
        run / ".eval.csv.4242.tmp",
    ]
    for path in leftovers:
        path.write_bytes(b"half")
    orphan = run / "checkpoints" / "step_000000299"
    orphan.mkdir()
    (orphan / "model.zip").write_bytes(b"half")
    train(cfg, seed=0, out=out, resume=True)
    assert not any(p.exists() for p in leftovers)
    assert not orphan.exists()
    assert not list(run.rglob("*.tmp*"))
    assert [r["step"] for r in _rows(run)] == [200, 400]
