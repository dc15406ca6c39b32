"""One writer per output folder: a lock file holding the writer's PID.

Two pipelines on one output folder would both run every job (twice the CPU) and race on the
same files. :func:`output_lock` creates ``<out>/pipeline.lock`` atomically
(``O_CREAT | O_EXCL``) with the PID of the process that holds it, refuses a second writer
with a :class:`~sumo_ayss.util.errors.LockError` naming the holder's PID, and removes the file
when the block ends: normally, on an exception, on Ctrl-C (SIGINT) and on SIGTERM (handled
as a Ctrl-C while the lock is held in the main thread).

A lock whose PID no longer runs (a pipeline killed with SIGKILL, a crashed machine) is
stale: the next writer takes it over and logs so. Takeovers are serialised by a second,
short-lived file (``pipeline.lock.takeover``) so that two writers finding the same stale lock
cannot both win. The PID is only meaningful on this machine: do not share an output folder
between machines (e.g. over NFS) while a pipeline writes it.
"""

from __future__ import annotations

import contextlib
import logging
import os
import signal
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from sumo_ayss.util.errors import LockError

__all__ = ["LOCK_NAME", "output_lock"]

logger = logging.getLogger(__name__)

#: The lock file's name in the output folder.
LOCK_NAME = "pipeline.lock"
#: A lock file still empty after this long [s] was left by a writer killed between
#: creating it and writing its PID: stale.
_EMPTY_GRACE_S = 2.0
#: A takeover guard older than this [s] was left by a writer killed during its takeover.
_GUARD_STALE_S = 10.0


def pid_alive(pid: int) -> bool:
    """Whether process ``pid`` runs on this machine (a zombie, dead but not yet reaped by
    its parent, does not count)."""
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    with contextlib.suppress(OSError, IndexError):
        stat = Path(f"/proc/{pid}/stat").read_text()
        return stat.rpartition(")")[2].split()[0] != "Z"
    return True


def _read(path: Path) -> str | None:
    """The lock file's text, or None when it is gone."""
    try:
        return path.read_text(encoding="utf-8", errors="replace")
    except FileNotFoundError:
        return None


def _holder(text: str) -> int | None:
    """The PID a lock file's text names, or None (empty or not a PID)."""
    first = text.strip().split("\n", 1)[0].strip()
    return int(first) if first.isdigit() else None


def _take_over(path: Path, seen: str) -> None:
    """Remove the stale lock ``path`` if it still holds ``seen``, under the takeover guard
    (another writer taking it over at the same time waits for the guard instead)."""
    guard = path.with_name(path.name + ".takeover")
    try:
        fd = os.open(guard, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
    except FileExistsError:
        with contextlib.suppress(FileNotFoundError):
            if time.time() - guard.stat().st_mtime > _GUARD_STALE_S:
                guard.unlink()
        time.sleep(0.05)
        return
    try:
        if _read(path) == seen:
            pid = _holder(seen)
            logger.warning(
                "taking over the stale lock %s (%s no longer runs)",
                path,
                f"PID {pid}" if pid is not None else "its writer",
            )
            path.unlink()
    finally:
        os.close(fd)
        guard.unlink()


def _acquire(path: Path, timeout_s: float = 30.0) -> None:
    """Create ``path`` holding this process's PID, or raise :class:`LockError`."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        try:
            fd = os.open(path, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
        except FileExistsError:
            text = _read(path)
            if text is None:  # released meanwhile
                continue
            pid = _holder(text)
            if pid is not None and pid != os.getpid() and pid_alive(pid):
                raise LockError(
                    f"{path.parent}: another pipeline (PID {pid}) is writing this output "
                    f"folder (lock file {path}); wait for it to end, stop it (kill {pid}), "
                    "or give another --out"
                ) from None
            if pid is None and time.time() - _mtime(path) < _EMPTY_GRACE_S:
                time.sleep(0.02)  # its writer is writing the PID now
                continue
            _take_over(path, text)
            continue
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(f"{os.getpid()}\n")
        return
    raise LockError(f"{path.parent}: could not take the lock file {path} in {timeout_s:g} s")


def _mtime(path: Path) -> float:
    try:
        return path.stat().st_mtime
    except FileNotFoundError:
        return 0.0


def _release(path: Path) -> None:
    """Remove ``path`` if it still holds this process's PID."""
    text = _read(path)
    if text is not None and _holder(text) == os.getpid():
        path.unlink(missing_ok=True)


class _Terminated(KeyboardInterrupt):
    """SIGTERM while the lock is held, handled as a Ctrl-C."""


def _raise_terminated(signum: int, frame: Any) -> None:
    raise _Terminated


@contextlib.contextmanager
def output_lock(folder: Path) -> Iterator[Path]:
    """Hold ``<folder>/pipeline.lock`` for the block (the folder is created if needed).

    In the main thread, SIGTERM raises a KeyboardInterrupt while the lock is held, so that
    the lock is released on the way out; the previous handler is restored afterwards.

    Args:
        folder: The output folder.

    Yields:
        The lock file's path.

    Raises:
        LockError: Another live process holds the lock (the message names its PID), or the
            lock file cannot be created.
    """
    path = (Path(folder) / LOCK_NAME).resolve()
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        _acquire(path)
    except OSError as e:
        raise LockError(f"{path.parent}: cannot create the lock file {path} ({e})") from None
    in_main = threading.current_thread() is threading.main_thread()
    previous = signal.getsignal(signal.SIGTERM) if in_main else None
    try:
        if in_main and previous in (signal.SIG_DFL, None):
            signal.signal(signal.SIGTERM, _raise_terminated)
        yield path
    finally:
        if in_main and previous in (signal.SIG_DFL, None):
            signal.signal(signal.SIGTERM, signal.SIG_DFL)
        _release(path)
