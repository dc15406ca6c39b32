"""``eval.csv``: one row per SPCP candidate, written by training, read by everyone.

Columns (:data:`EVAL_COLUMNS`, in file order):

==========================  ======================================================================
``step``                    training transitions when the candidate was stored (int)
``mean_return``             mean undiscounted episode reward over the evaluation scenarios
``std_return``              its standard deviation (NaN with one scenario)
``crash_rate``              fraction of evaluation episodes with a collision, in [0, 1]
``lane_change_rate``        fraction with a POV lane change (cut-in; 0 in car-following)
``mean_final_headway_m``    mean headway after the last step, m
``n_episodes``              evaluation episodes (int)
``wall_s``                  wall time of the evaluation, s
``checkpoint``              the candidate's model, relative to the run folder
==========================  ======================================================================

:func:`write_eval_table` is the one writer (atomic, whole file), :func:`read_eval_table` the
one reader.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from sumo_ayss.util.atomic import atomic_write_text
from sumo_ayss.util.errors import CheckpointError

__all__ = ["EVAL_COLUMNS", "read_eval_rows", "read_eval_table", "write_eval_table"]

EVAL_COLUMNS: tuple[str, ...] = (
    "step",
    "mean_return",
    "std_return",
    "crash_rate",
    "lane_change_rate",
    "mean_final_headway_m",
    "n_episodes",
    "wall_s",
    "checkpoint",
)
"""The columns of ``eval.csv``, in file order."""

_INT_COLUMNS = ("step", "n_episodes")
_MAY_BE_NAN = ("std_return",)


def write_eval_table(path: Path, rows: Sequence[dict[str, Any]]) -> None:
    """Write ``rows`` (dicts with exactly :data:`EVAL_COLUMNS`) as ``eval.csv``, atomically."""
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=list(EVAL_COLUMNS), lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    atomic_write_text(path, buf.getvalue())


def read_eval_table(path: Path) -> list[dict[str, Any]]:
    """The rows of ``eval.csv`` in file order (none if it does not exist).

    ``step`` and ``n_episodes`` are ints, ``checkpoint`` text, the other columns floats;
    every number is finite except ``std_return``.

    Raises:
        CheckpointError: The file is unreadable, lacks a column, or has a bad cell; the
            message names the file, the line and the column.
    """
    return read_eval_rows(path)[0]


def read_eval_rows(path: Path, *, skip_bad_rows: bool = False) -> tuple[list[dict[str, Any]], int]:
    """Parse ``eval.csv``: the rows (as :func:`read_eval_table`) and how many were skipped.

    Args:
        path: The file; a missing file has no rows.
        skip_bad_rows: Skip a row with a bad cell (and count it) instead of raising; the
            report shows the rest of a damaged table.

    Raises:
        CheckpointError: The file is unreadable or lacks a column; with ``skip_bad_rows``
            false also for a bad cell (naming the file, the line and the column).
    """
    if not path.is_file():
        return [], 0
    try:
        with path.open(encoding="utf-8", newline="") as f:
            reader = csv.DictReader(f)
            missing = [c for c in EVAL_COLUMNS if c not in (reader.fieldnames or [])]
            if missing:
                raise CheckpointError(f"{path}: not an eval table (missing columns {missing})")
            rows = list(reader)
    except (OSError, UnicodeDecodeError, csv.Error) as e:
        raise CheckpointError(f"{path}: unreadable ({e})") from e
    out: list[dict[str, Any]] = []
    for line, row in enumerate(rows, start=2):
        try:
            out.append(_parse_row(row, f"{path}, line {line}"))
        except CheckpointError:
            if not skip_bad_rows:
                raise
    return out, len(rows) - len(out)


def _parse_row(row: dict[str, Any], where: str) -> dict[str, Any]:
    for key in EVAL_COLUMNS:
        if key == "checkpoint":
            continue
        cell = row[key]
        try:
            value = int(cell) if key in _INT_COLUMNS else float(cell)
        except (TypeError, ValueError):
            raise CheckpointError(
                f"{where}: column {key!r} must be a number, got {cell!r}"
            ) from None
        if key not in _MAY_BE_NAN and not math.isfinite(value):
            raise CheckpointError(f"{where}: column {key!r} must be finite, got {cell!r}")
        row[key] = value
    return row
