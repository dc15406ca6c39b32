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

Only the driver writes into the output folder, so a task lost with its worker or its node
leaves its run folder as it was (the retry starts from it) and a task that still answers
after its retry cannot write twice. A job already finished on the driver is not submitted
again. When the cluster stops answering (its head died) the pipeline stops within seconds
with a :class:`~sumo_ayss.util.errors.ClusterError`; the same command against a new head
resumes from the run folders. The code itself does not travel: every node needs the same
``sumo_ayss`` installed (Ray adds the driver's working directory to the workers' import path
where that directory exists).
"""

from __future__ import annotations

import dataclasses
import io
import logging
import shutil
import socket
import tarfile
import tempfile
import time
import traceback
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from sumo_ayss.grid.jobs import NOT_RETRIED, JobSpec, is_finished, run_job
from sumo_ayss.grid.progress import GridProgress, JobStatus
from sumo_ayss.util.atomic import disk_full_error
from sumo_ayss.util.errors import ClusterError, ConfigError

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
        try:
            tar.extractall(tmp, filter="data")
        except OSError as e:
            shutil.rmtree(tmp, ignore_errors=True)  # the run folder itself is untouched
            needed = sum(m.size for m in tar.getmembers())
            full = disk_full_error(folder, needed, e)  # the folder unpacked
            if full is None:
                raise
            raise full from e
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
        result["node"] = _node_name()
        return result, pack(local.run_dir)


def _node_name() -> str:
    """The Ray node a task runs on: its host name and the first 8 hex of its node id."""
    try:
        import ray

        node = ray.get_runtime_context().get_node_id()[:8]
    except Exception:  # pragma: no cover - outside a Ray task
        node = "?"
    return f"{socket.gethostname()}:{node}"


#: Seconds between two checks that the cluster's head still answers while no job ends.
PROBE_EVERY_S = 2.0
#: Failed checks in a row (one ``PROBE_EVERY_S`` apart) before the head is declared lost.
PROBE_FAILURES = 2


def _gcs_address(ray: Any) -> str | None:
    """The head's GCS address as ``host:port`` (None where Ray does not say, e.g. a client)."""
    try:
        found = ray.get_runtime_context().gcs_address
    except Exception:  # pragma: no cover - depends on how Ray was joined
        return None
    return found if isinstance(found, str) and ":" in found else None


def _head_answers(gcs_address: str) -> bool:
    """Whether the head's GCS port accepts a TCP connection (within 2 s)."""
    host, _, port = gcs_address.rpartition(":")
    try:
        with socket.create_connection((host, int(port)), timeout=2.0):
            return True
    except (OSError, ValueError):
        return False


def _connect(ray: Any, address: str | None) -> None:
    """``ray.init``, with an error that says what to do when the cluster refuses us."""
    try:
        ray.init(address=address, include_dashboard=False, log_to_driver=False)
    except ConnectionError as e:
        raise ClusterError(
            f"--address {address}: no Ray cluster answered ({e}). Start one first "
            "(README, 'The whole grid'): `RAY_AUTH_MODE=token .venv/bin/ray start --head` on the "
            "head, `RAY_AUTH_MODE=token RAY_AUTH_TOKEN=<the head's token> .venv/bin/ray start "
            "--address <head-ip>:6379` on each worker. If the head is running, it may require a "
            "token this process lacks: set RAY_AUTH_MODE=token and the head's token "
            "(~/.ray/auth_token, RAY_AUTH_TOKEN_PATH or RAY_AUTH_TOKEN) here too; Ray never "
            "turns token authentication on by itself for an explicit address. Or leave out "
            "--address to run on a Ray instance started just for this pipeline"
        ) from e
    except Exception as e:  # ray.exceptions.AuthenticationError and its kin
        if type(e).__name__ != "AuthenticationError":
            raise
        raise ClusterError(
            f"--address {address}: the Ray cluster refused this process's authentication "
            f"token ({str(e).split('.')[0]}): set RAY_AUTH_MODE=token and the head's token "
            "(~/.ray/auth_token on the head; here RAY_AUTH_TOKEN=<token> or "
            "RAY_AUTH_TOKEN_PATH=<file>), as every node of the cluster has it"
        ) from e


#: How a job finished before this run is logged (it is never sent to the cluster).
SKIPPED = "already finished, not submitted"


def _skipped(spec: JobSpec) -> dict[str, Any]:
    """The result of a job that is already finished on the driver (nothing sent to Ray)."""
    return {
        "job": spec.name,
        "stages": {"train": "skipped", "evaluate": "skipped"},
        "wall_s": 0.0,
        "train_s": 0.0,
        "evaluate_s": 0.0,
    }


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
        _connect(ray, address)
    task = ray.remote(num_cpus=1, max_retries=0)(remote_job)
    statuses = [JobStatus(j) for j in jobs]
    # ray's own function is untyped: named through a typed callable (mypy --strict).
    cluster_resources: Callable[[], dict[str, float]] | None = getattr(
        ray, "cluster_resources", None
    )
    resources = cluster_resources() if cluster_resources is not None else {}
    progress = GridProgress(statuses, int(resources.get("CPU", 1)), after)
    pending: dict[Any, JobStatus] = {}
    gcs = _gcs_address(ray) if address is not None else None
    logger.info("%d jobs as Ray tasks (one CPU each)", len(jobs))

    def submit(s: JobStatus) -> None:
        s.start()
        try:
            ref = task.remote(s.spec, pack(s.spec.run_dir))
        except OSError as e:
            raise lost(f"{type(e).__name__}: {e}") from e
        pending[ref] = s
        logger.info(progress.line(s, f"submitted to Ray (try {s.attempts})"))

    def lost(why: str) -> ClusterError:
        done = sum(st.state == "done" for st in statuses)
        return ClusterError(
            f"the Ray cluster at {gcs or address} stopped answering ({why}): {done} of "
            f"{len(statuses)} jobs finished and are kept in their run folders, "
            f"{len(pending)} were lost or queued. Start a new head (and its workers) and "
            "rerun the same command: finished jobs are not run again"
        )

    try:
        for s in statuses:
            if is_finished(s.spec):  # a rerun: never sent to the cluster again
                s.start()
                logger.info(progress.finished(s, _skipped(s.spec)) + " on the driver: " + SKIPPED)
            else:
                submit(s)
        failures, probed = 0, time.monotonic()
        while pending:
            try:
                ready, _ = ray.wait(list(pending), num_returns=1, timeout=PROBE_EVERY_S)
            except OSError as e:  # the driver's own raylet went with the head
                raise lost(f"{type(e).__name__}: {e}") from e
            if not ready:
                if gcs is not None and time.monotonic() - probed >= PROBE_EVERY_S:
                    probed = time.monotonic()
                    failures = 0 if _head_answers(gcs) else failures + 1
                    if failures >= PROBE_FAILURES:
                        raise lost(f"its head {gcs} refused {failures} connections in a row")
                continue
            ref = ready[0]
            s = pending.pop(ref)
            try:
                result, folder = ray.get(ref)
            except OSError as e:  # the driver lost its cluster, not the job its worker
                pending[ref] = s
                raise lost(f"{type(e).__name__}: {e}") from e
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
            else:
                unpack(folder, s.spec.run_dir)  # only the driver writes the output folder
                node = f" on {result['node']}" if "node" in result else ""
                logger.info(progress.finished(s, result) + node)
    finally:
        if started_here:
            ray.shutdown()
    logger.info(progress.summary())
    return statuses
