"""The pipeline's local scheduler: jobs on a pool of spawned worker processes, with
retries, progress events, a live table, and a clean stop on Ctrl-C or SIGTERM.

One SUMO per process (libsumo holds one simulation each), so jobs run in separate
interpreters (``spawn``: no inherited libsumo state).
"""

from __future__ import annotations

import collections
import logging
import threading
import time
import traceback
from collections.abc import Sequence
from concurrent.futures import Future
from typing import Any

from sumo_ayss.grid.jobs import NOT_RETRIED, JobSpec, run_job
from sumo_ayss.grid.progress import GridProgress, JobStatus
from sumo_ayss.grid.workers import spawn_pool, stop_workers
from sumo_ayss.util.errors import DiskFullError

logger = logging.getLogger("sumo_ayss.pipeline")


class _Terminated(KeyboardInterrupt):
    """SIGTERM, handled as a Ctrl-C."""


def _raise_terminated(signum: int, frame: Any) -> None:
    raise _Terminated


def run_grid_local(
    jobs: Sequence[JobSpec], workers: int, retries: int, live: Any = None, after: str = ""
) -> list[JobStatus]:
    """Run ``jobs`` on a local process pool with retries; report progress as it goes.

    At most ``workers`` jobs are handed to the pool at a time; the others wait here, so the
    jobs shown as running are the ones a worker holds, and a Ctrl-C (SIGINT) or SIGTERM
    cancels them at once: running jobs are terminated (their state is ``interrupted``,
    resumable), queued ones never start (``cancelled``), and the KeyboardInterrupt
    propagates to the caller within seconds. Every job event is logged (one line each, with
    the grid's counts and ETA); ``live`` (a :class:`rich.console.Console`, or None for
    none) also shows a table of every job that refreshes twice a second. ``after`` names
    what follows the grid outside the ETA (:class:`~sumo_ayss.grid.progress.GridProgress`).
    """
    import signal

    statuses = [JobStatus(j) for j in jobs]
    progress = GridProgress(statuses, workers, after)
    queue: collections.deque[JobStatus] = collections.deque(statuses)
    logger.info(
        "%d jobs on %d worker processes; each job logs to <run folder>/job.log",
        len(jobs),
        workers,
    )
    pool = spawn_pool(workers)
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
                except DiskFullError as e:  # every other job would meet it: stop the grid
                    s.state, s.error = "failed", str(e)
                    logger.error(progress.line(s, f"FAILED: {e}"))
                    raise
                except Exception as e:  # a job's failure is data here
                    s.error = "".join(traceback.format_exception_only(e)).strip()
                    s.stage = ""
                    if s.attempts <= retries and not isinstance(e, NOT_RETRIED):
                        s.state = "queued"
                        queue.appendleft(s)
                        logger.warning(progress.line(s, f"failed ({s.error}); will retry"))
                    else:
                        s.state = "failed"
                        log = s.spec.folder.job_log
                        why = " (not retried: it fails again)" if s.attempts <= retries else ""
                        logger.error(progress.line(s, f"FAILED{why}: {s.error} (log: {log})"))
                    continue
                logger.info(progress.finished(s, result))
            if display is not None:
                display.update(progress.table())
            time.sleep(0.2)
    except (KeyboardInterrupt, DiskFullError) as e:
        for s in queue:
            s.state = "cancelled"
        for fut, s in pending.items():
            fut.cancel()
            s.state = "interrupted"
        stop_workers(pool)
        logger.warning(
            "%s: %d running job(s) stopped, %d queued job(s) cancelled; rerun the "
            "same command to resume",
            "interrupted" if isinstance(e, KeyboardInterrupt) else "the disk is full",
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
    logger.info(progress.summary())
    return statuses


def _live(progress: GridProgress, console: Any) -> Any:
    from rich.live import Live

    live = Live(progress.table(), console=console, refresh_per_second=2, transient=False)
    live.start()
    return live
