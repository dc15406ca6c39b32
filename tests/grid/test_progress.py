"""Grid progress read from run folders: events, rates, ETA and a table whose units survive."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest

from sumo_ayss.config import ExperimentConfig, TrainConfig
from sumo_ayss.grid.progress import GridProgress, JobStatus, format_duration
from sumo_ayss.run_folder import RunFolder, read_run, write_eval_table, write_progress


@dataclass(frozen=True)
class Spec:
    name: str
    run_dir: Path
    experiment: ExperimentConfig = field(
        default_factory=lambda: ExperimentConfig(train=TrainConfig(total_timesteps=10_000))
    )

    @property
    def folder(self) -> RunFolder:
        return RunFolder(self.run_dir)


def _write(path: Path, data: dict[str, Any]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(data))


def _grid(tmp_path: Path, n: int) -> list[JobStatus]:
    return [
        JobStatus(Spec(f"car_following/pi1/seed_{k}", tmp_path / f"seed_{k}")) for k in range(n)
    ]


def test_events_from_run_folder_files(tmp_path: Path) -> None:
    statuses = _grid(tmp_path, 3)
    progress = GridProgress(statuses, workers=2)
    job = statuses[0]
    job.start()
    assert progress.poll() == []
    job.spec.run_dir.mkdir(parents=True)
    row = {
        "step": 5000,
        "mean_return": 11.8312,
        "std_return": 2.0,
        "crash_rate": 0.0,
        "lane_change_rate": 0.0,
        "mean_final_headway_m": 2.1,
        "n_episodes": 10,
        "wall_s": 1.5,
        "checkpoint": "checkpoints/step_000005000/model.zip",
    }
    write_eval_table(job.spec.run_dir / "eval.csv", [row])
    write_progress(job.spec.run_dir, "train", step=5200, total=10_000, rate_steps_per_s=100.0)
    events = progress.poll()
    assert len(events) == 1 and events[0].endswith(
        "seed_0: SPCP candidate at step 5,000/10,000 (100 steps/s): mean evaluation reward 11.83"
    )
    assert "0/3 done, 1 running, 2 queued, 0 failed" in events[0]
    assert (job.step, job.rate_steps_per_s) == (5200, 100.0)
    write_progress(job.spec.run_dir, "evaluate")
    (job.spec.run_dir / "spcp.json").write_text("{}")
    assert progress.poll()[0].endswith("training finished; evaluating")
    assert progress.poll() == []  # each event once


def test_stale_progress_file_of_an_earlier_invocation_is_ignored(tmp_path: Path) -> None:
    [job] = _grid(tmp_path, 1)
    _write(
        RunFolder(job.spec.run_dir).progress,
        {"stage": "train", "time": 0.0, "step": 9000, "rate_steps_per_s": 1.0},
    )
    job.start()
    GridProgress([job], 1).poll()
    assert job.step == 0 and job.rate_steps_per_s is None


def test_eta_spreads_remaining_steps_and_evaluations_over_workers(tmp_path: Path) -> None:
    statuses = _grid(tmp_path, 4)
    progress = GridProgress(statuses, workers=2)
    assert progress.eta_s() == (None, False)
    done = statuses[0]
    done.start()
    msg = progress.finished(
        done,
        {
            "wall_s": 120.0,
            "stages": {"train": "done", "evaluate": "done"},
            "train_s": 100.0,
            "evaluate_s": 20.0,
        },
    )
    assert "done in 120 s (train done, evaluate done; training 100 s, evaluation 20 s)" in msg
    assert done.rate_steps_per_s == pytest.approx(100.0)  # 10,000 steps in 100 s
    running = statuses[1]
    running.start()
    running.step = 5000
    # remaining: 5,000 + 2 × 10,000 steps at 100 steps/s = 250 s, + 3 evaluations × 20 s,
    # over 2 workers
    eta, with_eval = progress.eta_s()
    assert with_eval and eta == pytest.approx((250 + 60) / 2)
    assert progress.eta_text() == "ETA ≈ 3 min"  # 155 s


def test_only_started_jobs_are_running_and_table_keeps_units(tmp_path: Path) -> None:
    from rich.console import Console

    statuses = _grid(tmp_path, 3)
    statuses[0].start()
    progress = GridProgress(statuses, workers=1)
    counts = progress.counts()
    assert counts == {
        "queued": 2,
        "running": 1,
        "done": 0,
        "failed": 0,
        "interrupted": 0,
        "cancelled": 0,
    }
    console = Console(width=200, record=True)
    console.print(progress.table())
    text = console.export_text()
    assert "wall s" in text and "steps/s" in text
    assert text.count("running") == 2  # the title's count and the row (no stage yet)
    assert text.count("queued") == 3


def test_format_duration() -> None:
    assert [format_duration(s) for s in (5, 89, 600, 3900)] == [
        "5 s",
        "89 s",
        "10 min",
        "1 h 05 min",
    ]


def test_eta_without_training_left_needs_no_rate(tmp_path: Path) -> None:
    [job] = _grid(tmp_path, 1)
    (job.spec.run_dir).mkdir()
    (job.spec.run_dir / "spcp.json").write_text("{}")  # trained by an earlier invocation
    job.start()
    assert job.step == job.total
    assert GridProgress([job], 1).eta_s() == (0.0, False)


def test_table_reads_whole_at_80_columns(tmp_path: Path) -> None:
    from rich.console import Console

    statuses = _grid(tmp_path, 3)
    statuses[0].start()
    statuses[0].stage, statuses[0].step, statuses[0].rate_steps_per_s = "train", 4200, 95.0
    statuses[1].start()
    statuses[1].stage = "evaluate"
    console = Console(width=80, record=True)
    console.print(GridProgress(statuses, workers=2, after="cross-play and the report").table())
    text = console.export_text()
    assert "…" not in text, text
    assert all(len(line) <= 80 for line in text.splitlines())
    for cell in ("car_following/pi1/seed_0", "train", "evaluate", "queued", "42 % of 10k"):
        assert cell in text, (cell, text)
    for head in ("job", "state", "steps", "steps/s", "try", "wall s"):
        assert head in text
    assert "then cross-play and the report" in " ".join(text.split())


def test_a_retry_is_counted_and_said_at_the_end(tmp_path: Path) -> None:
    statuses = _grid(tmp_path, 2)
    progress = GridProgress(statuses, workers=1)
    for s in statuses:
        s.start()
    statuses[0].start()  # a second try: the first failed
    statuses[0].error = "SimulationError: boom"
    for s in statuses:
        progress.finished(s, {"wall_s": 1.0, "stages": {"train": "done"}})
    assert "0 failed, 1 retried" in progress.header()
    assert progress.summary().startswith("grid finished: 2 done (1 after a retry), 0 failed")


def test_pipeline_final_messages_name_a_job_that_passed_on_retry(tmp_path: Path) -> None:
    from sumo_ayss.pipeline import PipelineResult, final_messages
    from tests.report.test_report import make_run

    run = read_run(make_run(tmp_path, "car_following", "pi1", 0))
    status = JobStatus(Spec("car_following/pi1/seed_0", run.path))
    status.attempts, status.state = 2, "done"
    status.error = "SimulationError: boom"
    lines = final_messages(PipelineResult([status], None, [run], []))
    expected = (
        "RETRIED car_following/pi1/seed_0: passed on try 2 after a failure: SimulationError: boom"
    )
    assert expected in lines


def test_jobs_handed_over_beyond_the_cpus_read_as_submitted(tmp_path: Path) -> None:
    """Ray takes every job at once: on 2 CPUs, 3 handed-over jobs are 2 running and 1
    waiting, not '3 running' (issue 35)."""
    jobs = _grid(tmp_path, 3)
    for j in jobs:
        j.start()
    header = GridProgress(jobs, 2).header()
    assert "0/3 done, 2 running, 1 submitted (waiting for a CPU), 0 queued" in header
