"""Round trip of every run-folder file: the writer the stages call, then the reader, then the
report's loader (no SUMO run, no torch)."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from sumo_ayss.analysis.safety_measures import MEASURE_NAMES
from sumo_ayss.config import RewardConfig, to_dict
from sumo_ayss.records.table import Table, read_table, write_table
from sumo_ayss.run_folder import (
    AYSS_SCHEMA,
    CROSSPLAY_SCHEMA,
    OUTCOME_SCHEMA,
    CaseFolder,
    CrossplayOpponent,
    CrossplayRecord,
    RunConfig,
    RunFolder,
    Seeds,
    StageHeader,
    StudyFolder,
    find_run_dirs,
    read_ayss_json,
    read_crossplay_json,
    read_done_marker,
    read_eval_table,
    read_outcome_json,
    read_progress,
    read_run,
    read_run_config,
    write_ayss_json,
    write_crossplay_json,
    write_done_marker,
    write_eval_table,
    write_outcome_json,
    write_progress,
    write_provenance,
    write_run_config,
    write_spcp,
)
from sumo_ayss.run_folder.metadata import (
    read_command,
    read_seeds,
    read_spcp,
    read_versions,
)
from sumo_ayss.scenarios.outcome import MeanInterval, OutcomeSummary, Proportion
from sumo_ayss.training.checkpoint_files import (
    LATEST_JSON,
    read_checkpoint_state,
    read_latest,
    write_checkpoint_state,
    write_latest,
)
from sumo_ayss.training.selection import Selection
from sumo_ayss.util.errors import CheckpointError, TableError
from sumo_ayss.vuts.catalog import BUILTIN_VUTS
from tests.helpers import loaded_among


def _eval_rows(folder: RunFolder) -> list[dict[str, object]]:
    return [
        {
            "step": step,
            "mean_return": 10.0 + k,
            "std_return": math.nan if k == 0 else 2.0,
            "crash_rate": 0.1,
            "lane_change_rate": 0.9,
            "mean_final_headway_m": 2.5,
            "n_episodes": 100,
            "wall_s": 3.25,
            "checkpoint": folder.checkpoint_model(folder.step_dir(step)),
        }
        for k, step in enumerate((5000, 10000))
    ]


def _summary() -> OutcomeSummary:
    return OutcomeSummary(
        case="cut_in",
        n_episodes=200,
        crash_rate=Proportion(21, 200, 0.105, 0.07, 0.155, 0.95),
        lane_change_rate=Proportion(200, 200, 1.0, 0.98, 1.0, 0.95),
        mean_return=MeanInterval(200, 8.3, 7.1, 9.5, 0.95),
        mean_final_headway_m=MeanInterval(200, 0.33, -2.7, 3.4, 0.95),
        lc_no_collision_return=MeanInterval(179, 10.4, 9.4, 11.4, 0.95),
        lc_no_collision_final_headway_m=MeanInterval(1, 0.42, math.nan, math.nan, 0.95),
    )


def _ayss_table(n: int = 5) -> Table:
    return Table(
        AYSS_SCHEMA,
        {
            "sample": np.arange(n),
            "v_pov_mps": np.linspace(10, 20, n),
            "v_vut_mps": np.linspace(12, 22, n),
            "h_m": np.linspace(0.5, 4.5, n),
            "same_lane": np.zeros(n, dtype=int),
            "action": np.arange(n) % 3,
            "target_speed_mps": np.full(n, 15.0),
            "ttc_s": np.array([np.inf, 2.0, 3.0, np.inf, 1.5])[:n],
            "indicator_name": np.full(n, "delta_v_bar_mps"),
            "indicator": -np.linspace(0.1, 2.0, n),
            "h_after_m": np.linspace(0.4, 4.4, n),
            "delta_v_bar_before_mps": np.full(n, np.nan),
        },
    )


@pytest.fixture
def run_folder(tmp_path: Path) -> RunFolder:
    """A run folder with every file, each written by its writer."""
    folder = StudyFolder(tmp_path).run("cut_in", "pi2", 3)
    folder.checkpoints.mkdir(parents=True)
    env = {
        "case": "cut_in",
        "vut": "pi2",
        "vuts": {k: to_dict(v) for k, v in BUILTIN_VUTS.items()},
        "reward": to_dict(RewardConfig()),
    }
    train = {"total_timesteps": 10000, "eval_every": 5000}
    write_run_config(folder.config, RunConfig("pi2", 3, {"env": env, "train": train}))
    command, versions = "python -m sumo_ayss.train --seed 3", {"python": "3.11.2", "numpy": "2.0.0"}
    write_provenance(folder, command, versions, Seeds(3, 3, 2024))
    rows = _eval_rows(folder)
    write_eval_table(folder.eval_table, rows)
    step_dir = folder.step_dir(10000)
    step_dir.mkdir()
    write_latest(folder.checkpoints / LATEST_JSON, step_dir)
    write_checkpoint_state(step_dir / "state.json", {"num_timesteps": 10000, "next_eval": 15000})
    choice = Selection(1, 10000, 11.0, "mean_reward", "the best")
    write_spcp(folder.spcp_json, choice, str(rows[1]["checkpoint"]), rows[1])
    write_progress(folder.path, "done")
    header = StageHeader("runs/cut_in/pi2/seed_3", "cut_in", "pi2", 3, 10000)
    write_table(folder.outcome_csv, _outcome_table())
    write_outcome_json(
        folder.outcome_json, header, {"n": 2, "seed": 4242}, {}, _summary().as_dict(), 1.5
    )
    write_table(folder.ayss_csv, _ayss_table())
    ayss_settings = {"n_samples": 100, "seed": 7}
    summary = {"case": "cut_in", "indicator_name": "delta_v_bar_mps", "counts": {"kept": 5}}
    write_ayss_json(folder.ayss_json, header, ayss_settings, summary)
    write_done_marker(folder.evaluate_done, "abc123")
    return folder


def _outcome_table() -> Table:
    return Table(
        OUTCOME_SCHEMA,
        {
            "scenario": [0, 1],
            "v_pov0_mps": [20.0, 25.0],
            "v_vut0_mps": [22.0, 21.0],
            "gap0_m": [3.0, 10.0],
            "episode_return": [12.5, -1.0],
            "collided": [False, True],
            "lane_changed": [True, True],
            "final_headway_m": [1.5, -0.2],
            "n_steps": [25, 7],
            "near_miss_pay": [12.5, 9.0],
            "vut_mean_speed_mps": [21.5, 0.5],
            **{name: [1.25, 0.5] for name in MEASURE_NAMES},
        },
    )


def test_every_file_reads_back_as_written(run_folder: RunFolder) -> None:
    f = run_folder
    config = read_run_config(f.config)
    assert (config.vut, config.seed) == ("pi2", 3) and config.experiment["train"]["eval_every"]
    assert read_command(f.command) == "python -m sumo_ayss.train --seed 3"
    assert read_versions(f.versions) == {"python": "3.11.2", "numpy": "2.0.0"}
    assert read_seeds(f.seeds) == Seeds(3, 3, 2024)
    rows = read_eval_table(f.eval_table)
    expected = _eval_rows(f)
    assert math.isnan(rows[0]["std_return"]) and rows[1] == expected[1]
    assert {k: v for k, v in rows[0].items() if k != "std_return"} == {
        k: v for k, v in expected[0].items() if k != "std_return"
    }
    assert read_latest(f.checkpoints / LATEST_JSON) == (10000, "step_000010000")
    assert read_checkpoint_state(f.step_dir(10000) / "state.json")["next_eval"] == 15000
    spcp = read_spcp(f.spcp_json)
    assert (spcp.step, spcp.score, spcp.criterion, spcp.reason) == (
        10000,
        11.0,
        "mean_reward",
        "the best",
    )
    assert spcp.checkpoint == "checkpoints/step_000010000/model.zip"
    progress = read_progress(f.path)
    assert progress is not None and progress["stage"] == "done"
    assert read_table(f.outcome_csv, OUTCOME_SCHEMA).equals(_outcome_table())
    assert read_table(f.ayss_csv, AYSS_SCHEMA).equals(_ayss_table())
    record = read_outcome_json(f.outcome_json)
    assert record.settings == {"n": 2, "seed": 4242} and record.spcp_step == 10000
    o, s = record.outcome, _summary()
    assert o.n == 200 and o.crash_rate.value == s.crash_rate.value
    assert (o.crash_rate.lo, o.crash_rate.hi) == (s.crash_rate.lo, s.crash_rate.hi)
    assert o.lane_change_rate is not None and o.lane_change_rate.value == 1.0
    assert (o.mean_return.value, o.mean_return.lo, o.mean_return.hi) == (8.3, 7.1, 9.5)
    assert o.mean_final_headway_m.value == 0.33
    sub = o.lane_change_no_collision
    assert sub is not None and sub.n == 179 and sub.mean_return.value == 10.4
    assert sub.mean_final_headway_m.value == 0.42 and math.isnan(sub.mean_final_headway_m.lo)
    ayss = read_ayss_json(f.ayss_json)
    assert ayss.settings == {"n_samples": 100, "seed": 7}
    assert (ayss.indicator_name, ayss.counts) == ("delta_v_bar_mps", {"kept": 5})
    assert read_done_marker(f.evaluate_done) == "abc123"


def test_report_loads_what_the_writers_wrote(run_folder: RunFolder, tmp_path: Path) -> None:
    assert find_run_dirs([tmp_path]) == [run_folder.path.resolve()]
    run = read_run(run_folder.path)
    assert run.problems == ()
    assert (run.case, run.vut, run.seed) == ("cut_in", "pi2", 3)
    assert run.reward == RewardConfig() and run.vut_description
    assert run.versions == {"python": "3.11.2", "numpy": "2.0.0"}
    assert run.eval_curve is not None and run.eval_curve["step"].tolist() == [5000, 10000]
    assert run.eval_curve["mean_return"].tolist() == [10.0, 11.0]
    assert run.spcp is not None and run.spcp.step == 10000
    assert run.outcome is not None and run.outcome.crash_rate.value == 0.105
    assert run.outcome.lane_change_no_collision is not None
    assert run.ayss is not None and len(run.ayss) == 5
    assert run.ayss.indicator_name == "delta_v_bar_mps"
    assert run.ayss.h.tolist() == _ayss_table()["h_m"].tolist()
    training = run.training
    assert (training.total_timesteps, training.eval_every) == (10000, 5000)
    assert (training.n_candidates, training.spcp_step, training.still_improving) == (
        2,
        10000,
        True,
    )


def test_readers_name_the_file_and_field(run_folder: RunFolder) -> None:
    f = run_folder
    f.outcome_json.write_text('{"settings": {}, "summary": {"n_episodes": 2}}')
    with pytest.raises(TableError, match=r"outcome\.json: summary: missing field 'crash_rate'"):
        read_outcome_json(f.outcome_json)
    f.outcome_json.write_text(
        '{"settings": {}, "summary": {"n_episodes": 2, "crash_rate": {"value": "x"}}}'
    )
    with pytest.raises(TableError, match=r"summary\.crash_rate: value: expected int or float"):
        read_outcome_json(f.outcome_json)
    f.seeds.write_text('{"train_seed": 1, "sumo_seed": "x", "eval_seed": 2}')
    with pytest.raises(CheckpointError, match=r"seeds\.json: sumo_seed: expected int, got 'x'"):
        read_seeds(f.seeds)
    f.config.write_text("vut: pi2\nenv: {}\n")
    with pytest.raises(CheckpointError, match=r"config\.yaml: unreadable run configuration"):
        read_run_config(f.config)
    f.spcp_json.write_text('{"score": 1}')
    with pytest.raises(CheckpointError, match=r"spcp\.json: missing field 'step'"):
        read_spcp(f.spcp_json)


def test_one_json_reader_one_error_family(tmp_path: Path) -> None:
    """Every stored JSON file is read by ``jsonio.read_json``: a broken file raises the same
    message whichever reader meets it, as a ``StoredFileError`` (the base of the
    ``TableError`` of summaries and the ``CheckpointError`` of a run's own records)."""
    from sumo_ayss.run_folder.adaptive import read_adaptive
    from sumo_ayss.training.checkpoint_files import read_checkpoint_state, read_latest
    from sumo_ayss.util.errors import StoredFileError

    readers = [read_outcome_json, read_seeds, read_spcp, read_latest, read_checkpoint_state]
    readers.append(read_adaptive)
    for reader in readers:
        for text, message in [
            (None, "file not found"),
            ("{", "unreadable JSON: not valid JSON"),
            ("[1]", "expected a JSON object, got list"),
        ]:
            path = tmp_path / f"{reader.__name__}.json"
            path.unlink(missing_ok=True)
            if text is not None:
                path.write_text(text)
            with pytest.raises(StoredFileError) as info:
                reader(path)
            assert str(info.value).startswith(f"{path}: {message}"), reader.__name__
    assert issubclass(TableError, StoredFileError) and issubclass(CheckpointError, StoredFileError)
    with pytest.raises(CheckpointError):
        read_seeds(tmp_path / "missing.json")
    with pytest.raises(TableError):
        read_outcome_json(tmp_path / "missing.json")
    bad = tmp_path / "adaptive.json"
    bad.write_text('{"format": 1, "looks": [{"n_seeds": true}]}')
    with pytest.raises(TableError, match=r"adaptive\.json: looks\[0\]: n_seeds: expected int"):
        read_adaptive(bad)


def test_one_csv_reader_one_error_family(run_folder: RunFolder, tmp_path: Path) -> None:
    """Every stored CSV file (the episode tables, ``eval.csv``, the study's ``ranking.csv``
    and ``measures.csv``) is read by ``table.read_table``: the same messages, naming the file,
    the column and the row, as a ``StoredFileError`` (``eval.csv``, a run's own record,
    raises ``CheckpointError``; the others ``TableError``)."""
    from sumo_ayss.run_folder.study import read_measures_csv, read_ranking_csv
    from sumo_ayss.util.errors import StoredFileError

    f = run_folder
    rows = read_eval_table(f.eval_table)
    lines = f.eval_table.read_text().splitlines()
    f.eval_table.write_text("\n".join([*lines, lines[2].replace(",100,", ",two,")]) + "\n")
    with pytest.raises(CheckpointError, match=r"eval\.csv: column 'n_episodes', row 2: expected"):
        read_eval_table(f.eval_table)
    kept = read_eval_table(f.eval_table, skip_bad_rows=True)
    assert [r["step"] for r in kept] == [r["step"] for r in rows] == [5000, 10000]
    curve = read_run(f.path).eval_curve
    assert curve is not None and curve.n_dropped == 1 and len(curve) == 2
    f.eval_table.write_text("\n".join([*lines, lines[2].replace(",3.25,", ",inf,")]) + "\n")
    with pytest.raises(CheckpointError, match=r"eval\.csv, column 'wall_s', row 2: inf not"):
        read_eval_table(f.eval_table)
    assert read_eval_table(tmp_path / "eval.csv") == []  # not written yet: no candidate
    for reader in (read_ranking_csv, read_measures_csv):
        path = tmp_path / "study.csv"
        path.write_text("case\n")
        with pytest.raises(TableError, match=r"study\.csv: missing column\(s\) \['"):
            reader(path)
        with pytest.raises(StoredFileError, match=r"x\.csv: table file not found"):
            reader(tmp_path / "x.csv")


def test_config_yaml_holds_the_vut_once_and_legacy_folders_still_read(tmp_path: Path) -> None:
    path = tmp_path / "config.yaml"
    write_run_config(path, RunConfig("pi2", 3, {"env": {"case": "cut_in"}, "train": {}}))
    data = yaml.safe_load(path.read_text())
    assert "vut" not in data and data["env"]["vut"] == "pi2" and data["seed"] == 3
    config = read_run_config(path)
    assert (config.vut, config.seed, config.experiment["env"]["vut"]) == ("pi2", 3, "pi2")
    # A folder written before the VUT was stored once: the top-level vut is the run's.
    path.write_text(yaml.safe_dump({"vut": "pi1", "seed": 0, "env": {"case": "cut_in"}}))
    config = read_run_config(path)
    assert config.vut == "pi1" and config.experiment == {"env": {"case": "cut_in", "vut": "pi1"}}
    path.write_text(yaml.safe_dump({"seed": 0, "env": {"case": "cut_in", "vut": ""}}))
    with pytest.raises(CheckpointError, match="vut must be a non-empty string"):
        read_run_config(path)


def test_crossplay_files_of_a_case_folder_round_trip(tmp_path: Path) -> None:
    folder = StudyFolder(tmp_path).case("cut_in")
    assert StudyFolder(tmp_path).run("cut_in", "pi1", 0).path.parent.parent == folder.path
    table = Table(
        CROSSPLAY_SCHEMA,
        {
            "vut": ["pi1", "pi2"],
            "opponent_vut": ["pi1", "pi1"],
            "opponent_seed": np.array([0, 0], dtype=np.int64),
            "scenario": np.array([0, 0], dtype=np.int64),
            "episode_return": [1.5, 2.5],
            "collided": np.array([False, True]),
            "final_headway_m": [3.0, -0.5],
            "n_steps": np.array([7, 4], dtype=np.int64),
            "near_miss_pay": [1.5, 12.5],
            "vut_mean_speed_mps": [20.0, 19.25],
            **{name: [0.5, np.nan] for name in MEASURE_NAMES},
        },
    )
    write_table(folder.crossplay_csv, table)
    back = read_table(folder.crossplay_csv, CROSSPLAY_SCHEMA)
    assert list(back["vut"]) == ["pi1", "pi2"] and list(back["collided"]) == [False, True]
    record = CrossplayRecord(
        "cut_in", 6, 4242, (CrossplayOpponent("pi1", 0, "ab" * 32),), ("pi1", "pi2"), 1.25
    )
    write_crossplay_json(folder.crossplay_json, record)
    assert read_crossplay_json(folder.crossplay_json) == record
    from sumo_ayss.stages.crossplay_cells import crossplay_inputs

    assert crossplay_inputs(record) == crossplay_inputs(
        dataclasses.replace(record, vuts=(), wall_s=0.0)
    )
    assert crossplay_inputs(record) != crossplay_inputs(dataclasses.replace(record, n=7))
    folder.crossplay_json.write_text('{"case": "cut_in", "n": 6, "seed": 1, "opponents": [{}]}')
    with pytest.raises(TableError, match=r"crossplay\.json: opponents\[0\]: missing field 'vut'"):
        read_crossplay_json(folder.crossplay_json)


def test_run_folder_imports_neither_torch_nor_libsumo() -> None:
    assert loaded_among("import sumo_ayss.run_folder", ("torch", "libsumo")) == []


def test_adaptive_record_round_trips_and_refuses_another_layout(tmp_path: Path) -> None:
    import math

    from sumo_ayss.analysis.sequential import SettleCheck
    from sumo_ayss.run_folder import AdaptiveLook, AdaptiveRecord, read_adaptive, write_adaptive

    check = SettleCheck(4, math.nan, 0.027, "a", "b", 0.11, 0.05, False)
    # the stored look holds the analysis's check field by field (storage imports no analysis)
    look = AdaptiveLook(**dataclasses.asdict(check))
    assert [f.name for f in dataclasses.fields(AdaptiveLook)] == [
        f.name for f in dataclasses.fields(SettleCheck)
    ]
    record = AdaptiveRecord((0, 1, 2, 3), 6, 0.05, (0, 1, 2, 3, 4), (look,))
    path = tmp_path / "adaptive.json"
    write_adaptive(path, record)
    back = read_adaptive(path)
    assert back.seeds == record.seeds and back.first_seeds == (0, 1, 2, 3)
    assert math.isnan(back.looks[0].omnibus_p) and back.looks[0].ends_p == 0.11
    from sumo_ayss.grid.adaptive import same_plan

    assert not back.settled and same_plan(back, (0, 1, 2, 3), 6, 0.05)
    assert not same_plan(back, (0, 1, 2), 6, 0.05)
    path.write_text('{"format": 1, "looks": "x"}')
    with pytest.raises(TableError, match=r"adaptive\.json: looks: expected list, got .x."):
        read_adaptive(path)


def test_each_file_of_a_folder_is_named_once(tmp_path: Path) -> None:
    """A folder record's attribute is the file's path on a folder and, on the class, the
    descriptor that names it (what a help text or a heading quotes)."""
    folder = RunFolder(tmp_path)
    assert folder.outcome_json == tmp_path / "outcome.json"
    assert RunFolder.outcome_json.name == folder.outcome_json.name == "outcome.json"
    assert CaseFolder.crossplay_csv.name == "crossplay.csv"
