"""A run's identity: its own VUT's definition, not the study's catalog nor the VUT's name;
the committed run folders (whose config.yaml holds their study's whole catalog) still match."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from sumo_ayss.config import ExperimentConfig, SimConfig, integration_method, to_dict
from sumo_ayss.config.identity import (
    identity_differences,
    is_redefinition,
    run_identity,
    vut_key,
)
from sumo_ayss.run_folder import RunConfig, RunFolder, stored_experiment
from sumo_ayss.run_folder.metadata import write_run_config
from sumo_ayss.stages import TrainStage
from sumo_ayss.training.config_check import check_same_config
from sumo_ayss.vuts.catalog import VehicleType

ROOT = Path(__file__).resolve().parents[2]
OB40 = VehicleType("IDM", {"minGap": 40.0}, "a far follower")


def _with_catalog(cfg: ExperimentConfig, vuts: dict[str, VehicleType]) -> ExperimentConfig:
    return dataclasses.replace(cfg, env=dataclasses.replace(cfg.env, vuts=vuts))


def test_another_vuts_definition_is_not_part_of_a_run() -> None:
    base = ExperimentConfig()  # pi1 in the built-in catalog
    grown = _with_catalog(base, {**base.env.vuts, "ob40": OB40})
    redefined = _with_catalog(
        base, {**base.env.vuts, "ob40": dataclasses.replace(OB40, model="EIDM")}
    )
    alone = _with_catalog(base, {"pi1": base.env.vuts["pi1"]})
    for other in (grown, redefined, alone):
        assert run_identity(other, 0) == run_identity(base, 0)
        assert identity_differences(base, 0, other, 0) == []


def test_the_runs_own_definition_is_named_and_its_description_is_not() -> None:
    base = ExperimentConfig()
    pi1 = base.env.vuts["pi1"]
    slower = dataclasses.replace(pi1, params={**pi1.params, "accel": 2.0})
    changed = _with_catalog(base, {**base.env.vuts, "pi1": slower})
    diffs = identity_differences(base, 0, changed, 0)
    assert diffs == ["env.vuts[env.vut].params.accel: 3.0 -> 2.0"]
    assert is_redefinition(diffs)
    retitled = _with_catalog(
        base, {**base.env.vuts, "pi1": dataclasses.replace(pi1, description="x")}
    )
    assert identity_differences(base, 0, retitled, 0) == []
    longer = dataclasses.replace(
        base, train=dataclasses.replace(base.train, total_timesteps=300_000)
    )
    mixed = identity_differences(base, 0, dataclasses.replace(longer, env=changed.env), 0)
    assert len(mixed) == 2 and not is_redefinition(mixed)
    assert identity_differences(base, 0, base, 1) == ["seed: 0 -> 1"]


def test_a_renamed_vut_is_the_same_run_and_the_same_vehicle() -> None:
    base = ExperimentConfig()
    env = dataclasses.replace(base.env, vut="first", vuts={"first": base.env.vuts["pi1"]})
    renamed = dataclasses.replace(base, env=env)
    assert run_identity(renamed, 3) == run_identity(base, 3)
    assert vut_key(renamed.env.vut_type) == vut_key(base.env.vuts["pi1"])
    assert vut_key(base.env.vuts["pi1"]) != vut_key(base.env.vuts["pi2"])


def test_resume_check_ignores_the_catalog_and_names_a_redefinition(tmp_path: Path) -> None:
    cfg = _with_catalog(ExperimentConfig(), {**ExperimentConfig().env.vuts, "ob40": OB40})
    folder = RunFolder(tmp_path)
    write_run_config(folder.config, RunConfig("pi1", 0, to_dict(cfg)))
    alone = _with_catalog(cfg, {"pi1": cfg.env.vuts["pi1"]})
    check_same_config(folder, alone, 0)  # the failure: another VUT's entry changed
    folder.spcp_json.write_text("{}")
    folder.spcp_zip.write_bytes(b"weights")
    assert TrainStage(folder, alone, 0).recorded() == TrainStage(folder, alone, 0).key()


def test_committed_run_folders_are_still_done_under_a_catalog_of_their_vut_alone() -> None:
    """Every committed run folder's stored catalog is its study's; asked with only its own
    VUT in the catalog (or another study's), the run is the same run."""
    folders = sorted(p.parent for p in (ROOT / "results").rglob("seed_*/config.yaml"))
    assert len(folders) > 100
    for path in folders[::7]:
        folder = RunFolder(path)
        cfg, seed = stored_experiment(folder)
        # The catalog's one effect on the dynamics (SUMO's integration method) kept:
        method = integration_method(cfg.env.sim, [*cfg.env.vuts.values(), cfg.env.pov])
        alone = _with_catalog(cfg, {cfg.env.vut: cfg.env.vut_type})
        alone = _with_sim(alone, step_method=method)
        stage = TrainStage(folder, alone, seed)
        assert stage.key() == stage.recorded(), path


def _with_sim(cfg: ExperimentConfig, **changes: object) -> ExperimentConfig:
    sim = dataclasses.replace(cfg.env.sim, **changes)  # type: ignore[arg-type]
    return dataclasses.replace(cfg, env=dataclasses.replace(cfg.env, sim=sim))


REACTION = VehicleType("IDM", {"minGap": 5.0, "actionStepLength": 1.0}, "decides every 1 s")


def test_a_catalog_that_makes_sumo_ballistic_is_part_of_every_run_of_it() -> None:
    """One VUT with a longer action step switches SUMO to ballistic integration for every
    vehicle of the simulation (SUMO 1.28): pi1 beside it is not pi1 alone."""
    base = ExperimentConfig()
    beside = _with_catalog(base, {**base.env.vuts, "r10": REACTION})
    assert "env.sim.integration" not in run_identity(base, 0)
    assert "env.sim.step_method" not in run_identity(base, 0)
    assert identity_differences(base, 0, beside, 0) == [
        "env.sim.integration: '(absent)' -> 'ballistic'"
    ]
    assert not is_redefinition(identity_differences(base, 0, beside, 0))
    # Asked explicitly, the same method is the same run, whatever the catalog holds.
    assert run_identity(_with_sim(base, step_method="ballistic"), 0) == run_identity(beside, 0)
    assert run_identity(_with_sim(beside, step_method="euler"), 0) == run_identity(base, 0)
    # A study of the reaction VUT alone is ballistic too: its own run is unchanged by it.
    own = dataclasses.replace(beside, env=dataclasses.replace(beside.env, vut="r10"))
    alone = _with_catalog(own, {"r10": REACTION})
    assert run_identity(alone, 0) == run_identity(own, 0)


def test_a_committed_reaction_run_is_not_the_same_run_beside_vuts_without_the_option() -> None:
    """The committed reaction ladder moved every VUT ballistically (its catalog holds r06 and
    r10); its r02 asked alone (Euler) is another run, and the resume check names why."""
    folder = RunFolder(ROOT / "results/ladders/reaction_a/car_following/r02/seed_201")
    cfg, seed = stored_experiment(folder)
    assert integration_method(cfg.env.sim, cfg.env.vuts.values()) == "ballistic"
    alone = _with_catalog(cfg, {"r02": cfg.env.vut_type})
    stage = TrainStage(folder, alone, seed)
    assert stage.recorded() is not None and stage.key() != stage.recorded()
    assert "env.sim.integration: 'ballistic' -> '(absent)'" in identity_differences(
        cfg, seed, alone, seed
    )
    assert SimConfig().step_method == "auto"


def test_committed_configs_naming_a_controller_by_module_path_read_as_its_registered_name() -> None:
    """Run folders written before the registered controller names store module paths (one,
    ``sumo_ayss.hwenv_laws``, no longer a module): read back, the target is the registered
    name; the run is the same run as one asked for now with the catalog entry of today,
    and the same vehicle as the definition key its study's records stored."""
    import json

    from sumo_ayss.config import load_pipeline
    from sumo_ayss.vuts.catalog import BUILTIN_VUTS

    human075 = load_pipeline(ROOT / "configs/ladders/careful_human.yaml").vuts["human075"]
    studies = [
        (
            "results/fidelity_ablation/clipped_pov/car_following/hwenv_pi1/seed_0",
            "sumo_ayss.hwenv_laws:HighwayEnvIDM",
            BUILTIN_VUTS["hwenv_pi1"],
        ),
        (
            "results/ladders/careful_human_a/car_following/human075/seed_501",
            "sumo_ayss.vuts.reference:CarefulDriver",
            human075,
        ),
    ]
    for run_dir, old, today in studies:
        folder = RunFolder(ROOT / run_dir)
        vut = folder.path.parent.name
        text = folder.config.read_text(encoding="utf-8")
        assert f"target: {old}" in text  # the old-style config, as committed
        cfg, seed = stored_experiment(folder)
        stored = cfg.env.vut_type.controller
        assert stored is not None and ":" not in stored.target  # a registered name
        assert stored.target == (today.controller.target if today.controller else None)
        stage = TrainStage(folder, _with_catalog(cfg, {vut: today}), seed)
        assert stage.key() == stage.recorded(), folder
        record = folder.path.parents[1] / "crossplay.json"
        keys = json.loads(record.read_text(encoding="utf-8")).get("vut_keys", {})
        if vut in keys:
            assert vut_key(today) == vut_key(cfg.env.vut_type) == keys[vut]
