"""The early-stopping rule: synthetic candidate curves with a known answer, its config
errors, and a real (tiny) training run that it stops."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from sumo_ayss.analysis.early_stop import evaluation_se, null_false_claims, stop_index
from sumo_ayss.config import load_experiment
from sumo_ayss.config.experiment import TrainConfig
from sumo_ayss.run_folder import read_eval_table
from sumo_ayss.train import train
from sumo_ayss.training.early_stop import stop_decision
from sumo_ayss.util.errors import ConfigError
from tests.training.test_train import tiny_config

SE = [0.5] * 10


@pytest.mark.parametrize(
    ("scores", "patience", "margin_se", "expected"),
    [
        # a plateau from the third candidate: k = 2 stops after two candidates without gain
        ([5.0, 8.0, 10.0, 10.2, 10.1, 10.3], 2, 1.0, 4),
        # the same with k = 1 stops at the first flat step
        ([5.0, 8.0, 10.0, 10.2, 10.1, 10.3], 1, 1.0, 3),
        # a margin of 0: 10.2 > 10.0 is a gain, 10.1 is not, 10.3 is: no two flat in a row
        ([5.0, 8.0, 10.0, 10.2, 10.1, 10.3], 2, 0.0, None),
        # rising by more than the noise at every step: never stops
        ([1.0, 2.0, 3.0, 4.0, 5.0, 6.0], 1, 1.0, None),
        # a dip then a recovery within the noise of the best: stops
        ([5.0, 9.0, 7.0, 9.4], 2, 1.0, 3),
        # a late jump beyond the noise resets the reference
        ([5.0, 5.1, 7.0, 7.2, 7.1], 2, 1.0, 4),
        # too few candidates to decide
        ([5.0, 5.0], 2, 1.0, None),
    ],
)
def test_stop_index_on_curves_with_a_known_answer(
    scores: list[float], patience: int, margin_se: float, expected: int | None
) -> None:
    assert stop_index(scores, SE[: len(scores)], patience, margin_se) == expected


def test_the_noise_is_the_reference_candidates_standard_error() -> None:
    scores = [10.0, 10.9]
    assert stop_index(scores, [1.0, 0.0], 1, 1.0) == 1  # 10.9 <= 10 + 1.0
    assert stop_index(scores, [0.5, 0.0], 1, 1.0) is None  # 10.9 > 10 + 0.5
    assert evaluation_se({"std_return": 8.0, "n_episodes": 100}) == pytest.approx(0.8)
    assert evaluation_se({"std_return": 8.0, "n_episodes": 1}) == 0.0
    with pytest.raises(ValueError, match="standard errors"):
        stop_index([1.0, 2.0], [0.1], 1, 1.0)


def test_stop_decision_reads_an_evaluation_table() -> None:
    rows = [
        {"step": 5000 * (i + 1), "mean_return": m, "std_return": 5.0, "n_episodes": 100}
        for i, m in enumerate([4.0, 9.0, 9.2, 8.8])
    ]
    assert not stop_decision(rows[:3], "mean_reward", 2, 1.0).stop
    d = stop_decision(rows, "mean_reward", 2, 1.0)
    assert d.stop and d.step == 20000 and d.reference_step == 10000
    assert "step 10000" in d.reason and "0.5000" in d.reason
    # the crash-free criterion: a crash-free candidate after crashing ones is a gain
    crashy = [dict(r, crash_rate=0.1 if i < 3 else 0.0) for i, r in enumerate(rows)]
    assert not stop_decision(crashy, "mean_reward_crash_free", 2, 1.0).stop
    assert not stop_decision([], "mean_reward", 2, 1.0).stop


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("early_stop_patience", 0, "train.early_stop_patience must be an int >= 1 or null"),
        ("early_stop_patience", 2.5, "train.early_stop_patience must be an int"),
        ("early_stop_patience", "3", "train.early_stop_patience must be an int"),
        ("early_stop_margin_se", -0.5, r"train.early_stop_margin_se must be in \[0, inf\)"),
        ("early_stop_margin_se", "one", "train.early_stop_margin_se must be"),
    ],
)
def test_a_bad_rule_is_refused_naming_the_field(
    tmp_path: Path, field: str, value: object, message: str
) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump({"train": {field: value}}))
    with pytest.raises(ConfigError, match=message):
        load_experiment(path)


def test_early_stopping_is_off_by_default() -> None:
    assert TrainConfig().early_stop_patience is None


def test_synthetic_nulls_keep_their_false_positive_rate() -> None:
    """On null grids (equally safe VUTs) the ranking's family-wise false-claim rate with
    early-stopped opponents stays at its level; a rule that stopped the runs of one VUT
    earlier would not (the check can fail)."""
    rng = np.random.default_rng(7)
    fair = null_false_claims(rng, grids=300, vuts=3, seeds=4, patience=2, margin_se=1.0)
    assert fair.stopped_share > 0.5  # the rule does act on these curves
    assert fair.rate_stopped <= 0.10 and fair.rate_full <= 0.10
    biased = null_false_claims(
        rng, grids=300, vuts=3, seeds=6, patience=2, margin_se=1.0, biased_vut=True
    )
    assert biased.rate_stopped > 0.1


@pytest.mark.sumo
def test_a_run_stops_when_its_candidates_stop_moving(tmp_path: Path) -> None:
    """With a margin no candidate can beat, the run stops after ``patience + 1``
    candidates, and what it trained is the prefix of the same run trained to the end."""
    path = tiny_config(tmp_path, 1000, 200)
    full_cfg = load_experiment(path)
    data = yaml.safe_load(path.read_text())
    data["train"].update(early_stop_patience=1, early_stop_margin_se=1e9)
    path.write_text(yaml.safe_dump(data))
    cfg = load_experiment(path)
    stopped = train(cfg, seed=4, out=tmp_path / "stopped")
    full = train(full_cfg, seed=4, out=tmp_path / "full")
    rows = read_eval_table(stopped / "eval.csv")
    full_rows = read_eval_table(full / "eval.csv")
    assert [r["step"] for r in rows] == [200, 400]
    assert len(full_rows) == 5
    keys = ("step", "mean_return", "std_return", "crash_rate", "n_episodes")
    assert [{k: r[k] for k in keys} for r in rows] == [
        {k: r[k] for k in keys} for r in full_rows[:2]
    ]
    spcp = json.loads((stopped / "spcp.json").read_text())
    assert "early stop after the candidate at step 400" in spcp["reason"]
    assert spcp["step"] in (200, 400)
    # a resume of the stopped run stays stopped (it does not train on to the cap)
    train(cfg, seed=4, out=tmp_path / "stopped", resume=True)
    assert [r["step"] for r in read_eval_table(stopped / "eval.csv")] == [200, 400]


def test_a_pipeline_switches_it_on_for_every_experiment(tmp_path: Path) -> None:
    from sumo_ayss.config.pipeline import load_pipeline
    from sumo_ayss.grid.plan import case_experiment

    cfg = load_pipeline(None, early_stop_patience=2)
    assert case_experiment(cfg, "cut_in").train.early_stop_patience == 2
    assert case_experiment(load_pipeline(None), "cut_in").train.early_stop_patience is None
    path = tmp_path / "p.yaml"
    path.write_text(yaml.safe_dump({"early_stop_margin_se": -1}))
    with pytest.raises(ConfigError, match="early_stop_margin_se must be in"):
        load_pipeline(path)
    with pytest.raises(ConfigError, match="early_stop_patience must be an int >= 1"):
        load_pipeline(None, early_stop_patience=0)
