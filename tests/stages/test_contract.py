"""The stage contract: one fingerprint, outputs and a done marker for every stage; the
markers that folders written before it hold are still read as done."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest

from sumo_ayss import discriminability as disc
from sumo_ayss.analysis.discriminability import BoxGrid
from sumo_ayss.config import AyssConfig, EnvConfig, ExperimentConfig, TrainConfig, load_pipeline
from sumo_ayss.run_folder import (
    CaseFolder,
    CrossplayOpponent,
    CrossplayRecord,
    DiagonalCheck,
    RunFolder,
    StageHeader,
    StudyFolder,
    read_crossplay_json,
    read_done_marker,
    write_ayss_json,
    write_crossplay_json,
    write_outcome_json,
)
from sumo_ayss.stages import (
    AyssStage,
    CrossplayStage,
    DiscriminabilityStage,
    EvaluateStage,
    OutcomeStage,
    TrainStage,
    fingerprint,
    is_done,
)
from sumo_ayss.training.run_metadata import write_metadata
from sumo_ayss.util.errors import CheckpointError, TableError

ROOT = Path(__file__).resolve().parents[2]


def test_fingerprint_hashes_json_with_sorted_keys_and_files_by_their_bytes(
    tmp_path: Path,
) -> None:
    assert fingerprint({"a": 1, "b": [1, 2]}) == fingerprint({"b": [1, 2], "a": 1})
    assert fingerprint({"a": (1, 2)}) == fingerprint({"a": [1, 2]})  # as stored in JSON
    assert fingerprint({"a": 1}) != fingerprint({"a": 2})
    assert len(fingerprint("x")) == 16
    path = tmp_path / "model.zip"
    path.write_bytes(b"one")
    before = fingerprint(path, 3)
    path.write_bytes(b"two")
    assert fingerprint(path, 3) != before  # the file's bytes count, not its name


def test_evaluate_marker_keeps_the_fingerprint_older_folders_hold(tmp_path: Path) -> None:
    """The values ``jobs._fingerprint`` wrote into ``evaluate.done.json`` before the
    contract (computed with that code): such folders are still done."""
    folder = RunFolder(tmp_path)
    folder.spcp_zip.write_bytes(b"model weights")
    default = EvaluateStage(folder, 200, AyssConfig(n_samples=100_000))
    assert default.key() == "956939e64e2ae2b9"
    custom = EvaluateStage(folder, 12, AyssConfig(n_samples=3000, seed=5))
    assert custom.key() == "b0111c505e8ab989"
    folder.evaluate_done.write_text('{"inputs": "956939e64e2ae2b9"}')  # as written then
    assert not is_done(default)  # no outputs yet
    for path in default.outputs:
        path.write_text("x")
    assert is_done(default) and not is_done(custom)
    custom.mark_done()
    assert read_done_marker(folder.evaluate_done) == custom.key() and is_done(custom)
    folder.spcp_zip.write_bytes(b"another SPCP")
    assert not is_done(custom)  # a retrained SPCP is evaluated again


def test_discriminability_fingerprint_is_the_one_older_records_hold(tmp_path: Path) -> None:
    settings = {"grid": BoxGrid().to_dict(), "threshold_mps2": 0.1, "decisions": 1}
    stage = DiscriminabilityStage(
        CaseFolder(tmp_path), EnvConfig(case="car_following"), ("pi1", "pi2"), settings
    )
    assert stage.key() == "7bbdfd10df3b0795"  # discriminability.fingerprint's, before
    assert stage.recorded() is None and not is_done(stage)
    stage.folder.discriminability_json.write_text("{not json")
    assert stage.recorded() is None  # unreadable: measured again


@pytest.mark.parametrize(
    ("config", "study"),
    [
        ("configs/paper.yaml", "results/paper"),
        ("configs/ladders/reaction.yaml", "results/ladders/reaction_a"),
    ],
)
def test_committed_discriminability_records_are_done(config: str, study: str) -> None:
    """The pipeline's own check, on the committed studies: nothing to measure again."""
    cfg = load_pipeline(ROOT / config, out=ROOT / study)
    for case in cfg.grid.cases:
        settings = {"grid": BoxGrid().to_dict(), "threshold_mps2": 0.1, "decisions": 1}
        env = disc.pipeline_env(cfg, case)
        folder = StudyFolder(cfg.out).case(case)
        assert is_done(DiscriminabilityStage(folder, env, tuple(cfg.grid.vuts), settings))


def test_train_stage_is_done_with_the_stored_config_and_both_spcp_files(tmp_path: Path) -> None:
    cfg = ExperimentConfig(train=TrainConfig(total_timesteps=10_000, eval_every=5000))
    folder = RunFolder(tmp_path / "car_following" / "pi1" / "seed_2")
    stage = TrainStage(folder, cfg, 2)
    assert stage.recorded() is None and not is_done(stage)
    write_metadata(folder, cfg, 2, ["--seed", "2"])  # what train writes first
    assert stage.recorded() == stage.key() and not is_done(stage)  # started, not selected
    folder.spcp_zip.write_bytes(b"model")
    folder.spcp_json.write_text("{}")
    assert is_done(stage)
    quiet = dataclasses.replace(cfg, train=dataclasses.replace(cfg.train, progress_bar=False))
    assert is_done(TrainStage(folder, quiet, 2))  # a display option is not an input
    longer = dataclasses.replace(cfg, train=dataclasses.replace(cfg.train, total_timesteps=20_000))
    assert not is_done(TrainStage(folder, longer, 2))
    assert not is_done(TrainStage(folder, cfg, 3))
    folder.config.write_text("seed: [\n")
    with pytest.raises(CheckpointError, match=r"config\.yaml: unreadable run configuration"):
        is_done(stage)


def test_outcome_and_ayss_stages_compare_the_settings_their_json_records(tmp_path: Path) -> None:
    folder = RunFolder(tmp_path)
    header = StageHeader("run", "car_following", "pi1", 0, 500)
    summary = {
        "case": "car_following",
        "n_episodes": 2,
        "crash_rate": {"value": 0.0, "lo": 0.0, "hi": 0.5, "k": 0, "n": 2, "level": 0.95},
        "mean_return": {"n": 2, "mean": 1.0, "lo": 0.5, "hi": 1.5, "level": 0.95},
        "mean_final_headway_m": {"n": 2, "mean": 3.0, "lo": 2.0, "hi": 4.0, "level": 0.95},
    }
    write_outcome_json(folder.outcome_json, header, {"n": 2, "seed": 7}, {}, summary, 1.0)
    folder.outcome_csv.write_text("x")
    assert is_done(OutcomeStage(folder, 2, 7)) and not is_done(OutcomeStage(folder, 3, 7))
    ayss = AyssConfig(n_samples=50, seed=3)
    write_ayss_json(folder.ayss_json, header, ayss.to_dict(), {"indicator_name": "x", "counts": {}})
    folder.ayss_csv.write_text("x")
    assert not is_done(AyssStage(folder, ayss))  # ayss_bins.csv is an output too
    folder.ayss_bins.write_text("x")
    assert is_done(AyssStage(folder, ayss))
    assert not is_done(AyssStage(folder, dataclasses.replace(ayss, n_samples=60)))
    folder.ayss_json.write_text("[]")
    with pytest.raises(TableError, match=r"ayss\.json: expected a JSON object"):
        is_done(AyssStage(folder, ayss))


def test_crossplay_stage_needs_the_same_opponents_and_a_diagonal_check(tmp_path: Path) -> None:
    folder = CaseFolder(tmp_path)
    pool = (CrossplayOpponent("pi1", 0, "a" * 64), CrossplayOpponent("pi2", 0, "b" * 64))
    requested = CrossplayRecord("cut_in", 6, 4242, pool, ("pi1", "pi2"), 0.0)
    stage = CrossplayStage(folder, requested)
    done = dataclasses.replace(requested, wall_s=3.5, diagonal=(DiagonalCheck("pi1", 0, 6, 6),))
    write_crossplay_json(folder.crossplay_json, dataclasses.replace(done, diagonal=()))
    folder.crossplay_csv.write_text("x")
    assert not is_done(stage)  # a record from before the diagonal check: run again
    write_crossplay_json(folder.crossplay_json, done)
    assert is_done(stage)
    assert not is_done(CrossplayStage(folder, dataclasses.replace(requested, n=7)))
    other = (pool[0], CrossplayOpponent("pi2", 0, "c" * 64))  # pi2's SPCP retrained
    assert not is_done(CrossplayStage(folder, dataclasses.replace(requested, opponents=other)))
    # A record without VUT keys (before issue 36) is done for the same VUT names; with
    # keys, another definition under a name is another table.
    keyed = dataclasses.replace(requested, vut_keys=("k1", "k2"))
    assert is_done(CrossplayStage(folder, keyed))
    assert not is_done(CrossplayStage(folder, dataclasses.replace(requested, vuts=("pi1",))))
    write_crossplay_json(folder.crossplay_json, dataclasses.replace(done, vut_keys=("k1", "k2")))
    assert read_crossplay_json(folder.crossplay_json).vut_keys == ("k1", "k2")
    assert is_done(CrossplayStage(folder, keyed))
    redefined = dataclasses.replace(requested, vut_keys=("k1", "k3"))
    assert not is_done(CrossplayStage(folder, redefined))
    write_crossplay_json(folder.crossplay_json, done)
    data = json.loads(folder.crossplay_json.read_text())
    del data["rollout"]  # written before issue 21: driven as pairs, run again
    folder.crossplay_json.write_text(json.dumps(data))
    assert not is_done(stage)
