"""Ray backend of the pipeline: one Ray task per (case, VUT, seed) on an existing cluster.

``python -m sumo_ayss.pipeline configs/paper.yaml --backend ray [--address auto]``

Without ``--address`` Ray starts a private instance on this machine for the pipeline;
``--address auto`` (or ``ray://host:10001``) joins a cluster that is already running
(``ray start --head`` on the head machine, ``ray start --address <head>:6379`` on workers).

Workers need not share a file system with the driver: a task receives the job's run
folder as it stands on the driver (empty, half-trained or finished), works on a private
copy, and returns the folder as a gzipped tar that the driver unpacks in place. So the
skip / resume logic is the same as on a local pool, and the results land in the run folder
on the driver. ``ray`` is an optional extra: ``pip install 'sumo_ayss[ray]'``.
"""

from __future__ import annotations

import dataclasses
import io
import logging
import shutil
import tarfile
import tempfile
import traceback
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from sumo_ayss.grid.jobs import NOT_RETRIED, JobSpec, run_job
from sumo_ayss.grid.progress import GridProgress, JobStatus
from sumo_ayss.util.errors import ConfigError

logger = logging.getLogger(__name__)


def pack(folder: Path) -> bytes:
    """A gzipped tar of ``folder``'s contents (empty bytes when it does not exist)."""
    if not folder.is_dir():
        return b""
    buf = io.BytesIO()
    with tarfile.open(fileobj=buf, mode="w:gz") as tar:
        for path in sorted(folder.rglob("*")):
            tar.add(path, arcname=str(path.relative_to(folder)), recursive=False)
    return buf.getvalue()


def unpack(data: bytes, folder: Path) -> None:
    """Replace ``folder`` by the contents of ``data`` (a :func:`pack` result), atomically."""
    tmp = folder.with_name(f".{folder.name}.unpack")
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir(parents=True)
    with tarfile.open(fileobj=io.BytesIO(data), mode="r:gz") as tar:
        tar.extractall(tmp, filter="data")
    old = folder.with_name(f".{folder.name}.old")
    shutil.rmtree(old, ignore_errors=True)
    if folder.exists():
        folder.rename(old)
    tmp.rename(folder)
    shutil.rmtree(old, ignore_errors=True)


def remote_job(spec: JobSpec, folder: bytes) -> tuple[dict[str, Any], bytes]:
    """Body of a Ray task: run the job on a private copy of its run folder."""
    with tempfile.TemporaryDirectory(prefix="sumo_ayss_ray_") as tmp:
        local = dataclasses.replace(spec, out=tmp)
        if folder:
            unpack(folder, local.run_dir)
        result = run_job(local)
        return result, pack(local.run_dir)


def run_grid_ray(
    jobs: Sequence[JobSpec], retries: int, address: str | None, after: str = ""
) -> list[JobStatus]:
    """Run ``jobs`` as Ray tasks (one CPU each), retrying a failed job ``retries`` times.

    Every job event is logged like the local backend's (started, done with its stages and
    times, failed, retried, each line with the grid's counts and ETA,
    :class:`~sumo_ayss.grid.progress.GridProgress`); a task's run folder is remote until it
    ends, so there are no events in between. ``after``: what follows the grid, outside
    the ETA.
    """
    try:
        import ray
    except ImportError as e:  # pragma: no cover - depends on the install
        raise ConfigError(
            "--backend ray needs the optional dependency: pip install 'sumo_ayss[ray]'"
        ) from e
    started_here = not ray.is_initialized()
    if started_here:
        try:
            ray.init(address=address, include_dashboard=False, log_to_driver=False)
        except ConnectionError as e:
            raise ConfigError(
                f"--address {address}: no Ray cluster reachable ({e}). Start one first: "
                "`.venv/bin/ray start --head` on this machine (then `.venv/bin/ray start "
                "--address <head-ip>:6379` on each worker machine), or leave out --address to "
                "run on a Ray instance started just for this pipeline on this machine"
            ) from e
    task = ray.remote(num_cpus=1, max_retries=0)(remote_job)
    statuses = [JobStatus(j) for j in jobs]
    resources = ray.cluster_resources() if hasattr(ray, "cluster_resources") else {}
    progress = GridProgress(statuses, int(resources.get("CPU", 1)), after)
    pending: dict[Any, JobStatus] = {}
    logger.info("%d jobs as Ray tasks (one CPU each)", len(jobs))

    def submit(s: JobStatus) -> None:
        s.start()
        ref = task.remote(s.spec, pack(s.spec.run_dir))
        pending[ref] = s
        logger.info(progress.line(s, f"submitted to Ray (try {s.attempts})"))

    try:
        for s in statuses:
            submit(s)
        while pending:
            ready, _ = ray.wait(list(pending), num_returns=1)
            ref = ready[0]
            s = pending.pop(ref)
            try:
                result, folder = ray.get(ref)
                unpack(folder, s.spec.run_dir)
                logger.info(progress.finished(s, result))
            except Exception as e:  # a job's failure is data here
                s.error = "".join(traceback.format_exception_only(e)).strip()[-2000:]
                cause = getattr(e, "cause", e)  # a RayTaskError wraps the job's exception
                if s.attempts <= retries and not isinstance(cause, NOT_RETRIED):
                    s.state = "queued"
                    logger.warning(progress.line(s, f"failed ({s.error}); will retry"))
                    submit(s)
                else:
                    s.state = "failed"
                    s.spec.run_dir.mkdir(parents=True, exist_ok=True)
                    log = s.spec.folder.job_log
                    log.write_text(s.error + "\n")
                    logger.error(progress.line(s, f"FAILED: {s.error} (log: {log})"))
    finally:
        if started_here:
            ray.shutdown()
    logger.info(progress.summary())
    return statuses
