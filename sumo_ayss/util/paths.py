"""Paths written into result files: relative to the repository, never the machine's layout.

Committed results (``results/``) are read on other machines; an absolute path such as
``/home/me/sumo_ayss/runs/...`` in them is noise at best and a leak at worst.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

from sumo_ayss.config import PROJECT_ROOT


def portable_path(path: str | Path, base: str | Path = PROJECT_ROOT) -> str:
    """``path`` relative to ``base`` (default the repository root) when it lies below it,
    else as given (unresolved), in POSIX form."""
    p = Path(path)
    try:
        return p.resolve().relative_to(Path(base).resolve()).as_posix()
    except ValueError:
        return p.as_posix()


def display_path(path: str | Path, base: str | Path) -> str:
    """``path`` relative to ``base`` (a report folder, the working directory), even where it
    lies beside it (``../``), in POSIX form: what reports and messages show of a path."""
    return Path(os.path.relpath(Path(path).resolve(), Path(base).resolve())).as_posix()


def portable_python() -> str:
    """The running interpreter for ``command.txt``: ``.venv/bin/python`` when it is the
    repository's virtual environment, else plain ``python``."""
    exe = Path(os.path.abspath(sys.executable))  # not resolved: a venv's python is a link
    try:
        return exe.relative_to(PROJECT_ROOT.resolve()).as_posix()
    except ValueError:
        return "python"
