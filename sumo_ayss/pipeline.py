"""One command from config to verdict: the grid cases × VUTs × seeds, resumable.

    python -m sumo_ayss.pipeline configs/paper.yaml [--workers N] [--backend local|ray]

Progress: on a terminal, a live table of every job (queued / running / done / failed,
training steps, rate in steps/s, wall time in s) with the grid's ETA; with ``--no-live`` or
when the output is not a terminal, one log line per job event (started, each SPCP
candidate, training finished, done, failed) with the grid's counts and ETA.

Each job (case, VUT, seed) trains (or resumes) its SPCP candidates, selects the SPCP, runs
the outcome episodes and the Monte Carlo AYSS. In cross-play mode (``report.mode:
crossplay``, the default) every SPCP of a case with two or more VUTs then drives against
every VUT of the case (:func:`run_crossplay_stage`, :mod:`sumo_ayss.crossplay`); then the
finished runs are loaded and each case analysed once, and one report covers the whole grid
(:func:`run_pipeline` returns the loaded runs and the analyses, which :mod:`sumo_ayss.rank`
ranks without reading or bootstrapping again). Jobs
run in parallel processes (one SUMO per process: libsumo holds one simulation each), or as
Ray tasks. Every stage writes atomically and is skipped when its output exists and was made
from the same inputs, so rerunning after a crash or Ctrl-C continues where it stopped. A
failing job is retried once, then reported with its log; it never costs the other jobs.

Where things live: the sections below in :mod:`sumo_ayss.config.pipeline`; running the grid
in :mod:`sumo_ayss.grid` (its plan, one job :class:`~sumo_ayss.grid.jobs.JobSpec`, the local
process pool, Ray, progress, adaptive seeding). This module runs the grid, the stages after
it and the report.

Pipeline YAML (every key optional)::

    grid: {cases: [car_following, cut_in], vuts: [pi1, pi2], seeds: [0, 1, 2, 3]}  # budget
    experiments: {car_following: car_following.yaml, cut_in: cut_in.yaml}  # per case
    out: ../runs/paper          # relative to the YAML file
    budget: fast                # a named budget: fast (default) | verdict | quick | paper | null
    total_timesteps: null       # override the budget's / every experiment's train.total_timesteps
    eval_every: null            # override the budget's / every experiment's train.eval_every
    learning_rate: null         # override the budget's / every experiment's agent.learning_rate
    early_stop_patience: null   # every experiment's train.early_stop_patience (null: its own, off)
    early_stop_margin_se: null  # every experiment's train.early_stop_margin_se
    evaluate: {n_outcome: 200, n_ayss: 100000}  # n_ayss: shorthand for ayss.n_samples
    #   ayss: {h_m: [0, 5], seed: 4242, ...}   # Monte Carlo (sumo_ayss.config.AyssConfig)
    vuts: {}                    # extra VUTs (name: vehicle type) added to every experiment
    report: {mode: crossplay, crossplay_blocks: seed, n_boot: 2000}  # config.report
    expected_order: []          # a known safety order, safest first (validation studies)
    workers: 0                  # 0 = as many as cores
    retries: 1
"""

from __future__ import annotations

import argparse
import functools
import logging
import os
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal, NamedTuple, Protocol

from sumo_ayss.config import (
    PipelineConfig,
    check_out_dir,
    load_pipeline,
    to_dict,
)
from sumo_ayss.config.budget import BUDGET_CHOICES, BUDGET_HELP
from sumo_ayss.discriminability import discriminability_beside
from sumo_ayss.grid.folder_lock import output_lock
from sumo_ayss.grid.jobs import JobSpec
from sumo_ayss.grid.local import run_grid_local
from sumo_ayss.grid.plan import plan_jobs, plan_seed
from sumo_ayss.grid.progress import JobStatus
from sumo_ayss.modes import analyse_cases, check_mode, get_mode
from sumo_ayss.run_folder import RunRecord, StudyFolder, case_runs, load_runs, write_pipeline_json
from sumo_ayss.util.errors import AyssError, DiskFullError

if TYPE_CHECKING:
    from sumo_ayss.analysis.case import CaseAnalysis
    from sumo_ayss.config.report import ReportOptions
    from sumo_ayss.scenarios.crossplay import CellRunner

logger = logging.getLogger("sumo_ayss.pipeline")  # also when run as __main__

Backend = Literal["local", "ray"]


class ReportWriter(Protocol):
    """Writes a study's report from its loaded runs and analyses; returns ``report.html``
    (:func:`sumo_ayss.report.document.write_report_for`, handed in by the command,
    :mod:`sumo_ayss.commands.pipeline`: the stage imports no renderer)."""

    def __call__(
        self,
        runs: Sequence[RunRecord],
        out_dir: Path,
        *,
        analyses: Sequence[CaseAnalysis[RunRecord]] | None = ...,
        options: ReportOptions | None = ...,
    ) -> Path: ...


__all__ = [
    "PipelineResult",
    "ReportWriter",
    "load_pipeline",
    "plan_jobs",
    "run_crossplay_stage",
    "run_pipeline",
]


class PipelineResult(NamedTuple):
    """What :func:`run_pipeline` did and found.

    Attributes:
        statuses: One per job, in grid order.
        report: The report's ``report.html``, or None when no job finished or no report
            writer was handed in.
        runs: The finished jobs' run folders, read once
            (:func:`sumo_ayss.run_folder.read_run`), in the order of ``statuses``.
        analyses: Every case's analysis (:func:`sumo_ayss.modes.analyse_cases`, paper
            mode included), computed once; the report's verdicts, and rank's rows.
        cfg: The configuration it ran.
        notes: What it said about the output folder before the jobs ran (a renamed VUT
            reused, a redefined VUT retrained, two names for one vehicle:
            :func:`sumo_ayss.grid.study.prepare_out`), each line starting ``NOTE:`` or
            ``WARNING:``.
    """

    statuses: list[JobStatus]
    report: Path | None
    runs: list[RunRecord]
    analyses: list[CaseAnalysis[RunRecord]]
    cfg: PipelineConfig | None = None
    notes: tuple[str, ...] = ()


def _relative_paths(data: Any, base: Path) -> Any:
    """``data`` with absolute path strings made relative to ``base`` (no machine paths)."""
    if isinstance(data, dict):
        return {k: _relative_paths(v, base) for k, v in data.items()}
    if isinstance(data, list):
        return [_relative_paths(v, base) for v in data]
    if isinstance(data, str) and os.path.isabs(data):
        return Path(os.path.relpath(data, base.resolve())).as_posix()
    return data


def configure_logging(live: bool) -> Any:
    """CLI logging; returns the live display's console (None: not live or not a terminal).

    With a live table, log lines go through the table's console so that they print above
    it instead of being glued onto its border.
    """
    if live and sys.stdout.isatty():
        from rich.console import Console
        from rich.logging import RichHandler

        console = Console()
        handler = RichHandler(console=console, show_path=False, markup=False)
        logging.basicConfig(level=logging.INFO, format="%(message)s", handlers=[handler])
        return console
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(name)s: %(message)s")
    return None


def final_messages(result: PipelineResult) -> list[str]:
    """What the CLI prints at the end: failures, the report and its trust warnings (from
    the runs the pipeline loaded)."""
    lines = list(result.notes)
    lines += [
        f"FAILED {s.spec.name}: {s.error}  (log: {s.spec.folder.job_log})"
        for s in result.statuses
        if s.state == "failed"
    ]
    lines += [
        f"RETRIED {s.spec.name}: passed on try {s.attempts} after a failure: {s.error}"
        for s in result.statuses
        if s.state == "done" and s.attempts > 1
    ]
    done = [s for s in result.statuses if s.state == "done"]
    if done:
        from sumo_ayss.training.trust import fewest_seeds, trust_warnings

        training = {r.path: r.training for r in result.runs}
        runs = [(s.spec.name, training[Path(s.spec.run_dir).resolve()]) for s in done]
        seeds = fewest_seeds((r.case, r.vut) for r in result.runs)
        lines += [f"WARNING: {w}" for w in trust_warnings(runs, seeds)]
    if result.cfg is not None:
        from sumo_ayss.grid.adaptive import summary_lines

        lines += summary_lines(result.cfg)
    if result.report is not None:
        lines.append(f"report: {result.report}")
    return lines


def run_pipeline(
    cfg: PipelineConfig,
    *,
    backend: Backend = "local",
    address: str | None = None,
    live: bool = True,
    console: Any = None,
    report: ReportWriter | None = None,
) -> PipelineResult:
    """Run the grid, then load every finished job's run folder, analyse each case once and
    (with ``report``) write the report; return the statuses, the report, the loaded runs and
    the analyses.

    ``report``: the report writer, called with the runs and the analyses while the output
    folder is still locked (the command's, :func:`sumo_ayss.commands.pipeline.run_pipeline`;
    None: no report, :attr:`PipelineResult.report` is None).

    The output folder is locked while it runs (:func:`sumo_ayss.grid.folder_lock.output_lock`):
    a second pipeline on it is refused with a :class:`~sumo_ayss.util.errors.LockError` naming
    the holder's PID.

    ``live``: show a live table when standard output is a terminal (``console``: the
    :class:`rich.console.Console` to draw it on, default a new one); job events are logged
    either way.
    """
    check_mode(cfg.report.mode)
    jobs = plan_jobs(cfg)
    check_out_dir(cfg.out, "out")
    with output_lock(cfg.out):  # one writer per output folder
        return _run_locked(cfg, jobs, backend, address, live, console, report)


def _run_locked(
    cfg: PipelineConfig,
    jobs: list[JobSpec],
    backend: Backend,
    address: str | None,
    live: bool,
    console: Any,
    write_report: ReportWriter | None,
) -> PipelineResult:
    """:func:`run_pipeline` once the output folder's lock is held."""
    from sumo_ayss.grid.study import prepare_out, set_aside_redefined

    notes = tuple(prepare_out(cfg, jobs))  # another study's folder is refused here
    study = StudyFolder(cfg.out)
    write_pipeline_json(study.pipeline_json, _relative_paths(to_dict(cfg), cfg.out))
    after = ", ".join(stages_after_grid(cfg))
    if backend == "local" and live and console is None and sys.stdout.isatty():
        from rich.console import Console

        console = Console()

    def run_jobs(todo: list[JobSpec]) -> list[JobStatus]:
        for line in set_aside_redefined(todo):  # adaptive seeding's jobs too
            logger.info(line)
        if backend == "ray":
            from sumo_ayss.grid.ray_backend import run_grid_ray

            return run_grid_ray(todo, cfg.retries, address, after=after)
        return run_grid_local(
            todo,
            min(cfg.n_workers, len(todo)),
            cfg.retries,
            console if live else None,
            after=after,
        )

    statuses = run_jobs(jobs)
    finished = [s.spec.run_dir for s in statuses if s.state == "done"]
    if not finished:
        return PipelineResult(statuses, None, [], [], cfg, notes)
    from sumo_ayss.grid.adaptive import is_adaptive, run_adaptive

    runs = load_runs(finished)  # read once: cross-play, the report and rank use them
    if get_mode(cfg.report.mode).runs_crossplay:
        run_crossplay_stage(cfg, statuses, runs)
    if is_adaptive(cfg):
        statuses, runs = run_adaptive(
            cfg, statuses, runs, run_jobs, run_crossplay_stage, plan_seed, load_runs
        )
    drawing = " and drawing the figures" if write_report is not None else ""
    with discriminability_beside(cfg):  # it reads the config only; the report reads its files
        logger.info("report: analysing %d run folders%s", len(runs), drawing)
        analyses = analyse_cases(case_runs(runs), cfg.report)  # once per case: report's, rank's
    report = (
        None
        if write_report is None
        else write_report(runs, study.report_dir, analyses=analyses, options=cfg.report)
    )
    return PipelineResult(statuses, report, runs, analyses, cfg, notes)


def stages_after_grid(cfg: PipelineConfig) -> list[str]:
    """What runs after the grid's jobs, outside their ETA (named in it: no silent gap)."""
    several = len(cfg.grid.vuts) >= 2
    stages = ["discriminability"] if several else []
    if several and get_mode(cfg.report.mode).runs_crossplay:
        stages.append("cross-play")
    from sumo_ayss.grid.adaptive import is_adaptive

    if is_adaptive(cfg):
        stages.append(f"adaptive seeding (up to {cfg.max_seeds} seeds)")
    return [*stages, "the report"]


def run_crossplay_stage(
    cfg: PipelineConfig, statuses: Sequence[JobStatus], runs: Sequence[RunRecord]
) -> list[Path]:
    """Cross-play of every case of the grid with two or more VUTs; the tables written.

    Every SPCP of the case drives against every VUT on the outcome scenarios
    (``evaluate.n_outcome`` of the outcome seed), :func:`sumo_ayss.crossplay.run_case`; a
    case already cross-played with the same SPCPs and settings is skipped. A case with one
    VUT has no cross-play; a case with a failed job is skipped with a warning (its report
    then says that the cross-play table is missing); a failure of the stage itself is
    logged, never fatal. ``runs``: the finished jobs' records (:func:`~sumo_ayss.run_folder.
    read_run`). The cells run on ``workers`` processes (:mod:`sumo_ayss.grid.cells`; one:
    in this process), the tables the same either way.
    """
    if len(cfg.grid.vuts) < 2:
        logger.info("cross-play skipped: the grid has one VUT (cross-play compares two or more)")
        return []

    from sumo_ayss.grid.cells import cell_pool

    with cell_pool(cfg.n_workers) as pool:  # one pool for every case's cells
        return _crossplay_cases(cfg, statuses, runs, pool)


def _crossplay_cases(
    cfg: PipelineConfig,
    statuses: Sequence[JobStatus],
    runs: Sequence[RunRecord],
    pool: CellRunner | None,
) -> list[Path]:
    """:func:`run_crossplay_stage`'s cases, their cells on ``pool`` (None: here)."""
    from sumo_ayss.crossplay import run_case
    from sumo_ayss.grid.adaptive import case_seeds
    from sumo_ayss.scenarios.outcome import DEFAULT_OUTCOME_SEED

    by_path = {r.path: r for r in runs}
    written = []
    for case in cfg.grid.cases:
        seeds = case_seeds(cfg, case)
        jobs = sorted(  # grid order (VUT, then seed), also after adaptive seeding added seeds
            (s for s in statuses if s.spec.case == case),
            key=lambda s: (cfg.grid.vuts.index(s.spec.vut), seeds.index(s.spec.seed)),
        )
        failed = [s.spec.name for s in jobs if s.state != "done"]
        if failed:
            logger.warning(
                "cross-play of %s skipped: %d job(s) not done (%s); the report says the "
                "cross-play table is missing",
                case,
                len(failed),
                ", ".join(failed),
            )
            continue
        try:
            csv_path = run_case(
                [by_path[s.spec.run_dir.resolve()] for s in jobs],
                StudyFolder(cfg.out).case(case).path,
                n=cfg.evaluate.n_outcome,
                seed=DEFAULT_OUTCOME_SEED,
                trust_controller=True,  # the pipeline's own runs, from the user's configs
                progress=functools.partial(_crossplay_progress, case),
                reference=cfg.evaluate.reference,
                references=cfg.evaluate.reference_rows,
                pool=pool,
            )
        except DiskFullError:
            raise
        except AyssError as e:  # never fatal: the report says the table is missing
            logger.warning("cross-play of %s failed: %s", case, e)
            continue
        written.append(csv_path)
    return written


def _crossplay_progress(case: str, line: str) -> None:
    logger.info("cross-play %s: %s", case, line)


def add_config_flags(parser: argparse.ArgumentParser) -> None:
    """The flags ``pipeline`` and ``rank`` share to replace parts of the config: ``--out``,
    ``--workers``, ``--seeds``, ``--budget`` and the budget overrides ``--total-timesteps``,
    ``--eval-every``, ``--n-outcome``, ``--n-ayss`` (a small budget without writing a YAML).
    They are written into ``pipeline.json`` and every run's ``config.yaml`` like the YAML's
    own values; :func:`config_from_args` applies them."""
    parser.add_argument("--out", type=Path, default=None, help="replace the config's out")
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument(
        "--seeds", type=int, nargs="+", default=None, help="replace grid.seeds (e.g. 100 101 102)"
    )
    parser.add_argument("--budget", choices=BUDGET_CHOICES, default=None, help=BUDGET_HELP)
    group = parser.add_argument_group(
        "budget overrides (replace the config's or the named --budget's values; written into "
        "pipeline.json and each run's config.yaml)"
    )
    group.add_argument(
        "--total-timesteps", type=int, default=None, help="training transitions per run"
    )
    group.add_argument(
        "--eval-every", type=int, default=None, help="transitions between SPCP candidates"
    )
    group.add_argument(
        "--n-outcome", type=int, default=None, help="outcome episodes per SPCP (paper: 200)"
    )
    group.add_argument("--n-ayss", type=int, default=None, help="AYSS Monte Carlo draws per SPCP")
    group.add_argument(
        "--learning-rate",
        type=float,
        default=None,
        help="the learner's Adam learning rate in every experiment (agent.learning_rate; "
        "default: the budget's where it names one, else the experiment's)",
    )
    group.add_argument(
        "--early-stop-patience",
        type=int,
        default=None,
        help="stop a run once this many candidates in a row have not beaten the best before "
        "them by more than early_stop_margin_se standard errors (train.early_stop_patience; "
        "default: off)",
    )
    group.add_argument(
        "--max-seeds",
        type=int,
        default=None,
        help="adaptive seeding: add seeds to a case whose ranking has not settled, up to this "
        "many per VUT (default: the budget's when it chose the seeds, fast 7; else fixed)",
    )


def config_from_args(args: argparse.Namespace) -> PipelineConfig:
    """``args.config`` with the flags of :func:`add_config_flags` applied, its
    ``report.mode`` checked against the registered modes."""
    cfg = load_pipeline(
        args.config,
        out=args.out,
        workers=args.workers,
        seeds=args.seeds,
        budget=args.budget,
        total_timesteps=args.total_timesteps,
        eval_every=args.eval_every,
        learning_rate=args.learning_rate,
        n_outcome=args.n_outcome,
        n_ayss=args.n_ayss,
        max_seeds=args.max_seeds,
        early_stop_patience=args.early_stop_patience,
    )
    check_mode(cfg.report.mode)
    return cfg


if __name__ == "__main__":  # python -m sumo_ayss.pipeline: the command (sumo_ayss.commands)
    from sumo_ayss.commands.pipeline import main

    main()
