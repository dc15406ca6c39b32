"""One pipeline job, (case, VUT, seed): its definition and its execution in a worker.

:class:`JobSpec` is what a worker process (or a Ray task) receives; :func:`run_job` trains
(or resumes, or skips) and evaluates it. The local scheduler (:mod:`sumo_ayss.grid.local`),
the Ray backend (:mod:`sumo_ayss.grid.ray_backend`) and the pipeline (:mod:`sumo_ayss.pipeline`)
import this module; it imports none of them.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sumo_ayss.config import AyssConfig, ExperimentConfig
from sumo_ayss.run_folder import (
    RunFolder,
    StudyFolder,
    read_run,
    write_progress,
)
from sumo_ayss.stages import EvaluateStage, TrainStage, is_done
from sumo_ayss.util.errors import ControllerError, DiskFullError
from sumo_ayss.vuts.reference_types import DEFAULT_REFERENCE

logger = logging.getLogger("sumo_ayss.pipeline")

#: Failures a retry would repeat, so the schedulers do not retry them: a user controller
#: that raised or returned no number does so again on the same seed and path (the retry
#: resumes from the last candidate and drives the same episodes); a retry only delayed the
#: pipeline's exit by the time to get there again (18-40 s in issue 23). A full disk stops
#: the whole grid (every other job would meet it too).
NOT_RETRIED: tuple[type[BaseException], ...] = (ControllerError, DiskFullError)


@dataclass(frozen=True)
class JobSpec:
    """One (case, VUT, seed): everything a worker process needs, picklable.

    The configuration travels as the frozen record the pipeline built (never re-parsed in
    the worker).
    """

    case: str
    vut: str
    seed: int
    experiment: ExperimentConfig
    """The resolved experiment, its ``env.vut`` set to ``vut``."""
    out: str
    n_outcome: int
    """Outcome episodes (``evaluate.n_outcome``)."""
    ayss: AyssConfig
    """Monte Carlo settings of the AYSS stage (``evaluate.ayss``)."""
    reference: str | None = DEFAULT_REFERENCE
    """The reference driver that labels the outcome's crashes (``evaluate.reference``)."""

    def __post_init__(self) -> None:
        if (self.experiment.env.case, self.experiment.env.vut) != (self.case, self.vut):
            raise ValueError(
                f"JobSpec {self.name}: its experiment is {self.experiment.env.case}/"
                f"{self.experiment.env.vut}"
            )

    @property
    def name(self) -> str:
        return f"{self.case}/{self.vut}/seed_{self.seed}"

    @property
    def run_dir(self) -> Path:
        return StudyFolder(Path(self.out)).run(self.case, self.vut, self.seed).path

    @property
    def folder(self) -> RunFolder:
        """The job's run folder."""
        return RunFolder(self.run_dir)


def is_finished(spec: JobSpec) -> bool:
    """Whether the job's run folder holds its finished training and evaluation (same inputs)."""
    folder = spec.folder
    return is_done(TrainStage(folder, spec.experiment, spec.seed)) and is_done(
        EvaluateStage(folder, spec.n_outcome, spec.ayss)
    )


def run_job(spec: JobSpec) -> dict[str, Any]:
    """Train (or resume, or skip) and evaluate one job. Runs in a worker process."""
    from sumo_ayss.evaluate import backfill_ayss_bins, evaluate_run
    from sumo_ayss.grid.threads import set_torch_threads
    from sumo_ayss.training.trainer import train

    folder = spec.folder
    run_dir = folder.path
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
        cfg = spec.experiment
        set_torch_threads(cfg.train.torch_threads)  # for evaluate too, when training is skipped
        if is_done(TrainStage(folder, cfg, spec.seed)):
            stages["train"] = "skipped"
        else:
            # A run folder with another configuration is refused here, naming the fields.
            resume = folder.config.is_file()
            train(cfg, spec.seed, Path(spec.out), resume=resume, argv=["--pipeline", spec.name])
            stages["train"] = "resumed" if resume else "done"
        times["train_s"] = time.perf_counter() - t0

        write_progress(run_dir, "evaluate")
        t1 = time.perf_counter()
        evaluation = EvaluateStage(folder, spec.n_outcome, spec.ayss)
        # a run evaluated before ayss_bins.csv existed: reduce its ayss.csv, no re-evaluation
        backfill_ayss_bins(folder.ayss_csv, folder.ayss_bins)
        if is_done(evaluation):
            stages["evaluate"] = "skipped"
        else:
            evaluate_run(
                read_run(run_dir),  # read once, after training, and handed on
                n_outcome=spec.n_outcome,
                ayss=spec.ayss,
                force=True,
                progress=False,
                trust_controller=True,  # the pipeline's own runs, from the user's configs
                reference=spec.reference,
            )
            evaluation.mark_done()
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
