"""Cross-play stage with real SUMO: every opponent against every VUT on common scenarios."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from sumo_ayss.config import EnvConfig, OddConfig, load_experiment
from sumo_ayss.crossplay import main, read_matrix
from sumo_ayss.envs.car_following import CarFollowingEnv
from sumo_ayss.errors import CheckpointError, ConfigError
from sumo_ayss.scenarios.crossplay import Opponent, run_crossplay
from sumo_ayss.scenarios.outcome import run_outcome
from sumo_ayss.train import train
from tests.helpers import tiny_experiment
from tests.scenarios.test_outcome import BRAKE, HOLD, constant

N, SEED = 8, 11


@pytest.mark.sumo
def test_each_cell_equals_the_single_env_outcome_of_that_policy_and_vut() -> None:
    envs = {v: EnvConfig(case="car_following", vut=v) for v in ("pi1", "pi2")}
    opponents = [
        Opponent("pi1", 0, lambda env: constant(BRAKE)),
        Opponent("pi2", 0, lambda env: constant(HOLD)),
    ]
    table = run_crossplay(envs, opponents, n=N, seed=SEED, n_envs=3)
    assert len(table) == 2 * 2 * N
    for vut, cfg in envs.items():
        env = CarFollowingEnv(cfg, sumo_seed=SEED)
        try:
            for opp, action in (("pi1", BRAKE), ("pi2", HOLD)):
                ref = run_outcome(env, constant(action), n=N, seed=SEED).table
                rows = (table["vut"] == vut) & (table["opponent_vut"] == opp)
                assert table["scenario"][rows].tolist() == list(range(N))
                # bit-identical: the vec env runs the single env's code, summed in order
                assert table["episode_return"][rows].tolist() == ref["episode_return"].tolist()
                assert table["collided"][rows].tolist() == ref["collided"].tolist()
                assert np.allclose(table["final_headway_m"][rows], ref["final_headway_m"])
                assert table["n_steps"][rows].tolist() == ref["n_steps"].tolist()
        finally:
            env.close()
    m = read_matrix_from(table)
    assert m.crash_rate[:, 0].min() >= m.crash_rate[:, 1].max()  # braking crashes more


def read_matrix_from(table):  # the analysis's view of the table
    from sumo_ayss.analysis.crossplay import crossplay_matrix

    return crossplay_matrix(
        table["vut"],
        table["opponent_vut"],
        table["opponent_seed"],
        table["episode_return"],
        table["collided"],
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
    main([str(pipe), "--n-envs", "4"])
    text = capsys.readouterr().out
    assert "cross-play ranking, safest first" in text and "Kendall tau" in text
    case = out / "car_following"
    m = read_matrix(case / "crossplay.csv")
    assert m.vuts == ("pi1", "pi2") and m.opponents == (("pi1", 0), ("pi2", 0))
    assert m.n_scenarios == 6
    record = json.loads((case / "crossplay.json").read_text())
    assert record["n"] == 6 and [o["vut"] for o in record["opponents"]] == ["pi1", "pi2"]
    before = (case / "crossplay.csv").stat().st_mtime_ns
    main([str(pipe)])
    assert (case / "crossplay.csv").stat().st_mtime_ns == before  # done: skipped


def test_missing_spcp_is_a_clear_error(tmp_path: Path) -> None:
    from sumo_ayss.crossplay import case_runs

    with pytest.raises(CheckpointError, match=r"no spcp\.zip in .*seed_0"):
        case_runs(tmp_path, "cut_in", ["a"], [0])
