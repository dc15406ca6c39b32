"""The pipeline: bad grids refused up front, failing jobs retried then reported, kill + rerun."""

from __future__ import annotations

import dataclasses
import json
import logging
import os
import pickle
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml

from sumo_ayss.commands.pipeline import run_pipeline
from sumo_ayss.config import PROJECT_ROOT, AyssConfig, ExperimentConfig
from sumo_ayss.discriminability import discriminability_beside
from sumo_ayss.pipeline import load_pipeline, plan_jobs
from sumo_ayss.records.table import read_table
from sumo_ayss.run_folder import CROSSPLAY_SCHEMA, OUTCOME_SCHEMA
from sumo_ayss.util.errors import ConfigError
from tests.helpers import TINY_AGENT


def write_configs(tmp_path: Path, seeds: list[int], **extra) -> Path:
    exp = yaml.safe_load((PROJECT_ROOT / "configs" / "car_following.yaml").read_text())
    exp["agent"] = TINY_AGENT
    exp["train"].update(n_eval_scenarios=5)
    (tmp_path / "cf.yaml").write_text(yaml.safe_dump(exp))
    pipe = {
        "grid": {"cases": ["car_following"], "vuts": ["pi1", "pi2"], "seeds": seeds},
        "experiments": {"car_following": "cf.yaml"},
        "out": "runs",
        "total_timesteps": 600,
        "eval_every": 300,
        "evaluate": {"n_outcome": 10, "n_ayss": 2000},
        "workers": 1,
        **extra,
    }
    path = tmp_path / "pipe.yaml"
    path.write_text(yaml.safe_dump(pipe))
    return path


@pytest.mark.parametrize(
    ("grid", "match"),
    [
        ({"vuts": ["pi1", "pi9"]}, r"grid\.vuts: 'pi9' is not a VUT of the car_following"),
        ({"seeds": []}, r"grid\.seeds must not be empty"),
        ({"cases": ["merge"]}, r"grid\.cases\[0\] must be one of"),
    ],
)
def test_bad_grid_is_refused_before_any_job(tmp_path: Path, grid: dict, match: str) -> None:
    path = write_configs(tmp_path, [0])
    data = yaml.safe_load(path.read_text())
    data["grid"].update(grid)
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(ConfigError, match=match):
        plan_jobs(load_pipeline(path))
    assert not (tmp_path / "runs").exists()


@pytest.mark.sumo
def test_discriminability_is_written_by_a_worker_beside_the_analysis(tmp_path: Path) -> None:
    """With two workers it runs in a worker process while the body (the report's analysis)
    runs here, and is on disk when the body is done."""
    cfg = dataclasses.replace(load_pipeline(write_configs(tmp_path, [0])), workers=2)
    record = cfg.out / "car_following" / "discriminability.json"
    with discriminability_beside(cfg):
        assert not record.exists()  # the worker has just been spawned
    assert json.loads(record.read_text())["vuts"] == ["pi1", "pi2"]
    record.unlink()
    failed = pytest.raises(ValueError, match="the analysis failed")  # the body's, as is
    with failed, discriminability_beside(cfg):
        raise ValueError("the analysis failed")


@pytest.mark.sumo
@pytest.mark.parametrize("workers", [1, 2])
def test_a_discriminability_failure_is_logged_not_raised(
    tmp_path: Path, workers: int, caplog: pytest.LogCaptureFixture
) -> None:
    """Its folder cannot be written (the study's out is a file): the body still runs, the
    failure is a warning naming the case, in this process or from the worker."""
    cfg = dataclasses.replace(load_pipeline(write_configs(tmp_path, [0])), workers=workers)
    cfg.out.parent.mkdir(parents=True, exist_ok=True)
    cfg.out.write_text("not a folder")
    ran = []
    with caplog.at_level(logging.WARNING), discriminability_beside(cfg):
        ran.append(True)
    assert ran == [True]
    assert "discriminability of car_following not computed" in caplog.text


@pytest.mark.sumo
def test_failing_job_is_retried_then_reported_others_complete(tmp_path: Path) -> None:
    cfg = load_pipeline(write_configs(tmp_path, [0]))
    broken = cfg.out / "car_following" / "pi2" / "seed_0"
    broken.mkdir(parents=True)
    (broken / "config.yaml").write_text("not: [a, valid, run\n")  # a corrupt run folder
    statuses, report, *_ = run_pipeline(cfg, live=False)
    by_name = {s.spec.name: s for s in statuses}
    bad = by_name["car_following/pi2/seed_0"]
    assert bad.state == "failed" and bad.attempts == 2  # tried, retried once, reported
    assert bad.error and (broken / "job.log").is_file()
    good = by_name["car_following/pi1/seed_0"]
    assert good.state == "done"
    assert (good.spec.run_dir / "ayss.csv").is_file()
    assert report is not None and report.is_file()
    # Discriminability of the grid's VUTs (a property of the VUTs, not of the runs).
    record = json.loads((cfg.out / "car_following" / "discriminability.json").read_text())
    assert record["vuts"] == ["pi1", "pi2"] and record["pairs"][0]["share"] > 0
    # Cross-play mode (the default): skipped for the case with a failed job, and said so.
    assert not (cfg.out / "car_following" / "crossplay.csv").exists()
    text = report.read_text(encoding="utf-8")
    assert "[crossplay mode] no cross-play" in text and "Cross-play table missing" in text


@pytest.mark.sumo
def test_crossplay_mode_runs_the_crossplay_stage_and_reports_it(tmp_path: Path) -> None:
    cfg = load_pipeline(write_configs(tmp_path, [0]))
    assert cfg.report.mode == "crossplay" and cfg.report.crossplay_blocks == "seed"
    statuses, report, *_ = run_pipeline(cfg, live=False)
    assert all(s.state == "done" for s in statuses)
    case = cfg.out / "car_following"
    record = json.loads((case / "crossplay.json").read_text())
    assert record["n"] == 10 and record["seed"] == 4242
    assert [(o["vut"], o["seed"]) for o in record["opponents"]] == [("pi1", 0), ("pi2", 0)]
    assert (case / "crossplay.csv").is_file()
    assert report is not None
    text = report.read_text(encoding="utf-8")
    verdicts = text.split('id="inputs"')[0]
    assert "[crossplay mode]" in verdicts and "Ranking (crossplay mode), safest first" in verdicts
    assert "no cross-play table" not in text
    assert "(i) Cross-play ranking" in text and "Ranking by cross-play harm H" in text
    assert (report.parent / "car_following_crossplay_by_opponent.png").is_file()
    # The reference drivers drove against the whole pool; every crash carries its label.
    ref = read_table(case / "crossplay_reference.csv", CROSSPLAY_SCHEMA)
    assert sorted(set(ref["vut"].tolist())) == ["cc_driver", "fsm", "rss"]
    assert len(ref) == 3 * 2 * 10
    for table in (
        ref,
        read_table(case / "crossplay.csv", CROSSPLAY_SCHEMA),
        read_table(case / "pi1" / "seed_0" / "outcome.csv", OUTCOME_SCHEMA),
    ):
        label = table["crash_preventable"]
        assert np.isin(label[table["collided"]], [0.0, 1.0]).all()
        assert np.isnan(label[~table["collided"]]).all()
    assert "(k) Against the careful human" in text and "the careful human (cc_driver)" in text
    ics = json.loads((case / "inevitable.json").read_text())
    assert ics["n"] == 10 and ics["seed"] == 4242 and ics["strategies"] == ["brake"]
    assert "are inevitable-collision states" in text
    before = (case / "crossplay.csv").stat().st_mtime_ns
    ref_before = (case / "crossplay_reference.csv").stat().st_mtime_ns
    run_pipeline(cfg, live=False)  # a rerun skips every finished stage, cross-play included
    assert (case / "crossplay.csv").stat().st_mtime_ns == before
    assert (case / "crossplay_reference.csv").stat().st_mtime_ns == ref_before


@pytest.mark.sumo
def test_sigkill_then_rerun_finishes_without_redoing_finished_stages(tmp_path: Path) -> None:
    path = write_configs(tmp_path, [0, 1])
    cmd = [sys.executable, "-m", "sumo_ayss.pipeline", str(path), "--no-live"]
    out = tmp_path / "runs" / "car_following"
    first = out / "pi1" / "seed_0"
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 240
        while time.monotonic() < deadline:  # kill once job 1 is done and job 2 has started
            if (first / "evaluate.done.json").is_file() and (out / "pi1" / "seed_1").exists():
                break
            assert proc.poll() is None, "pipeline ended before it could be killed"
            time.sleep(0.05)
        os.kill(proc.pid, signal.SIGKILL)
    finally:
        proc.wait()
    lock = tmp_path / "runs" / "pipeline.lock"
    assert lock.read_text() == f"{proc.pid}\n"  # left by the killed pipeline: stale
    finished = {p: p.read_bytes() for p in first.glob("*.csv")}
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    assert "report:" in done.stdout
    assert "car_following: leaderboard (" in done.stdout  # the verdicts, printed
    assert "taking over the stale lock" in done.stderr and not lock.exists()
    for p, data in finished.items():  # completed stages were not redone
        assert p.read_bytes() == data, p
    log = (first / "job.log").read_text()
    assert log.count("SPCP:") == 1  # trained once, skipped on the rerun
    for vut in ("pi1", "pi2"):
        for seed in (0, 1):
            run = out / vut / f"seed_{seed}"
            assert (run / "spcp.json").is_file() and (run / "ayss.csv").is_file()
            assert json.loads((run / "evaluate.done.json").read_text())["inputs"]


def test_pipeline_vuts_report_and_known_order_sections(tmp_path: Path) -> None:
    ladder = {
        "cautious": {"model": "IDM", "params": {"minGap": 12.0, "tau": 2.0}},
        "bold": {"model": "IDM", "params": {"minGap": 1.0, "tau": 0.6}},
    }
    path = write_configs(
        tmp_path,
        [0, 1],
        vuts=ladder,
        report={"mode": "paper", "premise_reward": 0.5},
        expected_order=["cautious", "bold"],
    )
    data = yaml.safe_load(path.read_text())
    data["grid"]["vuts"] = ["bold", "cautious"]
    path.write_text(yaml.safe_dump(data))
    cfg = load_pipeline(path, seeds=[5, 6, 7])
    assert cfg.grid.seeds == (5, 6, 7)
    assert cfg.report.mode == "paper" and cfg.report.premise_reward == 0.5
    jobs = plan_jobs(cfg)
    assert [j.name for j in jobs[:3]] == [f"car_following/bold/seed_{s}" for s in (5, 6, 7)]
    params = jobs[0].experiment.env.vuts["bold"].params
    assert params["minGap"] == 1.0 and params["tau"] == 0.6
    assert "pi1" in jobs[0].experiment.env.vuts  # the built-ins stay
    assert jobs[0].experiment.env.vut == "bold"


def test_jobs_carry_the_config_parsed_once_and_it_pickles(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Each case's experiment is parsed once; the frozen records travel to workers as is."""
    import sumo_ayss.config.experiment as experiment_module

    ayss = {"n_samples": 300, "h_m": [0.0, 4.0], "seed": 7}
    path = write_configs(tmp_path, [0, 1], evaluate={"n_outcome": 10, "ayss": ayss})
    cfg = load_pipeline(path)
    assert cfg.evaluate.ayss.n_samples == 300 and cfg.evaluate.n_ayss is None
    parsed: list[type] = []
    real_build = experiment_module.build

    def counting_build(cls: type, *args: object, **kwargs: object) -> object:
        parsed.append(cls)
        return real_build(cls, *args, **kwargs)

    monkeypatch.setattr(experiment_module, "build", counting_build)
    jobs = plan_jobs(cfg)
    assert parsed == [ExperimentConfig]  # one case: one parse for its 4 jobs
    assert len(jobs) == 4
    assert all(j.ayss == AyssConfig(n_samples=300, h_m=(0.0, 4.0), seed=7) for j in jobs)
    assert [j.experiment.env.vut for j in jobs] == [j.vut for j in jobs]
    assert all(j.experiment.train.total_timesteps == 600 for j in jobs)
    assert pickle.loads(pickle.dumps(jobs)) == jobs


@pytest.mark.parametrize(
    ("extra", "match"),
    [
        ({"expected_order": ["pi1"]}, r"expected_order must list exactly the grid's VUTs"),
        ({"report": {"mode": "Fancy"}}, r"report\.mode must be a mode's name"),
        (
            {"report": {"crossplay_blocks": "seeds"}},
            r"report\.crossplay_blocks must be one of \['seed', 'opponent'\], got 'seeds'",
        ),
        (
            {"report": {"premise_reward": -1}},
            r"report\.premise_reward must be a finite number >= 0",
        ),
        ({"report": {"n_boot": 0}}, r"report\.n_boot must be an int >= 1, got 0"),
        ({"report": {"levels": 0.9}}, r"report: unknown key 'levels' \(did you mean 'level'\?\)"),
        ({"evaluate": {"ayss": {"h_m": [5, 0]}}}, r"evaluate\.ayss\.h_m must have min <= max"),
        (
            {"evaluate": {"n_ayss": 10, "ayss": {"n_samples": 20}}},
            r"evaluate\.n_ayss \(10\) and evaluate\.ayss\.n_samples \(20\) differ",
        ),
        ({"evaluate": {"ayss": {"seeds": 1}}}, r"evaluate\.ayss: unknown key 'seeds'"),
        ({"vuts": {"x": {"model": "IDM", "params": {"tau": -1}}}}, r"vuts\.x"),
    ],
)
def test_bad_pipeline_sections_are_refused(tmp_path: Path, extra: dict, match: str) -> None:
    with pytest.raises(ConfigError, match=match):
        load_pipeline(write_configs(tmp_path, [0], **extra))


def test_an_unregistered_mode_is_refused_when_the_stage_reads_the_config(tmp_path: Path) -> None:
    """The configuration imports no mode; ``pipeline`` and ``rank`` check ``report.mode``
    against the registry as they read their YAML (:func:`sumo_ayss.pipeline.config_from_args`)."""
    import argparse

    from sumo_ayss.pipeline import add_config_flags, config_from_args

    path = write_configs(tmp_path, [0], report={"mode": "fancy"})
    assert load_pipeline(path).report.mode == "fancy"
    parser = argparse.ArgumentParser()
    parser.add_argument("config", type=Path)
    add_config_flags(parser)
    with pytest.raises(ConfigError, match=r"report\.mode must be one of \['crossplay', 'exp"):
        config_from_args(parser.parse_args([str(path)]))


@pytest.mark.sumo
def test_progress_is_logged_per_job_event_and_small_budget_is_flagged(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    from sumo_ayss.pipeline import final_messages

    cfg = load_pipeline(write_configs(tmp_path, [0]))  # 2 jobs, 1 worker
    with caplog.at_level(logging.INFO, logger="sumo_ayss.pipeline"):
        result = run_pipeline(cfg, live=True)  # not a terminal: log lines only
    statuses, report = result.statuses, result.report
    lines = [r.getMessage() for r in caplog.records if r.name == "sumo_ayss.pipeline"]
    first = statuses[0].spec.name
    assert any(
        "0/2 done, 1 running, 1 queued, 0 failed" in x and f"{first}: started" in x for x in lines
    )  # only the job a worker holds is running
    candidates = [x for x in lines if f"{first}: SPCP candidate at step" in x]
    assert len(candidates) == 2  # 600 steps, a candidate every 300: both, each once
    done = [x for x in lines if ": done in " in x]
    assert len(done) == 2 and "1/2 done, 0 running, 1 queued" in done[0]
    assert "training" in done[0] and " s, evaluation " in done[0]
    messages = final_messages(result)
    assert messages[0].startswith("WARNING: Small training budget: 600 transitions per run")
    assert messages[-1] == f"report: {report}"
    for written in (cfg.out / "pipeline.json", report, report.with_name("summary.md")):
        assert str(tmp_path) not in written.read_text(), written  # no machine paths


@pytest.mark.sumo
def test_adaptive_seeding_adds_seeds_until_the_cap_and_extends_crossplay(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """A ranking that cannot settle (a significance level no test reaches) gets one seed at a
    time up to max_seeds; each look is recorded; cross-play drives only the new opponents and
    its table equals a full rerun's; a rerun adds nothing. On two workers: the grid's jobs
    and cross-play's cells (issue 40), the table equal to a full rerun in one process."""
    from sumo_ayss.crossplay import run_case
    from sumo_ayss.run_folder import read_adaptive, read_run

    path = write_configs(tmp_path, [0, 1], max_seeds=3, report={"welch_alpha": 1e-12}, workers=2)
    cfg = load_pipeline(path)
    assert cfg.added_seeds == (2,)
    with caplog.at_level(logging.INFO):
        statuses, report, runs, *_ = run_pipeline(cfg, live=False)
    assert "cross-play: cells on 2 worker processes" in caplog.text
    assert "cross-play drives 4 new cells (VUT x SPCP) and keeps 8" in caplog.text
    assert "adaptive seeding, car_following: not settled at 2 seeds per VUT" in caplog.text
    assert sorted((s.spec.vut, s.spec.seed) for s in statuses) == [
        (v, s) for v in ("pi1", "pi2") for s in (0, 1, 2)
    ]
    assert all(s.state == "done" for s in statuses) and len(runs) == 6
    case = cfg.out / "car_following"
    record = read_adaptive(case / "adaptive.json")
    assert record.seeds == (0, 1, 2) and [x.n_seeds for x in record.looks] == [2, 3]
    assert not record.settled and record.looks[0].gate_level > 0
    assert report is not None
    text = report.read_text(encoding="utf-8")  # the report shows every look
    assert "Adaptive seeding: each look at this case" in text
    assert "had not settled at the cap of 3 seeds per VUT" in text
    crossplay = json.loads((case / "crossplay.json").read_text())
    assert [(o["vut"], o["seed"]) for o in crossplay["opponents"]] == [
        ("pi1", 0),
        ("pi1", 1),
        ("pi1", 2),
        ("pi2", 0),
        ("pi2", 1),
        ("pi2", 2),
    ]
    assert len(crossplay["diagonal"]) == 6
    kept = (case / "crossplay.csv").read_bytes()
    full = tmp_path / "full"
    run_case(
        [
            read_run(s.spec.run_dir)
            for s in sorted(statuses, key=lambda s: (s.spec.vut, s.spec.seed))
        ],
        full,
        n=10,
        seed=4242,
        force=True,
    )  # in this process (no pool)
    assert (full / "crossplay.csv").read_bytes() == kept  # the extended table = a full run
    again = run_pipeline(cfg, live=False)  # resume: the same 6 jobs, nothing added
    assert len(again.statuses) == 6
    assert read_adaptive(case / "adaptive.json").looks == record.looks
    assert (case / "crossplay.csv").read_bytes() == kept
    # Another level is another schedule: the record starts over, and a level every grid
    # passes settles at the first look with the grid's own seeds (no job added).
    data = yaml.safe_load(path.read_text())
    data["report"] = {"welch_alpha": 0.99}
    path.write_text(yaml.safe_dump(data))
    settled = run_pipeline(load_pipeline(path), live=False)
    assert len(settled.statuses) == 4
    again_record = read_adaptive(case / "adaptive.json")
    assert [x.n_seeds for x in again_record.looks] == [2] and again_record.settled
    assert again_record.seeds == (0, 1)


def test_a_resumed_adaptive_grid_plans_the_seeds_its_record_added(tmp_path: Path) -> None:
    """A pipeline killed after adaptive seeding named a new seed runs that seed's jobs on
    resume; a record of another schedule (other seeds, cap or level) is ignored."""
    from sumo_ayss.run_folder import AdaptiveRecord, write_adaptive

    cfg = load_pipeline(write_configs(tmp_path, [0, 1], max_seeds=4))
    assert {j.seed for j in plan_jobs(cfg)} == {0, 1}
    record = tmp_path / "runs" / "car_following" / "adaptive.json"
    record.parent.mkdir(parents=True)
    write_adaptive(record, AdaptiveRecord((0, 1), 4, 0.05, (0, 1, 2), ()))
    planned = [(j.vut, j.seed) for j in plan_jobs(cfg)]
    assert planned == [(v, s) for v in ("pi1", "pi2") for s in (0, 1, 2)]
    write_adaptive(record, AdaptiveRecord((0, 1), 5, 0.05, (0, 1, 2), ()))  # another cap
    assert {j.seed for j in plan_jobs(cfg)} == {0, 1}
