"""Cross-play stage with real SUMO: every opponent against every VUT on common scenarios."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from sumo_ayss.analysis.crossplay_scoring import case_matrix
from sumo_ayss.config import AyssConfig, EnvConfig, OddConfig, load_experiment
from sumo_ayss.crossplay import main
from sumo_ayss.envs.car_following import CarFollowingEnv
from sumo_ayss.evaluate import evaluate_run
from sumo_ayss.records.table import table_from_rows
from sumo_ayss.run_folder import CROSSPLAY_SCHEMA, case_of, read_run
from sumo_ayss.scenarios.crossplay import (
    DIAGONAL_COLUMNS,
    Opponent,
    check_diagonal,
    diagonal_check,
    run_crossplay,
)
from sumo_ayss.scenarios.outcome import run_outcome
from sumo_ayss.scenarios.preventability import label_crashes
from sumo_ayss.train import train
from sumo_ayss.util.errors import CheckpointError, ConfigError, DiagonalMismatchError
from tests.helpers import tiny_experiment
from tests.scenarios.test_outcome import BRAKE, HOLD, constant

N, SEED = 8, 11


@pytest.mark.sumo
def test_each_cell_is_the_outcome_stage_of_that_policy_and_vut() -> None:
    """A cell (VUT v, opponent o) is what the outcome stage gives o's policy against v on
    SUMO seed = o's training seed, every column exactly; the diagonal check passes."""
    envs = {v: EnvConfig(case="car_following", vut=v) for v in ("pi1", "pi2")}
    opponents = [
        Opponent("pi1", 3, lambda env: constant(BRAKE)),
        Opponent("pi2", 5, lambda env: constant(HOLD)),
    ]
    table = run_crossplay(envs, opponents, n=N, seed=SEED)
    assert len(table) == 2 * 2 * N
    outcomes = {}
    for vut, cfg in envs.items():
        for opp, sumo_seed, action in (("pi1", 3, BRAKE), ("pi2", 5, HOLD)):
            env = CarFollowingEnv(cfg, sumo_seed=sumo_seed)
            try:
                result = run_outcome(env, constant(action), n=N, seed=SEED)
            finally:
                env.close()
            # The outcome stage labels its crashes after the rollouts (evaluate.py), too.
            labels = label_crashes(
                cfg,
                result.scenarios,
                [e.collided for e in result.episodes],
                [e.actions for e in result.episodes],
                sumo_seed=sumo_seed,
            )
            ref = result.labelled(labels).table
            rows = (table["vut"] == vut) & (table["opponent_vut"] == opp)
            assert table["scenario"][rows].tolist() == list(range(N))
            for col in DIAGONAL_COLUMNS:
                # exactly equal, NaN (a measure undefined in car-following) equal to NaN
                np.testing.assert_array_equal(table[col][rows], ref[col], err_msg=col)
            if opp == vut:
                outcomes[vut] = ref
    checks = [diagonal_check(table, v, s, outcomes[v]) for v, s in (("pi1", 3), ("pi2", 5))]
    assert [(c.n, c.n_equal) for c in checks] == [(N, N), (N, N)]
    check_diagonal(checks, "car_following")  # no error
    m = read_matrix_from(table)
    assert m.crash_rate[:, 0].min() >= m.crash_rate[:, 1].max()  # braking crashes more


def test_a_diagonal_that_differs_from_the_outcome_table_is_refused() -> None:
    """The guard names the VUT, the run and the share of differing episodes."""
    rows = [
        {
            "vut": "r10",
            "opponent_vut": "r10",
            "opponent_seed": 7,
            "scenario": k,
            "episode_return": 5.0,
            "collided": False,
            "final_headway_m": 3.0,
            "n_steps": 25,
            "near_miss_pay": 5.0,
            "vut_mean_speed_mps": 20.0,
        }
        for k in range(4)
    ]
    crossplay = table_from_rows(CROSSPLAY_SCHEMA, rows)
    outcome = _outcome_like(rows)
    assert diagonal_check(crossplay, "r10", 7, outcome).ok
    rows[2] = {**rows[2], "collided": True, "episode_return": -7.0, "n_steps": 3}
    check = diagonal_check(table_from_rows(CROSSPLAY_SCHEMA, rows), "r10", 7, outcome)
    assert (check.n, check.n_equal, check.share_differing) == (4, 3, 0.25)
    with pytest.raises(DiagonalMismatchError, match=r"r10 \(seed 7\): 1 of 4 episodes differ"):
        check_diagonal([check], "car_following")
    # an outcome table written before near_miss_pay and mobility existed: left out
    old = _outcome_like([*rows[:2], dict(rows[0], scenario=2), dict(rows[0], scenario=3)])
    for col in ("near_miss_pay", "vut_mean_speed_mps"):
        old.columns[col][:] = np.nan
    assert diagonal_check(crossplay, "r10", 7, old).ok
    with pytest.raises(ConfigError, match="no episodes of SPCP r10/seed_8"):
        diagonal_check(crossplay, "r10", 8, outcome)


def _outcome_like(rows):
    from sumo_ayss.run_folder import OUTCOME_SCHEMA

    keep = ("scenario", *DIAGONAL_COLUMNS)
    extra = {"v_pov0_mps": 20.0, "v_vut0_mps": 20.0, "gap0_m": 10.0, "lane_changed": False}
    rows = [{**{k: r[k] for k in keep if k in r}, **extra} for r in rows]  # measures: NaN
    return table_from_rows(OUTCOME_SCHEMA, rows)


def read_matrix_from(table):  # the analysis's view of the table
    from sumo_ayss.analysis.crossplay import crossplay_matrix
    from sumo_ayss.analysis.harm import episode_harm

    return crossplay_matrix(
        table["vut"],
        table["opponent_vut"],
        table["opponent_seed"],
        episode_harm(table["near_miss_pay"], table["collided"], 25.0),
        table["collided"],
        episode_return=table["episode_return"],
        mobility=table["vut_mean_speed_mps"],
    )


def test_a_pool_from_different_worlds_is_refused() -> None:
    a = EnvConfig(case="car_following", vut="pi1")
    b = dataclasses.replace(
        EnvConfig(case="car_following", vut="pi2"),
        odd=OddConfig(gap_m=(1.0, 20.0)),
    )
    with pytest.raises(ConfigError, match="differ in more than the VUT"):
        run_crossplay({"pi1": a, "pi2": b}, [Opponent("pi1", 0, lambda e: None)], n=2, seed=1)
    with pytest.raises(ConfigError, match="n: expected an integer >= 1"):
        run_crossplay({"pi1": a}, [Opponent("pi1", 0, lambda e: None)], n=0, seed=1)


@pytest.mark.sumo
def test_cli_cross_plays_a_tiny_grid_and_skips_when_done(tmp_path: Path, capsys) -> None:
    exp = tmp_path / "tiny.yaml"
    exp.write_text(yaml.safe_dump(tiny_experiment()))
    out = tmp_path / "runs"
    pipe = tmp_path / "pipe.yaml"
    pipe.write_text(
        yaml.safe_dump(
            {
                "grid": {"cases": ["car_following"], "vuts": ["pi1", "pi2"], "seeds": [0]},
                "experiments": {"car_following": "tiny.yaml"},
                "out": "runs",
                "evaluate": {"n_outcome": 6},
                "expected_order": ["pi2", "pi1"],
            }
        )
    )
    with pytest.raises(SystemExit, match=r"no spcp\.zip"):
        main([str(pipe)])
    for vut in ("pi1", "pi2"):
        train(load_experiment(exp).with_vut(vut), seed=0, out=out)
    with pytest.raises(SystemExit, match=r"outcome\.json: file not found"):
        main([str(pipe)])  # the diagonal check needs each run's outcome table
    for vut in ("pi1", "pi2"):
        evaluate_run(
            out / "car_following" / vut / "seed_0",
            n_outcome=6,
            ayss=AyssConfig(n_samples=500),
            progress=False,
        )
    main([str(pipe)])
    text = capsys.readouterr().out
    assert "cross-play ranking, safest first" in text and "Kendall tau" in text
    assert "crashes " in text and "mean speed" in text
    case = out / "car_following"
    found = case_of([read_run(out / "car_following" / v / "seed_0") for v in ("pi1", "pi2")])
    m = case_matrix(found.crossplay, found.runs)
    assert m.vuts == ("pi1", "pi2") and m.opponents == (("pi1", 0), ("pi2", 0))
    assert m.n_scenarios == 6
    record = json.loads((case / "crossplay.json").read_text())
    assert record["n"] == 6 and [o["vut"] for o in record["opponents"]] == ["pi1", "pi2"]
    assert record["rollout"] == "outcome"
    assert [(d["vut"], d["n"], d["n_equal"]) for d in record["diagonal"]] == [
        ("pi1", 6, 6),
        ("pi2", 6, 6),
    ]
    before = (case / "crossplay.csv").stat().st_mtime_ns
    main([str(pipe)])
    assert (case / "crossplay.csv").stat().st_mtime_ns == before  # done: skipped


def test_missing_spcp_is_a_clear_error(tmp_path: Path) -> None:
    from sumo_ayss.crossplay import case_runs

    with pytest.raises(CheckpointError, match=r"no spcp\.zip in .*seed_0"):
        case_runs(tmp_path, "cut_in", ["a"], [0])
