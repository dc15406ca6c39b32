"""One command from config to verdict: the grid cases × VUTs × seeds, resumable.

    python -m sumo_ayss.pipeline configs/paper.yaml [--workers N] [--backend local|ray]

Progress: on a terminal, a live table of every job (queued / running / done / failed,
training steps, rate in steps/s, wall time in s) with the grid's ETA; with ``--no-live`` or
when the output is not a terminal, one log line per job event (started, each SPCP
candidate, training finished, done, failed) with the grid's counts and ETA.

Each job (case, VUT, seed) trains (or resumes) its SPCP candidates, selects the SPCP, runs
the outcome episodes and the Monte Carlo AYSS; then one report covers the whole grid. Jobs
run in parallel processes (one SUMO per process: libsumo holds one simulation each), or as
Ray tasks. Every stage writes atomically and is skipped when its output exists and was made
from the same inputs, so rerunning after a crash or Ctrl-C continues where it stopped. A
failing job is retried once, then reported with its log; it never costs the other jobs.

Pipeline YAML (every key optional)::

    grid: {cases: [car_following, cut_in], vuts: [pi1, pi2], seeds: [0, 1, 2]}
    experiments: {car_following: car_following.yaml, cut_in: cut_in.yaml}  # per case
    out: ../runs/paper          # relative to the YAML file
    total_timesteps: null       # override every experiment's train.total_timesteps
    eval_every: null            # override every experiment's train.eval_every
    evaluate: {n_outcome: 200, n_ayss: 100000}
    vuts: {}                    # extra VUTs (name: vehicle type) added to every experiment
    report: {mode: exposure}    # report options (sumo_ayss.report.options.ReportOptions)
    expected_order: []          # a known safety order, safest first (validation studies)
    workers: 0                  # 0 = as many as cores
    retries: 1
"""

from __future__ import annotations

import argparse
import collections
import dataclasses
import hashlib
import json
import logging
import multiprocessing
import os
import sys
import threading
import time
import traceback
import types
import typing
from collections.abc import Mapping, Sequence
from concurrent.futures import Future, ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar, Literal

from sumo_ayss.catalog import VehicleType
from sumo_ayss.cli import prog
from sumo_ayss.config import (
    PROJECT_ROOT,
    Case,
    _require,
    build,
    check_out_dir,
    check_seed,
    read_yaml,
    to_dict,
)
from sumo_ayss.errors import AyssError, ConfigError
from sumo_ayss.progress import GridProgress, JobStatus, format_duration
from sumo_ayss.report.options import ReportOptions
from sumo_ayss.run_folder import RunFolder, run_dir_for

logger = logging.getLogger("sumo_ayss.pipeline")  # also when run as __main__

Backend = Literal["local", "ray"]


@dataclass(frozen=True)
class GridConfig:
    """The grid of jobs. Section ``grid``."""

    SECTION: ClassVar[str] = "grid"

    cases: tuple[Case, ...] = ("car_following", "cut_in")
    vuts: tuple[str, ...] = ("pi1", "pi2")
    seeds: tuple[int, ...] = (0, 1, 2)

    def __post_init__(self) -> None:
        for name in ("cases", "vuts", "seeds"):
            values = getattr(self, name)
            _require(len(values) > 0, f"grid.{name} must not be empty")
            _require(len(set(values)) == len(values), f"grid.{name} has duplicates: {list(values)}")
        for seed in self.seeds:
            check_seed(seed, "grid.seeds[]")


@dataclass(frozen=True)
class EvaluateConfig:
    """Outcome and AYSS sizes. Section ``evaluate``."""

    n_outcome: int = 200
    n_ayss: int = 100_000

    def __post_init__(self) -> None:
        _require(self.n_outcome >= 1, f"evaluate.n_outcome must be >= 1, got {self.n_outcome}")
        _require(self.n_ayss >= 1, f"evaluate.n_ayss must be >= 1, got {self.n_ayss}")


@dataclass(frozen=True)
class PipelineConfig:
    """A whole batch: grid, experiment file per case, output folder, parallelism."""

    grid: GridConfig = field(default_factory=GridConfig)
    experiments: Mapping[str, Path] = field(
        default_factory=lambda: {
            "car_following": PROJECT_ROOT / "configs" / "car_following.yaml",
            "cut_in": PROJECT_ROOT / "configs" / "cut_in.yaml",
        }
    )
    out: Path = Path("runs") / "paper"
    total_timesteps: int | None = None
    eval_every: int | None = None
    evaluate: EvaluateConfig = field(default_factory=EvaluateConfig)
    vuts: Mapping[str, VehicleType] = field(default_factory=dict)
    """Extra VUTs (catalog syntax, as in ``env.vuts``) added to every case's experiment, so
    that a leaderboard defines its VUTs once for all cases."""
    report: ReportOptions = field(default_factory=ReportOptions)
    """Statistical settings and analysis mode of the report and the ranking."""
    expected_order: tuple[str, ...] = ()
    """A known safety order of the grid's VUTs, safest first (validation studies such as
    ladders): ``rank`` then reports Kendall's τ of its ranking against it and whether the
    two ends differ significantly. Empty: no known order."""
    workers: int = 0
    retries: int = 1

    def __post_init__(self) -> None:
        _require(self.workers >= 0, f"workers must be >= 0, got {self.workers}")
        _require(self.retries >= 0, f"retries must be >= 0, got {self.retries}")
        if self.expected_order:
            _require(
                sorted(self.expected_order) == sorted(self.grid.vuts),
                f"expected_order must list exactly the grid's VUTs {sorted(self.grid.vuts)}, "
                f"got {list(self.expected_order)}",
            )
        object.__setattr__(self, "vuts", types.MappingProxyType(dict(self.vuts)))
        for name, vt in self.vuts.items():
            vt.validate(f"vuts.{name}")
        known = typing.get_args(Case)
        for case in self.experiments:
            _require(
                case in known,
                f"experiments.{case}: unknown case; allowed: {list(known)}",
            )
        for case in self.grid.cases:
            _require(
                case in self.experiments,
                f"experiments has no file for case {case!r}; given: {sorted(self.experiments)}",
            )

    @property
    def n_workers(self) -> int:
        return self.workers or os.cpu_count() or 1


@dataclass(frozen=True)
class JobSpec:
    """One (case, VUT, seed): everything a worker process needs, picklable."""

    case: str
    vut: str
    seed: int
    experiment: dict[str, Any]
    """The resolved experiment (``ExperimentConfig.to_dict()``, VUT set)."""
    out: str
    n_outcome: int
    n_ayss: int

    @property
    def name(self) -> str:
        return f"{self.case}/{self.vut}/seed_{self.seed}"

    @property
    def run_dir(self) -> Path:
        return run_dir_for(self.out, self.case, self.vut, self.seed)


# ---------------------------------------------------------------------- loading


def load_pipeline(path: str | Path | None, **overrides: Any) -> PipelineConfig:
    """Pipeline YAML over defaults, then ``overrides`` (None values are ignored)."""
    if path is None:
        cfg = PipelineConfig()
    else:
        path = Path(path)
        cfg = build(PipelineConfig, read_yaml(path), "", path.resolve().parent)
    clean = {k: v for k, v in overrides.items() if v is not None}
    seeds = clean.pop("seeds", None)
    if seeds is not None:
        clean["grid"] = dataclasses.replace(cfg.grid, seeds=tuple(int(x) for x in seeds))
    return dataclasses.replace(cfg, **clean) if clean else cfg


def plan_jobs(cfg: PipelineConfig) -> list[JobSpec]:
    """Resolve every job's experiment; bad grids are refused here, before any job runs."""
    from sumo_ayss.experiment import load_experiment

    jobs = []
    for case in cfg.grid.cases:
        exp = load_experiment(cfg.experiments[case])
        if exp.env.case != case:
            raise ConfigError(
                f"experiments.{case}: {cfg.experiments[case]} is a {exp.env.case!r} experiment"
            )
        overrides: dict[str, Any] = {"progress_bar": False}
        if cfg.total_timesteps is not None:
            overrides["total_timesteps"] = cfg.total_timesteps
        if cfg.eval_every is not None:
            overrides["eval_every"] = cfg.eval_every
        exp = dataclasses.replace(exp, train=dataclasses.replace(exp.train, **overrides))
        if cfg.vuts:
            exp = dataclasses.replace(
                exp, env=dataclasses.replace(exp.env, vuts={**exp.env.vuts, **cfg.vuts})
            )
        for vut in cfg.grid.vuts:
            if vut not in exp.env.vuts:
                raise ConfigError(
                    f"grid.vuts: {vut!r} is not a VUT of the {case} experiment; "
                    f"allowed: {sorted(exp.env.vuts)}"
                )
            for seed in cfg.grid.seeds:
                jobs.append(
                    JobSpec(
                        case=case,
                        vut=vut,
                        seed=int(seed),
                        experiment=exp.with_vut(vut).to_dict(),
                        out=str(cfg.out),
                        n_outcome=cfg.evaluate.n_outcome,
                        n_ayss=cfg.evaluate.n_ayss,
                    )
                )
    return jobs


# ---------------------------------------------------------------------- one job


def _fingerprint(*parts: Any) -> str:
    h = hashlib.sha256()
    for part in parts:
        if isinstance(part, Path):
            h.update(part.read_bytes())
        else:
            h.update(json.dumps(part, sort_keys=True, default=str).encode())
    return h.hexdigest()[:16]


def run_job(spec: JobSpec) -> dict[str, Any]:
    """Train (or resume, or skip) and evaluate one job. Runs in a worker process."""
    from sumo_ayss.evaluate import evaluate_run
    from sumo_ayss.experiment import experiment_from_dict
    from sumo_ayss.run_folder import read_evaluate_done, write_evaluate_done, write_progress
    from sumo_ayss.scenarios.ayss import AyssConfig
    from sumo_ayss.threads import set_torch_threads
    from sumo_ayss.train import train

    run_dir = spec.run_dir
    folder = RunFolder(run_dir)
    run_dir.mkdir(parents=True, exist_ok=True)
    handler = logging.FileHandler(folder.job_log)
    handler.setFormatter(logging.Formatter("%(asctime)s %(name)s %(levelname)s: %(message)s"))
    root = logging.getLogger()
    root.addHandler(handler)
    root.setLevel(logging.INFO)
    t0 = time.perf_counter()
    stages: dict[str, str] = {}
    times: dict[str, float] = {}
    try:
        cfg = experiment_from_dict(spec.experiment, run_dir)
        set_torch_threads(cfg.train.torch_threads)  # for evaluate too, when training is skipped
        if folder.spcp_json.is_file() and folder.config.is_file():
            from sumo_ayss.train import _check_same_config

            _check_same_config(run_dir, cfg, spec.seed)  # raises if the inputs changed
            stages["train"] = "skipped"
        else:
            resume = folder.config.is_file()
            train(cfg, spec.seed, Path(spec.out), resume=resume, argv=["--pipeline", spec.name])
            stages["train"] = "resumed" if resume else "done"
        times["train_s"] = time.perf_counter() - t0

        write_progress(run_dir, "evaluate")
        t1 = time.perf_counter()
        key = _fingerprint(folder.spcp_zip, spec.n_outcome, spec.n_ayss)
        if read_evaluate_done(folder.evaluate_done) == key:
            stages["evaluate"] = "skipped"
        else:
            evaluate_run(
                run_dir,
                n_outcome=spec.n_outcome,
                ayss=AyssConfig(n_samples=spec.n_ayss),
                force=True,
                progress=False,
                trust_controller=True,  # the pipeline's own runs, from the user's configs
            )
            write_evaluate_done(folder.evaluate_done, key)
            stages["evaluate"] = "done"
        times["evaluate_s"] = time.perf_counter() - t1
        write_progress(run_dir, "done")
    except BaseException:
        logger.exception("job %s failed", spec.name)
        raise
    finally:
        root.removeHandler(handler)
        handler.close()
    return {"job": spec.name, "stages": stages, "wall_s": time.perf_counter() - t0, **times}


# ---------------------------------------------------------------------- the grid


def _worker_init() -> None:
    """Worker initializer: die with the pipeline, and leave Ctrl-C to it.

    On Linux a worker gets SIGKILLed when the pipeline process dies: without it a killed
    pipeline leaves its workers running, and a rerun would race them for the same run
    folders. A Ctrl-C reaches every process of the terminal's group; workers ignore it and
    the pipeline stops them (:func:`_stop_workers`), so that no job starts afterwards.
    It also runs before any job imports torch, so that torch's intra-op pool starts with one
    BLAS/OpenMP thread (``run_job`` then applies ``train.torch_threads``).
    """
    import signal

    from sumo_ayss.threads import single_thread_env

    single_thread_env()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if sys.platform.startswith("linux"):
        import ctypes

        libc = ctypes.CDLL("libc.so.6", use_errno=True)
        pr_set_pdeathsig = 1
        libc.prctl(pr_set_pdeathsig, signal.SIGKILL)


def _stop_workers(pool: ProcessPoolExecutor, grace_s: float = 3.0) -> None:
    """Terminate the pool's worker processes now (SIGTERM, then SIGKILL after ``grace_s``).

    Safe for the run folders: every result is written atomically and a rerun resumes from
    the last checkpoint (:func:`sumo_ayss.train.train`).
    """
    processes = list(getattr(pool, "_processes", {}).values())  # CPython's worker table
    for proc in processes:
        if proc.is_alive():
            proc.terminate()
    deadline = time.monotonic() + grace_s
    for proc in processes:
        proc.join(max(0.0, deadline - time.monotonic()))
        if proc.is_alive():
            proc.kill()
            proc.join(1.0)
    pool.shutdown(wait=False, cancel_futures=True)


class _Terminated(KeyboardInterrupt):
    """SIGTERM, handled as a Ctrl-C."""


def _raise_terminated(signum: int, frame: Any) -> None:
    raise _Terminated


def run_grid_local(
    jobs: Sequence[JobSpec], workers: int, retries: int, live: Any = None
) -> list[JobStatus]:
    """Run ``jobs`` on a local process pool with retries; report progress as it goes.

    At most ``workers`` jobs are handed to the pool at a time; the others wait here, so the
    jobs shown as running are the ones a worker holds, and a Ctrl-C (SIGINT) or SIGTERM
    cancels them at once: running jobs are terminated (their state is ``interrupted``,
    resumable), queued ones never start (``cancelled``), and the KeyboardInterrupt
    propagates to the caller within seconds. Every job event is logged (one line each, with
    the grid's counts and ETA); ``live`` (a :class:`rich.console.Console`, or None for
    none) also shows a table of every job that refreshes twice a second.
    """
    import signal

    statuses = [JobStatus(j) for j in jobs]
    progress = GridProgress(statuses, workers)
    queue: collections.deque[JobStatus] = collections.deque(statuses)
    ctx = multiprocessing.get_context("spawn")  # fresh interpreters: no inherited libsumo
    logger.info(
        "%d jobs on %d worker processes; each job logs to <run folder>/job.log",
        len(jobs),
        workers,
    )
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=_worker_init)
    pending: dict[Future[dict[str, Any]], JobStatus] = {}
    in_main = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGTERM, _raise_terminated) if in_main else None
    display = None

    def submit(s: JobStatus) -> None:
        s.start()
        pending[pool.submit(run_job, s.spec)] = s
        logger.info(progress.line(s, f"started (try {s.attempts})"))

    try:
        display = _live(progress, live) if live is not None else None
        while pending or queue:
            while queue and len(pending) < workers:
                submit(queue.popleft())
            finished = [f for f in list(pending) if f.done()]
            for event in progress.poll():  # also the last events of the finished jobs
                logger.info(event)
            for fut in finished:
                s = pending.pop(fut)
                try:
                    result = fut.result()
                except Exception as e:  # a job's failure is data here
                    s.error = "".join(traceback.format_exception_only(e)).strip()
                    s.stage = ""
                    if s.attempts <= retries:
                        s.state = "queued"
                        queue.appendleft(s)
                        logger.warning(progress.line(s, f"failed ({s.error}); will retry"))
                    else:
                        s.state = "failed"
                        log = RunFolder(s.spec.run_dir).job_log
                        logger.error(progress.line(s, f"FAILED: {s.error} (log: {log})"))
                    continue
                logger.info(progress.finished(s, result))
            if display is not None:
                display.update(progress.table())
            time.sleep(0.2)
    except KeyboardInterrupt:
        for s in queue:
            s.state = "cancelled"
        for fut, s in pending.items():
            fut.cancel()
            s.state = "interrupted"
        _stop_workers(pool)
        logger.warning(
            "interrupted: %d running job(s) stopped, %d queued job(s) cancelled; rerun the "
            "same command to resume",
            len(pending),
            len(queue),
        )
        raise
    finally:
        if in_main:
            signal.signal(signal.SIGTERM, previous)
        if display is not None:
            display.update(progress.table())
            display.stop()
        pool.shutdown(wait=False, cancel_futures=True)
    c = progress.counts()
    logger.info(
        "grid finished: %d done, %d failed, %s wall",
        c["done"],
        c["failed"],
        format_duration(time.time() - progress.t0),
    )
    return statuses


def _live(progress: GridProgress, console: Any) -> Any:
    from rich.live import Live

    live = Live(progress.table(), console=console, refresh_per_second=2, transient=False)
    live.start()
    return live


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


def final_messages(statuses: Sequence[JobStatus], report: Path | None) -> list[str]:
    """What the CLI prints at the end: failures, the report and its trust warnings."""
    lines = [
        f"FAILED {s.spec.name}: {s.error}  (log: {RunFolder(s.spec.run_dir).job_log})"
        for s in statuses
        if s.state == "failed"
    ]
    done = [s for s in statuses if s.state == "done"]
    if done:
        from sumo_ayss.report.checks import read_training, trust_warnings

        runs = [(s.spec.name, read_training(s.spec.run_dir)) for s in done]
        lines += [f"WARNING: {w}" for w in trust_warnings(runs)]
    if report is not None:
        lines.append(f"report: {report}")
    return lines


def run_pipeline(
    cfg: PipelineConfig,
    *,
    backend: Backend = "local",
    address: str | None = None,
    live: bool = True,
    console: Any = None,
) -> tuple[list[JobStatus], Path | None]:
    """Run the grid, then the report over every finished job; return statuses and report.

    ``live``: show a live table when standard output is a terminal (``console``: the
    :class:`rich.console.Console` to draw it on, default a new one); job events are logged
    either way.
    """
    jobs = plan_jobs(cfg)
    check_out_dir(cfg.out, "out")
    cfg.out.mkdir(parents=True, exist_ok=True)
    from sumo_ayss.atomic import atomic_write_json

    atomic_write_json(cfg.out / "pipeline.json", _relative_paths(to_dict(cfg), cfg.out))
    if backend == "ray":
        from sumo_ayss.ray_backend import run_grid_ray

        statuses = run_grid_ray(jobs, cfg.retries, address)
    else:
        if live and console is None and sys.stdout.isatty():
            from rich.console import Console

            console = Console()
        statuses = run_grid_local(
            jobs, min(cfg.n_workers, len(jobs)), cfg.retries, console if live else None
        )
    finished = [s.spec.run_dir for s in statuses if s.state == "done"]
    report = None
    if finished:
        write_discriminability(cfg)
        from sumo_ayss.report import write_report

        report = write_report(finished, cfg.out / "report", options=cfg.report)
    return statuses, report


def write_discriminability(cfg: PipelineConfig) -> None:
    """``<out>/<case>/discriminability.json`` (+ .csv, .png) for every case with >= 2 VUTs.

    Where the grid's VUTs' one-step responses differ over the AYSS box
    (:mod:`sumo_ayss.discriminability`, default grid, some seconds per VUT); the report shows
    it. Skipped when an up-to-date record exists; a failure is logged, never fatal.
    """
    if len(cfg.grid.vuts) < 2:
        return
    from sumo_ayss import discriminability
    from sumo_ayss.errors import AyssError

    for case in cfg.grid.cases:
        try:
            env = discriminability.pipeline_env(cfg, case)
            discriminability.ensure(env, cfg.grid.vuts, cfg.out / case)
        except (AyssError, ImportError, OSError) as e:  # never fatal: the report says so
            logger.warning("discriminability of %s not computed: %s", case, e)


def main(argv: Sequence[str] | None = None) -> None:
    parser = argparse.ArgumentParser(
        prog=prog("python -m sumo_ayss.pipeline"), description=__doc__.splitlines()[0]
    )
    parser.add_argument(
        "config", type=Path, help="pipeline YAML (configs/paper.yaml runs the paper's grid)"
    )
    parser.add_argument("--out", type=Path, default=None)
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument(
        "--seeds", type=int, nargs="+", default=None, help="replace grid.seeds (e.g. 100 101 102)"
    )
    parser.add_argument("--backend", choices=["local", "ray"], default="local")
    parser.add_argument("--address", default=None, help="Ray cluster address (ray backend)")
    parser.add_argument(
        "--no-live",
        action="store_true",
        help="no live table: one log line per job event (the default when stdout is not a "
        "terminal)",
    )
    args = parser.parse_args(argv)
    console = configure_logging(not args.no_live)
    try:
        cfg = load_pipeline(args.config, out=args.out, workers=args.workers, seeds=args.seeds)
        statuses, report = run_pipeline(
            cfg,
            backend=args.backend,
            address=args.address,
            live=console is not None,
            console=console,
        )
    except AyssError as e:
        sys.exit(f"error: {e}")
    except KeyboardInterrupt:
        print("interrupted: no job runs any more; rerun the same command to resume", flush=True)
        sys.exit(130)
    for line in final_messages(statuses, report):
        print(line)
    sys.exit(1 if any(s.state == "failed" for s in statuses) else 0)


if __name__ == "__main__":
    main()
