"""Adaptive seeding: add training seeds to a case only while its ranking has not settled.

The ``verdict`` budget starts every case with 4 seeds per VUT and caps it at 6
(``max_seeds``, :mod:`sumo_ayss.config.pipeline`). After the grid and the cross-play stage,
each case is looked at (:func:`sumo_ayss.analysis.sequential.settle_check`: an F gate over
all VUTs at a level calibrated for the repeated looks, and the report's paired t of the
current ends); a case that has not settled gets one more seed per VUT (the next integer
after the last seed), its new jobs run, its cross-play table is extended with the new
opponents only, and it is looked at again, until it settles or reaches the cap. Cases
that settled are not touched again.

Every look is written to ``<out>/<case>/adaptive.json`` (:mod:`sumo_ayss.run_folder.adaptive`)
*before* the next seed's jobs start, so a pipeline killed mid-look resumes with the seeds it
had added (:func:`case_seeds`, used by :func:`sumo_ayss.grid.plan.plan_jobs`) and a rerun of
a finished grid repeats the same looks on the same tables.
"""

from __future__ import annotations

import dataclasses
import logging
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from sumo_ayss.config import PipelineConfig
from sumo_ayss.config.identity import vut_key
from sumo_ayss.grid.jobs import JobSpec
from sumo_ayss.grid.progress import JobStatus
from sumo_ayss.run_folder import (
    AdaptiveLook,
    AdaptiveRecord,
    RunRecord,
    StudyFolder,
    find_run_dirs,
    read_adaptive,
    write_adaptive,
)
from sumo_ayss.util.errors import AyssError

if TYPE_CHECKING:
    from sumo_ayss.analysis.sequential import SettleCheck

logger = logging.getLogger("sumo_ayss.grid.adaptive")

__all__ = [
    "case_seeds",
    "grid_vuts",
    "is_adaptive",
    "read_record",
    "run_adaptive",
    "same_plan",
    "same_vuts",
    "stale_record",
    "summary_lines",
]

RunJobs = Callable[[list[JobSpec]], list[JobStatus]]
"""Runs a list of jobs on the pipeline's backend and returns their statuses."""

CrossplayStage = Callable[[PipelineConfig, Sequence[JobStatus], Sequence[RunRecord]], list[Path]]
"""The pipeline's cross-play stage (:func:`sumo_ayss.pipeline.run_crossplay_stage`)."""

LoadRuns = Callable[[Sequence[Path]], list[RunRecord]]
"""Reads finished run folders (:func:`sumo_ayss.report.document.load_runs`)."""


def is_adaptive(cfg: PipelineConfig) -> bool:
    """Whether the grid may add seeds: a cap above ``grid.seeds``, two or more VUTs, and a
    ranking mode that runs cross-play (the looks read the cross-play table)."""
    from sumo_ayss.modes import get_mode

    assert cfg.max_seeds is not None  # resolved by the config
    return (
        cfg.max_seeds > len(cfg.seeds)
        and len(cfg.grid.vuts) >= 2
        and get_mode(cfg.report.mode).runs_crossplay
    )


def grid_vuts(cfg: PipelineConfig, case: str) -> tuple[tuple[str, str], ...]:
    """``(name, definition key)`` of the grid's VUTs in ``case``, in grid order: what an
    adaptive record must have looked at to be this grid's."""
    from sumo_ayss.grid.plan import case_experiment

    vuts = case_experiment(cfg, case).env.vuts
    return tuple((v, vut_key(vuts[v])) for v in cfg.grid.vuts)


def same_plan(
    record: AdaptiveRecord, first_seeds: tuple[int, ...], max_seeds: int, alpha: float
) -> bool:
    """Whether ``record`` belongs to the same schedule (a changed config starts over)."""
    return (record.first_seeds, record.max_seeds, record.alpha) == (
        tuple(first_seeds),
        max_seeds,
        alpha,
    )


def same_vuts(record: AdaptiveRecord, vuts: tuple[tuple[str, str], ...]) -> bool:
    """Whether ``record`` looked at the VUTs ``vuts`` (``(name, key)``, in any order); a
    record that does not name its VUTs (written before they were) is taken as is."""
    return not record.vuts or dict(record.vuts) == dict(vuts)


def stale_record(cfg: PipelineConfig, case: str) -> str | None:
    """Why the case's record is ignored although it is this schedule's (it looked at other
    VUTs), as a sentence; None when there is no such record."""
    if not is_adaptive(cfg):
        return None
    path = StudyFolder(cfg.out).case(case).adaptive_json
    try:
        record = read_adaptive(path) if path.is_file() else None
    except AyssError:
        return None
    now = grid_vuts(cfg, case)
    if record is None or same_vuts(record, now):
        return None
    names = {n for n, _ in record.vuts} & {n for n, _ in now}
    redefined = sorted(n for n in names if dict(record.vuts)[n] != dict(now)[n])
    return (
        f"{case}: adaptive seeding's record ({path.name}) looked at VUTs "
        f"{', '.join(n for n, _ in record.vuts)}"
        + (f" ({', '.join(redefined)} since redefined)" if redefined else "")
        + f"; the grid's are {', '.join(n for n, _ in now)}: the record is ignored and "
        f"seeding starts over from grid.seeds ({len(cfg.seeds)} per VUT)"
    )


def read_record(cfg: PipelineConfig, case: str) -> AdaptiveRecord | None:
    """The case's record if it belongs to this configuration's schedule and VUTs, else None
    (no record, an unreadable one, one made with other seeds, cap or level, or a stale one:
    of other VUTs, :func:`stale_record`)."""
    path = StudyFolder(cfg.out).case(case).adaptive_json
    if not path.is_file():
        return None
    try:
        record = read_adaptive(path)
    except AyssError as exc:
        logger.warning("%s; adaptive seeding of %s starts over", exc, case)
        return None
    assert cfg.max_seeds is not None
    if not same_plan(record, cfg.seeds, cfg.max_seeds, cfg.report.welch_alpha):
        return None
    if not same_vuts(record, grid_vuts(cfg, case)):
        return None
    return record


def case_seeds(cfg: PipelineConfig, case: str) -> tuple[int, ...]:
    """The case's seeds: ``grid.seeds`` plus those adaptive seeding already added (read
    from its record, so that a resumed pipeline runs them again)."""
    if not is_adaptive(cfg):
        return cfg.seeds
    record = read_record(cfg, case)
    return cfg.seeds if record is None else record.seeds


def _look(cfg: PipelineConfig, case: str, runs: Sequence[RunRecord]) -> SettleCheck:
    """One look at a case from its cross-play table."""
    from sumo_ayss.analysis.crossplay_scoring import case_matrix
    from sumo_ayss.analysis.sequential import looks_of, settle_check
    from sumo_ayss.run_folder import case_of

    assert cfg.max_seeds is not None
    found = case_of(runs)
    matrix = case_matrix(found.crossplay, found.runs)
    return settle_check(
        matrix.scores("seed"),  # seed blocks: the independent replications
        looks_of(len(cfg.seeds), cfg.max_seeds),
        cfg.report.welch_alpha,
    )


def _describe(case: str, look: SettleCheck) -> str:
    verdict = "settled" if look.settled else "not settled"
    return (
        f"adaptive seeding, {case}: {verdict} at {look.n_seeds} seeds per VUT (F gate p "
        f"{look.omnibus_p:.3g} against {look.gate_level:.3g}; ends {look.safest} vs "
        f"{look.least_safe}: p {look.ends_p:.3g} against {look.alpha:g})"
    )


def run_adaptive(
    cfg: PipelineConfig,
    statuses: list[JobStatus],
    runs: list[RunRecord],
    run_jobs: RunJobs,
    crossplay_stage: CrossplayStage,
    plan: Callable[[PipelineConfig, str, int], list[JobSpec]],
    load_runs: LoadRuns,
) -> tuple[list[JobStatus], list[RunRecord]]:
    """Look at every case, add seeds to those not settled, until each settles or reaches
    ``max_seeds``; return the statuses and the runs with the added jobs' appended (the runs
    in :func:`~sumo_ayss.run_folder.find_run_dirs` order, as a resumed pipeline reads them).

    ``plan(cfg, case, seed)`` gives one seed's jobs of a case. A case with a failed job or
    without a cross-play table is left as it is (logged).
    """
    assert cfg.max_seeds is not None
    statuses = list(statuses)
    by_path = {r.path.resolve(): r for r in runs}
    active = list(cfg.grid.cases)
    while active:
        grow = []
        for case in active:
            jobs = [s for s in statuses if s.spec.case == case]
            if any(s.state != "done" for s in jobs):
                logger.warning("adaptive seeding of %s stopped: a job is not done", case)
                continue
            try:
                look = _look(cfg, case, [by_path[s.spec.run_dir.resolve()] for s in jobs])
            except AyssError as exc:
                logger.warning("adaptive seeding of %s stopped: %s", case, exc)
                continue
            record = _record_look(cfg, case, look)
            logger.info(_describe(case, look))
            if not look.settled and len(record.seeds) < cfg.max_seeds:
                grow.append((case, record))
            elif not look.settled:
                logger.info("adaptive seeding, %s: at the cap of %d seeds", case, cfg.max_seeds)
        new_jobs = []
        for case, record in grow:
            seed = cfg.added_seeds[len(record.seeds) - len(cfg.seeds)]
            # The record names the seed before its jobs start: a kill resumes with it.
            path = StudyFolder(cfg.out).case(case).adaptive_json
            write_adaptive(path, dataclasses.replace(record, seeds=(*record.seeds, seed)))
            logger.info("adaptive seeding, %s: adding seed %d for every VUT", case, seed)
            new_jobs += plan(cfg, case, seed)
        if not new_jobs:
            break
        added = run_jobs(new_jobs)
        statuses += added
        done = [s.spec.run_dir for s in added if s.state == "done"]
        if done:
            by_path.update((r.path.resolve(), r) for r in load_runs(done))
        active = [case for case, _ in grow]
        only = dataclasses.replace(cfg, grid=dataclasses.replace(cfg.grid, cases=tuple(active)))
        crossplay_stage(
            only, [s for s in statuses if s.spec.case in active], list(by_path.values())
        )
    order = find_run_dirs([s.spec.run_dir for s in statuses if s.state == "done"])
    return statuses, [by_path[Path(p).resolve()] for p in order]


def _record_look(cfg: PipelineConfig, case: str, look: SettleCheck) -> AdaptiveRecord:
    """Append ``look`` to the case's record (replacing a look at the same seed count: a
    rerun repeats it) and write it."""
    assert cfg.max_seeds is not None
    record = read_record(cfg, case)
    if record is None:
        record = AdaptiveRecord(
            cfg.seeds, cfg.max_seeds, cfg.report.welch_alpha, cfg.seeds, (), grid_vuts(cfg, case)
        )
    stored = AdaptiveLook(**dataclasses.asdict(look))
    looks = (*tuple(x for x in record.looks if x.n_seeds < look.n_seeds), stored)
    record = dataclasses.replace(record, looks=looks, vuts=grid_vuts(cfg, case))
    write_adaptive(StudyFolder(cfg.out).case(case).adaptive_json, record)
    return record


def summary_lines(cfg: PipelineConfig) -> list[str]:
    """One line per case of an adaptive grid: where its seeding stopped and why."""
    if not is_adaptive(cfg):
        return []
    lines = []
    for case in cfg.grid.cases:
        record = read_record(cfg, case)
        if record is None or not record.looks:
            continue
        look = record.looks[-1]
        if look.settled:
            why = "settled"
        elif look.n_seeds >= record.max_seeds:
            why = f"not settled at the cap (max_seeds {record.max_seeds})"
        else:
            why = "not settled, stopped before the cap (a job or cross-play failed: the log)"
        lines.append(
            f"adaptive seeding, {case}: {why} with {look.n_seeds} seeds per VUT "
            f"(ends {look.safest} vs {look.least_safe}: p {look.ends_p:.3g}; F gate p "
            f"{look.omnibus_p:.3g} against {look.gate_level:.3g}; {record.alpha:g} false "
            "positives over the looks)"
        )
    return lines
