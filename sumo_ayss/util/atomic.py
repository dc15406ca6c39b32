"""Atomic, durable file writes: a temporary file in the same folder, fsync, ``os.replace``,
fsync of the folder.

A reader (or a resumed run after a kill) sees either the old file or the new one, never
half of one; after the function returns, the new file survives a power loss too (its data
and the rename are on disk). Every result file of sumo_ayss is written through these helpers.

Temporary files are named ``.<name>.<pid>.tmp``; :func:`remove_stale_temporaries` deletes
the ones a killed process left behind.
"""

from __future__ import annotations

import errno
import json
import os
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

from sumo_ayss.util.errors import DiskFullError

#: Suffix of every temporary file written here (``.<name>.<pid>.tmp``).
TMP_SUFFIX = ".tmp"


def fsync_dir(folder: str | Path) -> None:
    """Make a rename or a new entry in ``folder`` durable (no-op where folders cannot be opened)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:  # pragma: no cover - e.g. Windows
        return
    try:
        os.fsync(fd)
    except OSError:  # pragma: no cover - some file systems refuse fsync on folders
        pass
    finally:
        os.close(fd)


#: Errors of a file system without room: no space left, quota exceeded.
FULL_ERRNOS = frozenset({errno.ENOSPC, errno.EDQUOT})
#: A writer that hides the errno (``torch.save`` raises a ``RuntimeError``) counts as having
#: met a full disk when less than this is free after it failed, bytes.
NEARLY_FULL_B = 1 << 20


def free_bytes(folder: str | Path) -> int | None:
    """Bytes free to this user on ``folder``'s file system (None when it cannot be asked)."""
    try:
        st = os.statvfs(folder)
    except OSError:
        return None
    return st.f_bavail * st.f_frsize


def disk_full_error(
    path: Path, needed: int | None, cause: BaseException, written: int = 0
) -> DiskFullError | None:
    """The :class:`DiskFullError` for a failed write of ``path``, or None when ``cause`` is
    not a full file system. ``needed``: the file's size in bytes, None when unknown (then
    ``written``, the bytes on disk when it failed, is named as a lower bound)."""
    full = isinstance(cause, OSError) and cause.errno in FULL_ERRNOS
    free = free_bytes(path.parent)
    if not full and not (free is not None and free < NEARLY_FULL_B):
        return None
    if needed is not None:
        size = f"{needed:,} bytes"
    else:
        size = f"more than {written:,} bytes" if written else "an unknown number of bytes"
    return DiskFullError(
        f"no space left on the file system of {path}: the file needs {size} and "
        f"{'?' if free is None else f'{free:,}'} bytes are free there ({cause}). Every file "
        "written before is complete; free some space (or move the output folder) and rerun "
        "the same command to continue"
    )


def _measured_size(write: Callable[[Path], object], suffix: str) -> int | None:
    """The size of what ``write`` writes, written once more into the system's temporary
    folder (another file system, often); None when that fails too."""
    import tempfile

    try:
        with tempfile.TemporaryDirectory(prefix="sumo_ayss_size_") as folder:
            probe = Path(folder) / f"probe{suffix}"
            write(probe)
            return probe.stat().st_size
    except Exception:
        return None


def _tmp_path(path: Path) -> Path:
    return path.with_name(f".{path.name}.{os.getpid()}{TMP_SUFFIX}")


def atomic_write_with(path: str | Path, write: Callable[[Path], object]) -> None:
    """Let ``write(tmp)`` create a temporary file, then fsync it and rename it to ``path``
    (what ``write`` returns is ignored).

    For writers that need a path (SB3's ``save``, matplotlib's ``savefig``, ``torch.save``).
    The temporary file keeps ``path``'s suffix (some writers choose the format by it).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.stem}.{os.getpid()}{TMP_SUFFIX}{path.suffix}")
    try:
        write(tmp)
        with open(tmp, "rb+") as f:
            os.fsync(f.fileno())
        os.replace(tmp, path)
        fsync_dir(path.parent)
    except Exception as e:
        written = tmp.stat().st_size if tmp.is_file() else 0
        tmp.unlink(missing_ok=True)  # its room counts as free in the message
        full = disk_full_error(path, None, e, written)
        if full is not None:
            needed = _measured_size(write, path.suffix)
            raise (full if needed is None else disk_full_error(path, needed, e)) or full from e
        raise
    finally:
        tmp.unlink(missing_ok=True)


def atomic_write_bytes(path: str | Path, data: bytes) -> None:
    """Write ``data`` to ``path`` durably through a temporary file in the same folder + rename."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = _tmp_path(path)
    try:
        with open(tmp, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
        fsync_dir(path.parent)
    except OSError as e:
        tmp.unlink(missing_ok=True)  # its room counts as free in the message
        full = disk_full_error(path, len(data), e)
        if full is not None:
            raise full from e
        raise
    finally:
        tmp.unlink(missing_ok=True)


def atomic_write_text(path: str | Path, text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically and durably."""
    atomic_write_bytes(path, text.encode("utf-8"))


def atomic_write_json(path: str | Path, data: Any) -> None:
    """Indented, key-sorted JSON, written atomically."""
    atomic_write_text(path, json.dumps(data, indent=2, sort_keys=True) + "\n")


def atomic_copy(src: str | Path, dst: str | Path) -> None:
    """Copy ``src`` to ``dst`` atomically and durably."""
    atomic_write_with(dst, lambda tmp: shutil.copyfile(src, tmp))


def remove_stale_temporaries(folder: str | Path, recursive: bool = True) -> list[Path]:
    """Delete temporary files (``.*.tmp``, ``.*.tmp.*``) left in ``folder`` by a killed writer.

    Call it only where no other process writes into ``folder`` at the same time (a run folder
    at the start of its run). Returns the removed paths.
    """
    folder = Path(folder)
    if not folder.is_dir():
        return []
    pattern = "**/.*" if recursive else ".*"
    removed = []
    for path in folder.glob(pattern):
        name = path.name
        if path.is_file() and (name.endswith(TMP_SUFFIX) or f"{TMP_SUFFIX}." in name):
            path.unlink(missing_ok=True)
            removed.append(path)
    return removed
