"""Cross-play's cells on the local worker pool (issue 40).

Every (VUT, opponent) cell of a cross-play table is its own fresh simulation (SUMO seed = the
opponent's training seed, :func:`sumo_ayss.scenarios.crossplay.drive_cell`), so the cells can
run in any order on any process and give the same rows. :class:`CellPool` hands them to
``workers`` spawned processes (:mod:`.workers`, as the grid's jobs), one cell per task: a
task carries the VUT's env config and the opponent's ``spcp.zip`` path and learner settings,
and comes back with the cell's 200-odd rows; the worker loads the opponent for the cell
(12 ms) and drops it after, so it holds one SPCP at a time. The caller
(:func:`~sumo_ayss.scenarios.crossplay.run_crossplay`) records each cell as it comes back
(only the parent writes the cell store), prints its progress line and assembles the table in
grid order: byte-identical to the one-process table.

One pool serves every table of a stage (main and reference-driver tables, every case): its
processes start with the first cell and stay until the pool is closed. On an error or a
Ctrl-C the workers are stopped at once; the cells already recorded are kept for the rerun.
"""

from __future__ import annotations

import logging
from collections.abc import Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager
from types import TracebackType

from sumo_ayss.grid.workers import spawn_pool, stop_workers
from sumo_ayss.scenarios.crossplay import CellDone, CellTask, drive_cell
from sumo_ayss.util.errors import SimulationError

__all__ = ["CellPool", "cell_pool"]

logger = logging.getLogger(__name__)


class CellPool:
    """Cross-play cells on ``workers`` worker processes (a
    :class:`~sumo_ayss.scenarios.crossplay.CellRunner`); a context manager.

    Args:
        workers: Processes, >= 1 (started as cells arrive, at most one per cell).
    """

    def __init__(self, workers: int) -> None:
        if workers < 1:
            raise ValueError(f"workers: expected >= 1, got {workers}")
        self.workers = workers
        self._pool: ProcessPoolExecutor | None = None

    def drive(self, tasks: Sequence[CellTask]) -> Iterator[CellDone]:
        """Drive ``tasks`` on the workers, yielding ``(index, rows, seconds)`` as each cell
        comes back (any order).

        Raises:
            AyssError: A cell's error, of its type, its message naming the cell.
            SimulationError: If a worker process died (killed, out of memory), naming a cell
                it may have held.
        """
        if not tasks:
            return
        if self._pool is None:
            self._pool = spawn_pool(self.workers)
            logger.info("cross-play: cells on %d worker processes", self.workers)
        pending: dict[Future[tuple[list[dict[str, object]], float]], int] = {
            self._pool.submit(drive_cell, task): i for i, task in enumerate(tasks)
        }
        try:
            while pending:
                done, _ = wait(pending, return_when=FIRST_COMPLETED)
                for fut in sorted(done, key=pending.__getitem__):  # grid order within a batch
                    i = pending.pop(fut)
                    try:
                        rows, seconds = fut.result()
                    except BrokenProcessPool as e:
                        raise SimulationError(
                            f"cross-play cell {tasks[i].name}: a worker process died ({e}); "
                            "the cells finished before are kept: rerun to resume"
                        ) from e
                    yield i, rows, seconds
        finally:
            for fut in pending:
                fut.cancel()

    def close(self, *, stop: bool = False) -> None:
        """Shut the workers down (``stop``: at once, a cell in progress is lost)."""
        if self._pool is None:
            return
        if stop:
            stop_workers(self._pool)
        else:
            self._pool.shutdown(wait=True, cancel_futures=True)
        self._pool = None

    def __enter__(self) -> CellPool:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close(stop=exc_type is not None)


@contextmanager
def cell_pool(workers: int) -> Iterator[CellPool | None]:
    """The pool for ``workers`` processes, closed on leaving; None for one (the cells run in
    the caller's process, one after the other: no pool, for debugging and tests)."""
    if workers <= 1:
        yield None
        return
    with CellPool(workers) as pool:
        yield pool
