"""A study's output folder before its jobs run: another study's folder refused, renamed VUTs
reused, redefined VUTs' old runs set aside, and two names for one vehicle flagged.

A leaderboard grows in place: the same pipeline YAML and ``out:`` folder with a VUT added,
dropped, redefined or renamed. Each run is identified by what made it
(:mod:`sumo_ayss.config.identity`: its own VUT's definition, case, seed, budget, agent
and env settings), so the runs of unchanged VUTs are skipped as done. Before any job,
:func:`prepare_out` looks at the folder once:

* **another study's folder** (:func:`check_same_study`): runs of a case the grid does not
  name, or runs made with other settings than the ones asked (budget, agent, env; not the
  VUT's own definition), are refused with a :class:`~sumo_ayss.util.errors.ConfigError`
  naming what differs, before any job runs (before, every job failed on its own);
* **a renamed VUT** (:func:`reuse_renamed`): a grid VUT without runs whose definition equals
  that of a VUT folder no longer in the grid takes that folder over (moved, its runs'
  ``config.yaml`` relabelled, the old name kept in ``renamed.json``): nothing retrains;
* **a redefined VUT** (:func:`set_aside_redefined`): a run folder whose stored identity
  differs from the job's only in the VUT's own definition is moved to
  ``<out>/<case>/.superseded/<vut>-<old key>/seed_<k>`` (a hidden folder no reader
  searches), and the job trains again from scratch;
* **one vehicle, two names** (:func:`same_vehicles`): two grid VUTs with equal definitions
  (descriptions aside) are warned about: every comparison between them is a tie;
* **a stale adaptive-seeding record** (:func:`sumo_ayss.grid.adaptive.stale_record`): one
  that looked at other VUTs is ignored, and said so.

Every sentence said is returned (the pipeline prints them at the end) and logged.
"""

from __future__ import annotations

import logging
import os
import shutil
from collections.abc import Sequence
from pathlib import Path

from sumo_ayss.config import ExperimentConfig, PipelineConfig
from sumo_ayss.config.identity import (
    OWN_VUT,
    identity_differences,
    is_redefinition,
    vut_key,
)
from sumo_ayss.grid.jobs import JobSpec
from sumo_ayss.records.jsonio import write_json
from sumo_ayss.run_folder import (
    RunConfig,
    RunFolder,
    read_run_config,
    stored_experiment,
    write_run_config,
)
from sumo_ayss.util.errors import AyssError, ConfigError

__all__ = [
    "RENAMED_JSON",
    "SUPERSEDED_DIR",
    "check_same_study",
    "prepare_out",
    "reuse_renamed",
    "same_vehicles",
    "set_aside_redefined",
]

logger = logging.getLogger("sumo_ayss.pipeline")

#: The hidden folder of a case that keeps the runs of redefined VUTs.
SUPERSEDED_DIR = ".superseded"

#: A renamed VUT's runs say which name they were trained under.
RENAMED_JSON = "renamed.json"


def _run_dirs(vut_dir: Path) -> list[Path]:
    """The run folders (``seed_<k>`` with a ``config.yaml``) of one VUT folder, by seed."""
    if not vut_dir.is_dir():
        return []
    found = [p for p in vut_dir.glob("seed_*") if (p / "config.yaml").is_file()]
    return sorted(found, key=lambda p: (len(p.name), p.name))


def _stored(run_dir: Path) -> ExperimentConfig | None:
    """A run folder's stored experiment, None when it cannot be read (its job says why)."""
    try:
        return stored_experiment(RunFolder(run_dir))[0]
    except AyssError:
        return None


def _by_case(jobs: Sequence[JobSpec]) -> dict[str, dict[str, JobSpec]]:
    """``{case: {vut: a job of it}}`` in grid order."""
    out: dict[str, dict[str, JobSpec]] = {}
    for job in jobs:
        out.setdefault(job.case, {}).setdefault(job.vut, job)
    return out


def check_same_study(cfg: PipelineConfig, jobs: Sequence[JobSpec]) -> None:
    """Refuse an ``out:`` folder that holds another study's runs.

    Raises:
        ConfigError: The folder holds runs of a case the grid does not name, or a VUT
            folder's runs were made with other settings than the grid's jobs (anything of
            the run's identity but the VUT's own definition: budget, agent, env); the
            message names the cases or the fields (stored -> asked, five at most).
    """
    out = Path(cfg.out)
    if not out.is_dir():
        return
    others = sorted(
        p.name
        for p in out.iterdir()
        if p.is_dir() and p.name not in cfg.grid.cases and any(map(_run_dirs, p.iterdir()))
    )
    if others:
        raise ConfigError(
            f"out: {out} holds runs of case(s) {others}, which grid.cases "
            f"{list(cfg.grid.cases)} does not name: it is another study's folder; give "
            "another out: folder, or name those cases too"
        )
    for case, vuts in _by_case(jobs).items():
        asked = next(iter(vuts.values())).experiment
        case_dir = out / case
        if not case_dir.is_dir():
            continue
        for vut_dir in sorted(p for p in case_dir.iterdir() if not p.name.startswith(".")):
            runs = _run_dirs(vut_dir)
            stored = _stored(runs[0]) if runs else None
            if stored is None:
                continue
            diffs = [
                d
                for d in identity_differences(stored, 0, asked, 0)
                if not d.startswith(f"{OWN_VUT}.")
            ]
            if diffs:
                more = f"; and {len(diffs) - 5} more" if len(diffs) > 5 else ""
                shown = "; ".join(diffs[:5]) + more
                raise ConfigError(
                    f"out: {out} holds runs made with other settings than this study's: "
                    f"{runs[0].relative_to(out)} differs in {shown} (stored -> asked); give "
                    "another out: folder, or the settings those runs were made with"
                )


def same_vehicles(jobs: Sequence[JobSpec]) -> list[str]:
    """One warning per group of grid VUTs that are one vehicle (equal definitions,
    descriptions aside), per case where the cases differ."""
    lines: list[str] = []
    for case, vuts in _by_case(jobs).items():
        groups: dict[str, list[str]] = {}
        for vut, job in vuts.items():
            groups.setdefault(vut_key(job.experiment.env.vut_type), []).append(vut)
        for names in groups.values():
            if len(names) > 1:
                line = (
                    f"VUTs {', '.join(names)} are the same vehicle in {case} (identical "
                    "definitions, descriptions aside): every comparison between them is a tie"
                )
                lines.append(line)
    return lines


def reuse_renamed(cfg: PipelineConfig, jobs: Sequence[JobSpec]) -> list[str]:
    """Give a grid VUT without runs the runs of a VUT folder no longer in the grid whose
    definition (and every other setting) is the same; one sentence per reuse.

    The folder ``<out>/<case>/<old>`` becomes ``<out>/<case>/<new>``; each run's
    ``config.yaml`` then names the new VUT (``env.vut`` and its catalog entry; everything
    else as stored) and ``renamed.json`` records the old name.
    """
    lines = []
    for case, vuts in _by_case(jobs).items():
        case_dir = Path(cfg.out) / case
        if not case_dir.is_dir():
            continue
        spare = [
            p
            for p in sorted(case_dir.iterdir())
            if p.name not in cfg.grid.vuts and not p.name.startswith(".") and _run_dirs(p)
        ]
        for vut, job in vuts.items():
            if _run_dirs(case_dir / vut):
                continue
            for old in spare:
                stored = _stored(_run_dirs(old)[0])
                if stored is None or identity_differences(stored, 0, job.experiment, 0):
                    continue
                _rename(old, case_dir / vut, vut)
                spare.remove(old)
                lines.append(
                    f"{case}: VUT {vut} is {old.name} renamed (the same definition): its "
                    f"{len(_run_dirs(case_dir / vut))} runs are reused, none retrains"
                )
                break
    return lines


def _rename(old: Path, new: Path, name: str) -> None:
    """Move a VUT folder to its new name and relabel its runs."""
    os.replace(old, new)
    for run_dir in _run_dirs(new):
        folder = RunFolder(run_dir)
        stored = read_run_config(folder.config)
        env = dict(stored.experiment["env"])
        catalog = dict(env.get("vuts") or {})
        catalog[name] = catalog.pop(stored.vut)
        env["vuts"] = catalog
        experiment = {**stored.experiment, "env": env}
        write_run_config(folder.config, RunConfig(name, stored.seed, experiment))
        write_json(run_dir / RENAMED_JSON, {"from": old.name, "to": name})


def set_aside_redefined(jobs: Sequence[JobSpec]) -> list[str]:
    """Move every run folder whose VUT was redefined (its stored identity differs from its
    job's in the VUT's own definition only) to the case's :data:`SUPERSEDED_DIR`; one
    sentence per VUT."""
    moved: dict[tuple[str, str], list[str]] = {}
    for job in jobs:
        folder = job.folder
        stored = _stored(folder.path) if folder.config.is_file() else None
        if stored is None:
            continue
        diffs = identity_differences(stored, job.seed, job.experiment, job.seed)
        if not is_redefinition(diffs):
            continue
        old = vut_key(stored.env.vut_type)
        target = folder.path.parent.parent / SUPERSEDED_DIR / f"{job.vut}-{old}" / folder.path.name
        if target.exists():
            shutil.rmtree(target)
        target.parent.mkdir(parents=True, exist_ok=True)
        os.replace(folder.path, target)
        moved.setdefault((job.case, job.vut), diffs)
    return [
        f"{case}: VUT {vut} was redefined ({'; '.join(diffs[:3])}): its runs are trained "
        f"again; the old ones were moved to {case}/{SUPERSEDED_DIR}/"
        for (case, vut), diffs in moved.items()
    ]


def prepare_out(cfg: PipelineConfig, jobs: Sequence[JobSpec]) -> list[str]:
    """Everything above, in order, before any job runs; returns what was said (each
    sentence also logged: warnings for one vehicle under two names, notes otherwise).

    Raises:
        ConfigError: The folder is another study's (:func:`check_same_study`).
    """
    from sumo_ayss.grid.adaptive import stale_record

    check_same_study(cfg, jobs)
    warnings = same_vehicles(jobs)
    notes = reuse_renamed(cfg, jobs) + set_aside_redefined(jobs)
    notes += [line for case in cfg.grid.cases if (line := stale_record(cfg, case))]
    for line in warnings:
        logger.warning(line)
    for line in notes:
        logger.info(line)
    return [f"WARNING: {w}" for w in warnings] + [f"NOTE: {n}" for n in notes]
