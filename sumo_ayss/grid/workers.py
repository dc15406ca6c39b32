"""Worker processes of the local pools: the grid's jobs (:mod:`.local`) and cross-play's
cells (:mod:`.cells`).

One SUMO per process (libsumo holds one simulation each), so work runs in separate
interpreters, ``spawn``ed: no inherited libsumo state.
"""

from __future__ import annotations

import multiprocessing
import sys
import time
from concurrent.futures import ProcessPoolExecutor

__all__ = ["spawn_pool", "stop_workers", "worker_init"]


def spawn_pool(workers: int) -> ProcessPoolExecutor:
    """A pool of ``workers`` spawned processes (started as work arrives), each set up by
    :func:`worker_init`."""
    ctx = multiprocessing.get_context("spawn")  # fresh interpreters: no inherited libsumo
    return ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=worker_init)


def worker_init() -> None:
    """Worker initializer: die with the pipeline, and leave Ctrl-C to it.

    On Linux a worker gets SIGKILLed when the pipeline process dies: without it a killed
    pipeline leaves its workers running, and a rerun would race them for the same run
    folders. A Ctrl-C reaches every process of the terminal's group; workers ignore it and
    the pipeline stops them (:func:`stop_workers`), so that no job starts afterwards.
    It also runs before any job imports torch, so that torch's intra-op pool starts with one
    BLAS/OpenMP thread (``run_job`` then applies ``train.torch_threads``).
    """
    import signal

    from sumo_ayss.grid.threads import single_thread_env

    single_thread_env()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if sys.platform.startswith("linux"):
        import ctypes

        libc = ctypes.CDLL("libc.so.6", use_errno=True)
        pr_set_pdeathsig = 1
        libc.prctl(pr_set_pdeathsig, signal.SIGKILL)


def stop_workers(pool: ProcessPoolExecutor, grace_s: float = 3.0) -> None:
    """Terminate the pool's worker processes now (SIGTERM, then SIGKILL after ``grace_s``).

    Safe for the run folders: every result is written atomically and a rerun resumes from
    the last checkpoint (:func:`sumo_ayss.training.trainer.train`) or the last cross-play
    cell recorded (:class:`~sumo_ayss.run_folder.CellStore`).
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
