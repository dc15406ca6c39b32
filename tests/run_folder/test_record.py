"""The run record: every file of a run folder read once into one frozen record; what a
stage cannot do without is asked for and refused naming the file."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest
import yaml

from sumo_ayss.analysis.harm import harm_scale_of, run_episodes
from sumo_ayss.run_folder import RunFolder, RunRecord, read_run
from sumo_ayss.util.errors import CheckpointError
from tests.report.test_report import make_run


def test_a_complete_run_is_read_into_one_frozen_record(tmp_path: Path) -> None:
    run = read_run(make_run(tmp_path, "car_following", "pi2", 4))
    assert isinstance(run, RunRecord) and run.problems == ()
    assert (run.case, run.vut, run.seed, run.label) == ("car_following", "pi2", 4, "pi2 seed 4")
    assert run.path == (tmp_path / "car_following" / "pi2" / "seed_4").resolve()
    assert run.outcome_table is not None and run.decisions_per_episode == 25
    episodes = run_episodes(run)  # the analysis scores the stored table, not the reader
    assert episodes is not None and episodes.n == len(run.outcome_table)
    assert run.outcome is not None and run.outcome_record is not None
    assert harm_scale_of(run) is not None and run.training.n_candidates == len(run.eval_curve or ())
    assert run.experiment.env.vut == "pi2" and run.experiment.agent.gamma == 0.8
    assert run.config_seed == 4
    with pytest.raises(dataclasses.FrozenInstanceError):
        run.seed = 5  # type: ignore[misc]


def test_missing_files_are_problems_and_the_stages_get_an_error(tmp_path: Path) -> None:
    bare = tmp_path / "cut_in" / "pi1" / "seed_0"
    bare.mkdir(parents=True)
    run = read_run(bare)
    assert (run.case, run.vut, run.seed) == ("cut_in", "pi1", 0)  # from the folder path
    assert run.problems[0].startswith("config.yaml missing")
    outcome_csv = RunFolder.outcome_csv.name
    assert not any(p.startswith(outcome_csv) for p in run.problems)  # no harm scale to use
    with pytest.raises(CheckpointError, match=r"seed_0: not a run folder \(no config\.yaml\)"):
        run.experiment  # noqa: B018
    with pytest.raises(CheckpointError, match="not a run folder"):
        run.config_seed  # noqa: B018
    (bare / "config.yaml").write_text("seed: 0\nenv: {case: cut_in, vut: pi1}\nagent: {gamma: 7}\n")
    run = read_run(bare)
    assert run.config is not None and run.seed == 0
    assert (
        f"{RunFolder.outcome_csv.name} missing" in run.problems
    )  # scorable now, so its absence counts
    with pytest.raises(CheckpointError, match=r"config\.yaml: invalid run configuration: .*gamma"):
        run.experiment  # noqa: B018
    (bare / "config.yaml").write_text("seed: [\n")
    run = read_run(bare)
    assert run.config is None and run.problems[0].startswith("config.yaml unreadable")
    with pytest.raises(CheckpointError, match=r"config\.yaml: unreadable run configuration"):
        run.experiment  # noqa: B018


def test_candidates_that_all_scored_the_same_are_a_problem(tmp_path: Path) -> None:
    """A cut-in whose ODD pins the VUT's speed at 0 scores every candidate 0.0000: which
    one is the SPCP is arbitrary, and the record says so (issue 38)."""
    from sumo_ayss.run_folder import read_eval_table, write_eval_table

    folder = make_run(tmp_path, "cut_in", "pi1", 0)
    rows = read_eval_table(folder / "eval.csv")
    write_eval_table(folder / "eval.csv", [{**r, "mean_return": 0.0} for r in rows])
    (problem,) = read_run(folder).problems
    assert problem.startswith(f"eval.csv: all {len(rows)} SPCP candidates scored exactly the same")
    assert "(0.0000)" in problem
    write_eval_table(folder / "eval.csv", [{**rows[0], "mean_return": 0.0}])
    assert read_run(folder).problems == ()  # one candidate: nothing to compare
    write_eval_table(
        folder / "eval.csv",
        [{**r, "mean_return": 0.0} for r in rows[:-1]] + [{**rows[-1], "mean_return": 1e-9}],
    )
    assert read_run(folder).problems == ()  # not exactly the same
    spcp = json.loads((folder / "spcp.json").read_text())
    (folder / "spcp.json").write_text(json.dumps({**spcp, "no_signal": True}))
    (problem,) = read_run(folder).problems  # the selection's own criterion said so
    assert "scored exactly the same mean_reward" in problem


@pytest.mark.sumo
def test_a_cut_in_whose_odd_pins_the_vut_at_rest_is_a_problem_of_its_record(
    tmp_path: Path,
) -> None:
    """The issue's own case, trained with real SUMO: every candidate scores 0.0000."""
    from sumo_ayss.config import load_experiment
    from sumo_ayss.train import train
    from tests.helpers import tiny_experiment

    exp = tiny_experiment()
    odd = {"pov_speed_mps": [10.0, 30.0], "vut_speed_mps": [0.0, 0.0], "gap_m": [0.0, 25.0]}
    exp["env"] = {"case": "cut_in", "vut": "pi1", "odd": odd}
    path = tmp_path / "pinned.yaml"
    path.write_text(yaml.safe_dump(exp))
    train(load_experiment(path), seed=0, out=tmp_path / "runs")
    run = read_run(tmp_path / "runs" / "cut_in" / "pi1" / "seed_0")
    assert run.eval_curve is not None and set(run.eval_curve["mean_return"].tolist()) == {0.0}
    same = [p for p in run.problems if "scored exactly the same" in p]
    assert same == [
        "eval.csv: all 3 SPCP candidates scored exactly the same mean reward (0.0000): the "
        "opponent's actions changed nothing it is paid for (e.g. an ODD that pins the VUT's "
        "speed), so the SPCP is an arbitrary candidate and its scores carry no signal"
    ]
