"""A leaderboard that grows in place (issue 36): add, drop, redefine or rename one VUT of a
finished study in the same folder, and only that VUT's work runs again; the merged
cross-play table equals a fresh study's. Bad inputs: another study's folder is refused
before any job, two names for one vehicle are warned about, a stale adaptive record is
ignored and said so."""

from __future__ import annotations

import dataclasses
import hashlib
import logging
from pathlib import Path

import pytest
import yaml

from sumo_ayss.commands.pipeline import run_pipeline
from sumo_ayss.config import PROJECT_ROOT, to_dict
from sumo_ayss.crossplay import run_case
from sumo_ayss.grid.adaptive import case_seeds, grid_vuts, read_record, stale_record
from sumo_ayss.grid.study import prepare_out, same_vehicles
from sumo_ayss.pipeline import final_messages, load_pipeline, plan_jobs
from sumo_ayss.run_folder import (
    AdaptiveRecord,
    RunConfig,
    read_crossplay_json,
    read_run,
    write_adaptive,
    write_run_config,
)
from sumo_ayss.util.errors import ConfigError
from tests.helpers import TINY_AGENT

GAP25 = {"model": "IDM", "params": {"minGap": 25.0, "accel": 3.0, "decel": 5.0}}


def write_study(folder: Path, vuts: list[str], defs: dict, **extra) -> Path:
    """A one-case (car-following), one-seed pipeline at a tiny budget in ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    exp = yaml.safe_load((PROJECT_ROOT / "configs" / "car_following.yaml").read_text())
    exp["agent"] = TINY_AGENT
    exp["train"].update(n_eval_scenarios=5)
    (folder / "cf.yaml").write_text(yaml.safe_dump(exp))
    pipe = {
        "grid": {"cases": ["car_following"], "vuts": vuts, "seeds": [0]},
        "experiments": {"car_following": "cf.yaml"},
        "out": "runs",
        "total_timesteps": 600,
        "eval_every": 300,
        "evaluate": {"n_outcome": 10, "n_ayss": 2000},
        "vuts": defs,
        "workers": 1,
        **extra,
    }
    path = folder / "pipe.yaml"
    path.write_text(yaml.safe_dump(pipe))
    return path


def trained(out: Path) -> dict[str, str]:
    """``{vut: SHA-256 of its seed-0 spcp.zip}`` of a study's case."""
    case = out / "car_following"
    return {
        p.parent.parent.name: hashlib.sha256(p.read_bytes()).hexdigest()
        for p in case.glob("*/seed_0/spcp.zip")
    }


def table(out: Path) -> bytes:
    return (out / "car_following" / "crossplay.csv").read_bytes()


def full_rerun(out: Path, vuts: list[str], where: Path) -> bytes:
    """The case's cross-play driven whole, over the same runs (``force``)."""
    runs = [read_run(out / "car_following" / v / "seed_0") for v in vuts]
    run_case(runs, where, n=10, seed=4242, force=True)
    return (where / "crossplay.csv").read_bytes()


@pytest.mark.sumo
@pytest.mark.timeout(900)  # two studies and a third VUT at a tiny budget: ~2-5 min on 2 busy cores
def test_add_a_vut_trains_only_its_runs_and_crossplay_equals_a_fresh_study(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    path = write_study(tmp_path, ["pi1", "pi2"], {"gap25": GAP25})
    out = tmp_path / "runs"
    first = run_pipeline(load_pipeline(path), live=False)
    assert all(s.state == "done" for s in first.statuses)
    before = trained(out)

    # Add a VUT: only its job trains; cross-play drives its 5 new cells, keeps 4.
    path = write_study(tmp_path, ["pi1", "pi2", "gap25"], {"gap25": GAP25})
    with caplog.at_level(logging.INFO):
        grown = run_pipeline(load_pipeline(path), live=False)
    stages = {s.spec.vut: s.stages["train"] for s in grown.statuses}
    assert stages == {"pi1": "skipped", "pi2": "skipped", "gap25": "done"}
    assert trained(out) == {**before, "gap25": trained(out)["gap25"]}
    assert "cross-play drives 5 new cells (VUT x SPCP) and keeps 4" in caplog.text
    fresh_path = write_study(tmp_path / "fresh", ["pi1", "pi2", "gap25"], {"gap25": GAP25})
    fresh = run_pipeline(load_pipeline(fresh_path), live=False)
    assert all(s.stages["train"] == "done" for s in fresh.statuses)
    assert table(out) == table(tmp_path / "fresh" / "runs")  # merged = a fresh study's
    record = read_crossplay_json(out / "car_following" / "crossplay.json")
    assert record.vuts == ("pi1", "pi2", "gap25") and len(record.diagonal) == 3
    assert sorted(grown.analyses[0].runs) == ["gap25", "pi1", "pi2"]


@pytest.mark.sumo
@pytest.mark.timeout(900)  # a study, then three changes to it: ~2-5 min on 2 busy cores
def test_drop_redefine_rename_one_vut_runs_only_its_work(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    path = write_study(tmp_path, ["pi1", "pi2", "gap25"], {"gap25": GAP25})
    out = tmp_path / "runs"
    first = run_pipeline(load_pipeline(path), live=False)
    assert all(s.state == "done" for s in first.statuses)
    before = trained(out)

    # Drop a VUT: nothing trains or drives; the table is the kept cells'.
    path = write_study(tmp_path, ["pi1", "gap25"], {"gap25": GAP25})
    caplog.clear()
    with caplog.at_level(logging.INFO):
        shrunk = run_pipeline(load_pipeline(path), live=False)
    assert {s.stages["train"] for s in shrunk.statuses} == {"skipped"}
    assert "cross-play drives 0 new cells (VUT x SPCP) and keeps 4" in caplog.text
    assert table(out) == full_rerun(out, ["pi1", "gap25"], tmp_path / "full_drop")
    assert sorted(shrunk.analyses[0].runs) == ["gap25", "pi1"]

    # Redefine a VUT: only it retrains (its old run set aside); its cells are driven again.
    gap30 = {**GAP25, "params": {**GAP25["params"], "minGap": 30.0}}
    path = write_study(tmp_path, ["pi1", "gap25"], {"gap25": gap30})
    caplog.clear()
    with caplog.at_level(logging.INFO):
        redefined = run_pipeline(load_pipeline(path), live=False)
    stages = {s.spec.vut: s.stages["train"] for s in redefined.statuses}
    assert stages == {"pi1": "skipped", "gap25": "done"}
    assert trained(out)["pi1"] == before["pi1"]
    note = [m for m in final_messages(redefined) if m.startswith("NOTE:")]
    assert (
        note
        and "VUT gap25 was redefined (env.vuts[env.vut].params.minGap: 25.0 -> 30.0)" in (note[0])
    )
    assert list((out / "car_following" / ".superseded").glob("gap25-*/seed_0/spcp.zip"))
    assert "cross-play drives 3 new cells (VUT x SPCP) and keeps 1" in caplog.text
    assert table(out) == full_rerun(out, ["pi1", "gap25"], tmp_path / "full_redefine")

    # Rename a VUT without changing it: its runs and cells are reused under the new name.
    kept = trained(out)["gap25"]
    path = write_study(tmp_path, ["pi1", "far30"], {"far30": gap30})
    caplog.clear()
    with caplog.at_level(logging.INFO):
        renamed = run_pipeline(load_pipeline(path), live=False)
    assert {s.stages["train"] for s in renamed.statuses} == {"skipped"}
    after = trained(out)  # pi2's runs stay on disk, out of the grid
    assert (after["pi1"], after["far30"]) == (before["pi1"], kept) and "gap25" not in after
    assert any("VUT far30 is gap25 renamed" in m for m in final_messages(renamed))
    assert "cross-play drives 0 new cells (VUT x SPCP) and keeps 4" in caplog.text
    assert read_run(out / "car_following" / "far30" / "seed_0").vut == "far30"
    assert table(out) == full_rerun(out, ["pi1", "far30"], tmp_path / "full_rename")


def test_an_out_folder_of_another_budget_or_case_set_is_refused_before_any_job(
    tmp_path: Path,
) -> None:
    path = write_study(tmp_path, ["pi1", "pi2"], {})
    cfg = load_pipeline(path)
    job = plan_jobs(cfg)[1]  # pi2, seed 0
    train = dataclasses.replace(job.experiment.train, total_timesteps=900)
    exp = dataclasses.replace(job.experiment, train=train)
    job.folder.path.mkdir(parents=True)
    write_run_config(job.folder.config, RunConfig("pi2", 0, to_dict(exp)))
    with pytest.raises(ConfigError, match=r"train\.total_timesteps: 900 -> 600 \(stored -> asked"):
        run_pipeline(cfg, live=False)
    assert not (cfg.out / "car_following" / "pi1").exists()  # no job ran
    job.folder.config.unlink()
    cut_in = cfg.out / "cut_in" / "pi1" / "seed_0"
    cut_in.mkdir(parents=True)
    write_run_config(cut_in / "config.yaml", RunConfig("pi1", 0, to_dict(job.experiment)))
    with pytest.raises(ConfigError, match=r"holds runs of case\(s\) \['cut_in'\]"):
        run_pipeline(cfg, live=False)


def test_two_names_for_one_vehicle_are_warned_about(tmp_path: Path) -> None:
    """Equal definitions (descriptions aside) under two names: every comparison is a tie."""
    one = {"model": "IDM", "params": {"minGap": 5.0}, "description": "one"}
    twin = {**one, "description": "the other"}
    path = write_study(tmp_path, ["a", "b", "pi2"], {"a": one, "b": twin})
    assert same_vehicles(plan_jobs(load_pipeline(path))) == [
        "VUTs a, b are the same vehicle in car_following (identical definitions, "
        "descriptions aside): every comparison between them is a tie"
    ]
    path = write_study(tmp_path, ["a", "pi2"], {"a": one})
    assert same_vehicles(plan_jobs(load_pipeline(path))) == []


def test_a_stale_adaptive_record_is_ignored_and_said_so(tmp_path: Path) -> None:
    path = write_study(tmp_path, ["pi1", "pi2"], {}, max_seeds=4)
    cfg = load_pipeline(path)
    record = tmp_path / "runs" / "car_following" / "adaptive.json"
    record.parent.mkdir(parents=True)
    old = (("pi1", "k1"), ("ob40", "k2"))
    write_adaptive(record, AdaptiveRecord((0,), 4, 0.05, (0, 1), (), old))
    assert read_record(cfg, "car_following") is None and case_seeds(cfg, "car_following") == (0,)
    line = stale_record(cfg, "car_following")
    assert line is not None and "looked at VUTs ob40, pi1" in line and "pi1 since redefined" in line
    assert "the grid's are pi1, pi2: the record is ignored" in line
    assert f"NOTE: {line}" in prepare_out(cfg, plan_jobs(cfg))  # printed at the end
    write_adaptive(
        record, AdaptiveRecord((0,), 4, 0.05, (0, 1), (), grid_vuts(cfg, "car_following"))
    )
    assert stale_record(cfg, "car_following") is None
    assert case_seeds(cfg, "car_following") == (0, 1)  # this grid's record: its added seed
