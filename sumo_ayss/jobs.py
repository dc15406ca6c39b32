"""One pipeline job, (case, VUT, seed): its definition and its execution in a worker.

:class:`JobSpec` is what a worker process (or a Ray task) receives; :func:`run_job` trains
(or resumes, or skips) and evaluates it. The local scheduler (:mod:`sumo_ayss.grid_local`),
the Ray backend (:mod:`sumo_ayss.ray_backend`) and the pipeline (:mod:`sumo_ayss.pipeline`)
import this module; it imports none of them.
"""

from __future__ import annotations

import hashlib
import json
import logging
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sumo_ayss.config import AyssConfig, ExperimentConfig
from sumo_ayss.errors import ControllerError
from sumo_ayss.run_folder import (
    RunFolder,
    read_evaluate_done,
    run_dir_for,
    write_evaluate_done,
    write_progress,
)

logger = logging.getLogger("sumo_ayss.pipeline")

#: Failures a retry would repeat, so the schedulers do not retry them: a user controller
#: that raised or returned no number does so again on the same seed and path (the retry
#: resumes from the last candidate and drives the same episodes); a retry only delayed the
#: pipeline's exit by the time to get there again (18-40 s in issue 23).
NOT_RETRIED: tuple[type[BaseException], ...] = (ControllerError,)


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
        return run_dir_for(self.out, self.case, self.vut, self.seed)


def _fingerprint(*parts: Any) -> str:
    h = hashlib.sha256()
    for part in parts:
        if isinstance(part, Path):
            h.update(part.read_bytes())
        else:
            h.update(json.dumps(part, sort_keys=True, default=str).encode())
    return h.hexdigest()[:16]


def _ayss_key(ayss: AyssConfig) -> list[Any]:
    """What of ``ayss`` the evaluation marker records: the draws, plus every other setting
    when one differs from its default (so markers written before ``evaluate.ayss`` existed
    stay valid)."""
    if ayss == AyssConfig(n_samples=ayss.n_samples):
        return [ayss.n_samples]
    return [ayss.n_samples, ayss.to_dict()]


def run_job(spec: JobSpec) -> dict[str, Any]:
    """Train (or resume, or skip) and evaluate one job. Runs in a worker process."""
    from sumo_ayss.evaluate import evaluate_run
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
        cfg = spec.experiment
        set_torch_threads(cfg.train.torch_threads)  # for evaluate too, when training is skipped
        if folder.spcp_json.is_file() and folder.config.is_file():
            from sumo_ayss.training.config_check import check_same_config

            check_same_config(run_dir, cfg, spec.seed)  # raises if the inputs changed
            stages["train"] = "skipped"
        else:
            resume = folder.config.is_file()
            train(cfg, spec.seed, Path(spec.out), resume=resume, argv=["--pipeline", spec.name])
            stages["train"] = "resumed" if resume else "done"
        times["train_s"] = time.perf_counter() - t0

        write_progress(run_dir, "evaluate")
        t1 = time.perf_counter()
        key = _fingerprint(folder.spcp_zip, spec.n_outcome, *_ayss_key(spec.ayss))
        if read_evaluate_done(folder.evaluate_done) == key:
            stages["evaluate"] = "skipped"
        else:
            evaluate_run(
                run_dir,
                n_outcome=spec.n_outcome,
                ayss=spec.ayss,
                force=True,
                progress=False,
                trust_controller=True,  # the pipeline's own runs, from the user's configs
                run=(cfg, spec.seed),  # the config in hand: config.yaml is not parsed again
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
