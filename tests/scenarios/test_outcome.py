"""Outcome stage (paper Tables II, III) and the evaluate CLI, with real SUMO where an env runs."""

from __future__ import annotations

import json
import math
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import numpy.typing as npt
import pytest
import yaml

from sumo_ayss.analysis.stats import wilson_interval
from sumo_ayss.config import AyssConfig, load_experiment
from sumo_ayss.envs.car_following import CarFollowingEnv
from sumo_ayss.envs.odd import sample_initial_conditions
from sumo_ayss.evaluate import evaluate_run, main
from sumo_ayss.records.table import read_table, table_from_rows
from sumo_ayss.run_folder import AYSS_SCHEMA, OUTCOME_SCHEMA
from sumo_ayss.scenarios.outcome import (
    MeanInterval,
    Proportion,
    run_outcome,
    summarize_outcome,
)
from sumo_ayss.scenarios.rollout import Policy
from sumo_ayss.train import train
from sumo_ayss.util.errors import ConfigError
from tests.helpers import tiny_experiment

#: Car-following actions: k = 0 asks for a stop (target 0), k = 2 holds the POV's speed.
BRAKE, HOLD = 0, 2


def constant(action: int) -> Policy:
    """A scripted policy: the same action for every observation."""

    def policy(obs: npt.NDArray[np.float32]) -> npt.NDArray[np.int64]:
        return np.full(len(obs), action, dtype=np.int64)

    return policy


# --------------------------------------------------------------------------- statistics


def test_wilson_interval_on_hand_cases() -> None:
    # z = 1.959964 (97.5 % normal quantile), z² = 3.841459, n = 200, z²/n = 0.019207.
    # 0/200: p = 0, centre = half = (z²/2n)/(1 + z²/n), so lo = 0 and
    #   hi = z²/(n + z²) = 3.841459 / 203.841459 = 0.018845.
    lo, hi = wilson_interval(0, 200)
    assert lo == 0.0
    assert hi == pytest.approx(0.018845, abs=1e-6)
    # 10/200: p = 0.05, denominator 1.019207,
    #   centre = (0.05 + 0.009604) / 1.019207 = 0.058480,
    #   half = 1.959964 / 1.019207 · sqrt(0.05·0.95/200 + 3.841459/160000)
    #        = 1.923029 · sqrt(0.0002375 + 0.0000240091) = 1.923029 · 0.016171 = 0.031098,
    #   so [0.027383, 0.089578].
    lo, hi = wilson_interval(10, 200)
    assert lo == pytest.approx(0.027383, abs=1e-6)
    assert hi == pytest.approx(0.089578, abs=1e-6)
    # Symmetry: n/n mirrors 0/n.
    lo, hi = wilson_interval(200, 200)
    assert (lo, hi) == (pytest.approx(1 - 0.018845, abs=1e-6), 1.0)
    for bad in ((-1, 10), (11, 10), (0, 0), (1.5, 10)):
        with pytest.raises(ConfigError):
            wilson_interval(*bad)


def test_summary_of_a_hand_made_cut_in_table() -> None:
    # Four episodes: a lane change without crash (return 20, h 0.4), one with a crash,
    # one without a lane change, and a second clean lane change (return 22, h 0.6).
    rows = [
        (True, False, 20.0, 0.4),
        (True, True, -10.0, -1.0),
        (False, False, 0.0, 30.0),
        (True, False, 22.0, 0.6),
    ]
    table = table_from_rows(
        OUTCOME_SCHEMA,
        [
            {
                "scenario": i,
                "v_pov0_mps": 20.0,
                "v_vut0_mps": 20.0,
                "gap0_m": 3.0,
                "episode_return": ret,
                "collided": crash,
                "lane_changed": lc,
                "final_headway_m": h,
                "n_steps": 25,
            }
            for i, (lc, crash, ret, h) in enumerate(rows)
        ],
    )
    s = summarize_outcome(table, "cut_in")
    assert (s.crash_rate.count, s.crash_rate.n, s.crash_rate.value) == (1, 4, 0.25)
    assert s.lane_change_rate is not None and s.lane_change_rate.value == 0.75
    assert s.mean_return.mean == pytest.approx(8.0)
    assert s.lc_no_collision_return is not None and s.lc_no_collision_return.n == 2
    assert s.lc_no_collision_return.mean == pytest.approx(21.0)
    # t interval of two values 20, 22: s = sqrt(2), half = t_{0.975,1}·s/sqrt(2) = 12.706.
    assert s.lc_no_collision_return.hi == pytest.approx(21.0 + 12.7062, abs=1e-3)
    assert s.lc_no_collision_final_headway_m is not None
    assert s.lc_no_collision_final_headway_m.mean == pytest.approx(0.5)
    cf = summarize_outcome(table, "car_following")
    assert cf.lane_change_rate is None and cf.lc_no_collision_return is None
    empty = Proportion.of([])
    assert empty.n == 0 and math.isnan(empty.value)
    assert math.isnan(MeanInterval.of([1.0]).lo)


# --------------------------------------------------------------------------- with SUMO


@pytest.fixture
def cf_env_7() -> Iterator[CarFollowingEnv]:
    env = CarFollowingEnv(sumo_seed=7)
    try:
        yield env
    finally:
        env.close()


@pytest.mark.sumo
def test_braking_crashes_more_than_holding_on_the_same_scenarios(cf_env_7: CarFollowingEnv) -> None:
    brake = run_outcome(cf_env_7, constant(BRAKE), n=40, seed=11)
    hold = run_outcome(cf_env_7, constant(HOLD), n=40, seed=11)
    scenario_cols = ("scenario", "v_pov0_mps", "v_vut0_mps", "gap0_m")
    for col in scenario_cols:  # the same scenarios for both policies
        assert np.array_equal(brake.table[col], hold.table[col])
    ics = sample_initial_conditions(cf_env_7.config.odd, 40, 11)
    assert brake.table["gap0_m"].tolist() == [ic.gap_m for ic in ics]
    assert brake.summary.crash_rate.value > hold.summary.crash_rate.value
    assert brake.summary.crash_rate.lo <= brake.summary.crash_rate.value
    assert not brake.table["lane_changed"].any()
    assert (brake.table["n_steps"][brake.table["collided"]] < 25).all()

    again = run_outcome(cf_env_7, constant(BRAKE), n=40, seed=11)
    assert again.table.equals(brake.table)  # rows identical for the same seed
    other = run_outcome(cf_env_7, constant(BRAKE), n=40, seed=12)
    assert not np.array_equal(other.table["gap0_m"], brake.table["gap0_m"])


# --------------------------------------------------------------------------- evaluate CLI

#: tests/training/test_train.py's tiny learner: small nets, 600 steps, a candidate every 200.
TINY = tiny_experiment()


@pytest.mark.sumo
def test_cli_evaluates_a_tiny_run_and_skips_done_stages(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    config = tmp_path / "tiny.yaml"
    config.write_text(yaml.safe_dump(TINY))
    run = train(load_experiment(config), seed=1, out=tmp_path / "runs")

    main([str(run), "--n-outcome", "12", "--n-ayss", "3000", "--seed", "5", "--no-progress"])
    outcome = read_table(run / "outcome.csv", OUTCOME_SCHEMA)
    assert len(outcome) == 12
    ayss = read_table(run / "ayss.csv", AYSS_SCHEMA)
    assert 0 < len(ayss) <= 3000
    assert (ayss["h_m"] <= 5.0).all() and (ayss["ttc_s"] >= 0.2).all()
    assert set(ayss["indicator_name"]) == {"pov_accel_mps2"}
    summary = json.loads((run / "outcome.json").read_text())
    assert summary["settings"] == {"n": 12, "seed": 5}
    assert summary["vut"] == "pi1" and summary["case"] == "car_following"
    assert summary["summary"]["n_episodes"] == 12
    info = json.loads((run / "ayss.json").read_text())
    assert info["counts"]["n_kept"] == len(ayss) and info["settings"]["seed"] == 5
    assert info["settings"]["n_samples"] == 3000

    before = {name: (run / name).stat().st_mtime_ns for name in ("outcome.csv", "ayss.csv")}
    with caplog.at_level("INFO", logger="sumo_ayss.evaluate"):
        again = evaluate_run(
            run, n_outcome=12, outcome_seed=5, ayss=AyssConfig(n_samples=3000, seed=5)
        )
    assert not again.ran_outcome and not again.ran_ayss
    assert {n: (run / n).stat().st_mtime_ns for n in before} == before
    assert "skipping outcome.csv" in caplog.text
    with caplog.at_level("WARNING", logger="sumo_ayss.evaluate"):
        evaluate_run(run, n_outcome=13, outcome_seed=5, ayss=AyssConfig(n_samples=3000, seed=5))
    assert "not the requested" in caplog.text  # a skip with other settings is flagged
