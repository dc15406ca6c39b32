"""What pipeline and rank print and accept: the leaderboard at the end, budget flags that
enter the resolved configuration and are validated."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from sumo_ayss.commands.rank import main as rank_main
from sumo_ayss.config import PROJECT_ROOT, to_dict
from sumo_ayss.config.pipeline import load_pipeline
from sumo_ayss.pipeline import plan_jobs
from sumo_ayss.util.errors import ConfigError
from tests.test_rank import _pipe_yaml, _three_vuts

DEMO = PROJECT_ROOT / "configs" / "demo.yaml"


def test_rank_prints_the_leaderboard_of_each_case(tmp_path, monkeypatch, capsys) -> None:
    _three_vuts(tmp_path / "runs", monkeypatch)
    pipe = _pipe_yaml(tmp_path, ["cautious", "pi2", "pi1"])
    with pytest.raises(SystemExit) as done:
        rank_main([str(pipe), "--no-run", "--no-live"])
    assert done.value.code == 0
    out = capsys.readouterr().out
    assert "car_following: leaderboard (exposure mode), safest first" in out
    board = out.split("leaderboard (exposure mode)")[1]
    assert board.index("1. cautious") < board.index("2. pi2") < board.index("3. pi1")
    flat = " ".join(board.split())
    assert "safer than pi2 by " in flat and "; paired t, p" in flat
    assert "crashes " in board and "/600" in board  # 3 seeds x 200 episodes pooled
    assert " m/s" in board  # mobility
    assert "against the known order: Kendall tau = 1.00" in out
    board = board.split("\n\n")[0].split("known order")[0]
    rows = [line for line in board.splitlines() if line.startswith("  ")]
    assert len(rows) >= 6 and all(len(line) <= 80 for line in rows), board
    assert "car_following: leaderboard (exposure mode), safest first\n" in out


def test_budget_flags_enter_the_resolved_config_and_every_job(tmp_path: Path) -> None:
    cfg = load_pipeline(
        DEMO, out=tmp_path, total_timesteps=3000, eval_every=1000, n_outcome=7, n_ayss=123
    )
    resolved = to_dict(cfg)
    assert resolved["total_timesteps"] == 3000 and resolved["eval_every"] == 1000
    assert resolved["evaluate"]["n_outcome"] == 7
    assert resolved["evaluate"]["n_ayss"] == 123
    assert resolved["evaluate"]["ayss"]["n_samples"] == 123
    for job in plan_jobs(cfg):  # what train writes into each run's config.yaml
        assert job.experiment.train.total_timesteps == 3000
        assert job.experiment.train.eval_every == 1000
        assert job.n_outcome == 7 and job.ayss.n_samples == 123
    json.dumps(resolved, default=str)  # pipeline.json can hold it


@pytest.mark.parametrize(
    ("overrides", "message"),
    [
        ({"total_timesteps": 0}, "total_timesteps must be an integer >= 1"),
        ({"eval_every": -5}, "eval_every must be an integer >= 1"),
        ({"total_timesteps": 1000, "eval_every": 5000}, r"eval_every \(5000\) must be <="),
        ({"n_outcome": 0}, "evaluate.n_outcome must be >= 1"),
        ({"n_ayss": 0}, "evaluate.n_ayss must be >= 1"),
    ],
)
def test_bad_budget_flags_are_refused_naming_the_field(overrides, message) -> None:
    with pytest.raises(ConfigError, match=message):
        load_pipeline(DEMO, **overrides)


@pytest.mark.parametrize("command", ["pipeline", "rank"])
def test_budget_flags_are_on_pipeline_and_rank(command: str, capsys) -> None:
    from sumo_ayss.cli import main as cli_main

    with pytest.raises(SystemExit):
        cli_main([command, "--help"])
    text = capsys.readouterr().out
    for flag in ("--total-timesteps", "--eval-every", "--n-outcome", "--n-ayss"):
        assert flag in text


def test_a_bad_budget_flag_exits_with_a_clear_error(tmp_path: Path) -> None:
    with pytest.raises(SystemExit) as done:
        rank_main([str(DEMO), "--no-run", "--out", str(tmp_path), "--n-outcome", "0"])
    assert "evaluate.n_outcome must be >= 1, got 0" in str(done.value.code)


def test_discriminability_on_a_two_case_ladder_says_it_measures_the_first(caplog) -> None:
    from sumo_ayss.discriminability import load_target

    ladder = PROJECT_ROOT / "configs" / "ladders" / "min_gap.yaml"
    with caplog.at_level("WARNING"):
        target = load_target(ladder, None, None)
    assert target.env.case == "car_following"
    assert "measuring only the first, car_following; choose one with --case" in caplog.text
    caplog.clear()
    with caplog.at_level("WARNING"):
        assert load_target(ladder, None, "cut_in").env.case == "cut_in"
    assert "measuring only the first" not in caplog.text


def test_cli_help_names_cross_play_as_rank_default(capsys) -> None:
    from sumo_ayss.cli import main as cli_main

    cli_main([])
    text = capsys.readouterr().out
    line = next(x for x in text.splitlines() if x.strip().startswith("rank"))
    assert "safety index" not in line and "cross-play" in line
    with pytest.raises(SystemExit):
        cli_main(["rank", "--help"])
    help_text = " ".join(capsys.readouterr().out.split())
    assert "safety index" not in help_text and "Default mode: cross-play" in help_text


def test_eta_names_every_stage_after_the_grid() -> None:
    import dataclasses

    from sumo_ayss.pipeline import stages_after_grid

    cfg = load_pipeline(DEMO)
    assert stages_after_grid(cfg) == ["discriminability", "cross-play", "the report"]
    exposure = dataclasses.replace(cfg, report=dataclasses.replace(cfg.report, mode="exposure"))
    assert stages_after_grid(exposure) == ["discriminability", "the report"]
    one = dataclasses.replace(cfg, grid=dataclasses.replace(cfg.grid, vuts=("pi1",)))
    assert stages_after_grid(one) == ["the report"]


def test_leaderboard_with_one_seed_says_there_is_no_test(tmp_path, monkeypatch) -> None:
    from sumo_ayss.config.report import ReportOptions
    from sumo_ayss.modes import analyse_case
    from sumo_ayss.report.leaderboard import leaderboard_rows
    from sumo_ayss.run_folder import read_run
    from tests.report.test_report import make_run

    runs = {v: [read_run(make_run(tmp_path, "car_following", v, 0))] for v in ("pi1", "pi2")}
    a = analyse_case("car_following", runs, ReportOptions(mode="exposure", n_boot=100))
    rows = leaderboard_rows(a)
    assert rows[0].vs_next == f"no test against {rows[1].vut}: 1 vs 1 seed(s), a test needs 2"
    assert rows[0].rank == rows[1].rank == "1–2"  # no test: a tie, one shared rank
