"""Progress of a pipeline grid that a person can follow: per-job state, steps, rate, ETA.

The main process never talks to its workers about progress: it reads what each job writes
into its run folder (read with :mod:`sumo_ayss.run_folder`'s readers). The trainer rewrites
``progress.json`` atomically every few seconds (:func:`sumo_ayss.run_folder.write_progress`:
stage, step, total, rate); ``checkpoints/
latest.json`` names the last candidate; ``spcp.json`` and ``evaluate.done.json`` mark the
finished stages. From these :class:`GridProgress` makes

- one log line per job event (started, each new SPCP candidate, training finished,
  evaluation finished, failed, retried), each prefixed with the grid's counts and ETA, for
  ``--no-live`` runs and logs;
- a table for a live terminal display (jobs queued / train / evaluate / done / failed,
  training progress, rate in steps/s, tries, wall time in s) with the grid's ETA in its
  title, readable at 80 columns.

Imports neither SUMO nor torch.
"""

from __future__ import annotations

import math
import statistics
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol

from sumo_ayss.run_folder import RunFolder, read_eval_table, read_progress
from sumo_ayss.training.checkpoint_files import LATEST_JSON, read_latest
from sumo_ayss.util.errors import CheckpointError

STATES = ("queued", "running", "done", "failed", "interrupted", "cancelled")


class _Spec(Protocol):
    @property
    def name(self) -> str: ...

    @property
    def folder(self) -> RunFolder: ...

    experiment: dict[str, Any]


@dataclass
class JobStatus:
    """What the pipeline knows about one job.

    Attributes:
        spec: The job (:class:`sumo_ayss.grid.jobs.JobSpec`).
        state: One of :data:`STATES`; ``running`` only while a worker holds the job;
            ``interrupted`` / ``cancelled`` after a Ctrl-C (running / still queued then).
        attempts: Tries started so far.
        error: The last failure, one line.
        wall_s: Wall time of the finished try, s.
        started_at: ``time.time()`` when the current try was handed to a worker, s.
        stage: ``train``, ``evaluate`` or ``done`` while running / when done; "" before.
        step: Training transitions done (last seen).
        total: Training transitions asked for (``train.total_timesteps``).
        rate_steps_per_s: Last training rate seen, transitions per s of wall time.
        candidate_step: Step of the last SPCP candidate seen (``latest.json``), for events.
        train_s: Wall time of the training stage of the finished try, s (None: unknown).
        evaluate_s: Wall time of the evaluation stage of the finished try, s.
        stages: What the finished try did per stage (``done``, ``resumed``, ``skipped``).
        step_at_start: Training transitions already done when the current try began.
    """

    spec: Any
    state: str = "queued"
    attempts: int = 0
    error: str = ""
    wall_s: float = 0.0
    started_at: float | None = None
    stage: str = ""
    step: int = 0
    total: int = 0
    rate_steps_per_s: float | None = None
    candidate_step: int | None = None
    train_s: float | None = None
    evaluate_s: float | None = None
    stages: dict[str, str] = field(default_factory=dict)
    step_at_start: int = 0

    def __post_init__(self) -> None:
        self.total = int(self.spec.experiment.train.total_timesteps)
        self.step = _finished_steps(self.spec.folder, self.total)

    def start(self) -> None:
        """A worker takes the job: a new try begins (candidates found now are not events)."""
        self.attempts += 1
        self.state, self.stage, self.started_at = "running", "", time.time()
        self.step_at_start = self.step = _finished_steps(self.spec.folder, self.total)
        found = _candidates(self.spec.folder)
        self.candidate_step = found[-1][0] if found else None


def _finished_steps(folder: RunFolder, total: int) -> int:
    """Training transitions already in the run folder from an earlier invocation."""
    if folder.spcp_json.is_file():
        return total
    try:
        return read_latest(folder.checkpoints / LATEST_JSON)[0]
    except CheckpointError:  # missing (no checkpoint yet) or being replaced
        return 0


def _candidates(folder: RunFolder) -> list[tuple[int, str]]:
    """(step, mean evaluation reward to 2 decimals) of each SPCP candidate in ``eval.csv``."""
    try:
        rows = read_eval_table(folder.eval_table, skip_bad_rows=True)
    except CheckpointError:
        return []
    return [(int(row["step"]), f"{row['mean_return']:.2f}") for row in rows]


def format_duration(seconds: float) -> str:
    """``"45 s"``, ``"12 min"``, ``"1 h 05 min"``."""
    if not math.isfinite(seconds):
        return "?"
    seconds = max(0.0, seconds)
    if seconds < 90:
        return f"{seconds:.0f} s"
    minutes = round(seconds / 60)
    if minutes < 60:
        return f"{minutes} min"
    return f"{minutes // 60} h {minutes % 60:02d} min"


class GridProgress:
    """Watches the run folders of a grid's jobs; see the module docstring.

    Args:
        statuses: The grid's jobs (the pipeline updates ``state``, ``attempts``,
            ``started_at``, ``wall_s`` and the stage times; :meth:`poll` the rest).
        workers: Worker processes, for the ETA.
        after: What runs after the grid and is not in the ETA (e.g. ``"cross-play and
            the report"``), named in the ETA text so that no stage is a silent gap; "" for
            nothing.
    """

    def __init__(self, statuses: Sequence[JobStatus], workers: int, after: str = "") -> None:
        self.statuses = list(statuses)
        self.workers = max(1, workers)
        self.after = after
        self.t0 = time.time()

    def finished(self, s: JobStatus, result: dict[str, Any]) -> str:
        """Record a finished try (``result``: :func:`sumo_ayss.grid.jobs.run_job`'s); event."""
        s.state, s.stage = "done", "done"
        s.wall_s, s.stages = float(result["wall_s"]), dict(result["stages"])
        s.train_s, s.evaluate_s = result.get("train_s"), result.get("evaluate_s")
        trained = s.total - s.step_at_start
        if s.stages.get("train") != "skipped" and s.train_s and trained > 0:
            s.rate_steps_per_s = trained / s.train_s
        s.step = s.total
        what = ", ".join(f"{k} {v}" for k, v in s.stages.items())
        times = ""
        if s.train_s is not None and s.evaluate_s is not None:
            times = f"; training {s.train_s:.0f} s, evaluation {s.evaluate_s:.0f} s"
        return self.line(s, f"done in {s.wall_s:.0f} s ({what}{times})")

    # -- reading the run folders ------------------------------------------------------

    def poll(self) -> list[str]:
        """Refresh the running jobs from their run folders; return new event lines."""
        events = []
        for s in self.statuses:
            if s.state != "running":
                continue
            folder = s.spec.folder
            progress = read_progress(folder.path)
            if progress and float(progress.get("time", 0)) < (s.started_at or 0) - 1:
                progress = None  # left by an earlier invocation
            rate = progress.get("rate_steps_per_s") if progress else None
            at = f" ({rate:.0f} steps/s)" if isinstance(rate, int | float) and rate > 0 else ""
            for step, reward in _candidates(folder):
                if s.candidate_step is None or step > s.candidate_step:
                    text = f"SPCP candidate at step {step:,}/{s.total:,}{at}"
                    events.append(self.line(s, f"{text}: mean evaluation reward {reward}"))
                    s.candidate_step = step
            if progress:
                stage = str(progress.get("stage", ""))
                if stage == "train":
                    s.step = int(progress.get("step", s.step))
                    rate = progress.get("rate_steps_per_s")
                    if isinstance(rate, int | float) and rate > 0:
                        s.rate_steps_per_s = float(rate)
                if stage and stage != s.stage:
                    if stage == "evaluate":
                        s.step = s.total if folder.spcp_json.is_file() else s.step
                        events.append(self.line(s, "training finished; evaluating"))
                    s.stage = stage
        return events

    # -- numbers ----------------------------------------------------------------------

    def counts(self) -> dict[str, int]:
        out = dict.fromkeys(STATES, 0)
        for s in self.statuses:
            out[s.state] = out.get(s.state, 0) + 1
        return out

    def job_rate(self) -> float | None:
        """Typical training rate of one job, transitions/s (median of those seen)."""
        rates = [s.rate_steps_per_s for s in self.statuses if s.rate_steps_per_s]
        return statistics.median(rates) if rates else None

    def eta_s(self) -> tuple[float | None, bool]:
        """Seconds until the grid is done, and whether evaluation time is included.

        Remaining training transitions of unfinished jobs at the typical per-job rate, plus
        one evaluation per job that has not finished (the mean of the finished ones' when
        known), spread over ``min(workers, unfinished jobs)`` workers. None before any rate
        is known. A rough estimate: jobs of different cases train at different rates.
        """
        todo = [s for s in self.statuses if s.state in ("queued", "running")]
        if not todo:
            return 0.0, True
        steps = sum(max(0, s.total - s.step) for s in todo)
        rate = self.job_rate()
        if rate is None and steps > 0:
            return None, False
        train = steps / rate if steps > 0 and rate else 0.0
        evals = [s.evaluate_s for s in self.statuses if s.evaluate_s is not None]
        with_eval = bool(evals)
        work = train + (statistics.mean(evals) * len(todo) if evals else 0.0)
        return work / min(self.workers, len(todo)), with_eval

    def eta_text(self) -> str:
        eta, with_eval = self.eta_s()
        then = f" (jobs; then {self.after})" if self.after else ""
        if eta is None:
            return f"ETA: after the first rate is measured{then}"
        text = f"ETA ≈ {format_duration(eta)}"
        return (text if with_eval else text + " + evaluation") + then

    def retried(self) -> list[JobStatus]:
        """Jobs that needed more than one try (whatever their state now)."""
        return [s for s in self.statuses if s.attempts > 1]

    def header(self) -> str:
        """``"2/8 done, 2 running, 4 queued, 0 failed, 1 retried; 3 min elapsed; ETA ≈ 9
        min"`` (the retried count only when a job was retried; jobs handed over beyond the
        workers as ``"N submitted (waiting for a CPU)"``)."""
        c = self.counts()
        elapsed = format_duration(time.time() - self.t0)
        retried = len(self.retried())
        again = f", {retried} retried" if retried else ""
        # A backend that hands every job over at once (Ray) has more jobs "running" than
        # CPUs: those beyond the workers are submitted, waiting for a CPU, not running.
        running = min(c["running"], self.workers)
        waiting = c["running"] - running
        submitted = f", {waiting} submitted (waiting for a CPU)" if waiting else ""
        return (
            f"{c['done']}/{len(self.statuses)} done, {running} running{submitted}, "
            f"{c['queued']} queued, {c['failed']} failed{again}; {elapsed} elapsed; "
            f"{self.eta_text()}"
        )

    def summary(self) -> str:
        """The grid's last line: ``"grid finished: 7 done (1 after a retry), 1 failed, 12
        min wall"``."""
        c = self.counts()
        passed = sum(1 for s in self.retried() if s.state == "done")
        again = f" ({passed} after a retry)" if passed else ""
        wall = format_duration(time.time() - self.t0)
        return f"grid finished: {c['done']} done{again}, {c['failed']} failed, {wall} wall"

    def line(self, s: JobStatus, event: str) -> str:
        """One log line for an event of job ``s``."""
        return f"[{self.header()}] {s.spec.name}: {event}"

    def progress_text(self, s: JobStatus) -> str:
        if s.state == "done":
            return f"{s.total:,}/{s.total:,}"
        if s.total and (s.step or s.state == "running"):
            return f"{s.step:,}/{s.total:,} ({100 * s.step / s.total:.0f} %)"
        return ""

    def short_progress(self, s: JobStatus) -> str:
        """``"42 % of 10k"``: the training progress in a narrow table cell."""
        if not s.total or not (s.step or s.state in ("running", "done")):
            return ""
        step = s.total if s.state == "done" else s.step
        total = f"{s.total / 1000:g}k" if s.total >= 1000 else str(s.total)
        return f"{100 * step / s.total:.0f} % of {total}"

    # -- live table -------------------------------------------------------------------

    def table(self) -> Any:
        """A rich table of every job (headers escaped: rich reads ``[s]`` as markup)."""
        # Fits 80 columns: short headers that are never cut ("runn…", "[ste…" were
        # unreadable), the running stage as the state, no vertical rules; a long job name
        # folds onto a second line instead of squeezing the other cells.
        from rich import box
        from rich.markup import escape
        from rich.table import Table

        table = Table(
            title=escape(f"sumo_ayss pipeline: {self.header()}"),
            expand=False,
            box=box.SIMPLE_HEAD,
            pad_edge=False,
            show_edge=False,
        )
        for col, right, width in (
            ("job", False, 12),
            ("state", False, len("interrupted")),
            ("steps", True, len("100 % of 200k")),
            ("steps/s", True, len("steps/s")),
            ("try", True, len("try")),
            ("wall s", True, len("wall s")),
        ):
            table.add_column(
                escape(col),
                justify="right" if right else "left",
                no_wrap=col != "job",
                overflow="fold",
                min_width=width,
            )
        colours = {
            "done": "green",
            "failed": "red",
            "running": "yellow",
            "queued": "white",
            "interrupted": "red",
            "cancelled": "red",
        }
        now = time.time()
        for s in self.statuses:
            colour = colours.get(s.state, "white")
            if s.state == "running" and s.started_at is not None:
                wall = f"{now - s.started_at:.0f}"
            else:
                wall = f"{s.wall_s:.0f}" if s.wall_s else ""
            rate = f"{s.rate_steps_per_s:.0f}" if s.rate_steps_per_s else ""
            state = s.stage if s.state == "running" and s.stage else s.state
            table.add_row(
                escape(s.spec.name),
                f"[{colour}]{escape(state)}[/{colour}]",
                self.short_progress(s),
                rate if s.state in ("running", "done") else "",
                str(s.attempts),
                wall,
            )
        return table
