"""``eval.csv``: one row per SPCP candidate, written by training, read by everyone.

Its schema is :data:`EVAL_SCHEMA` (``step`` and ``n_episodes`` ints, ``checkpoint`` text, the
other columns finite floats but ``std_return``, NaN with one scenario). It is written by
:func:`write_eval_table` and read by the one CSV reader
(:func:`~sumo_ayss.records.table.read_table`), raising
:class:`~sumo_ayss.util.errors.CheckpointError` (a run's own record) naming the file, the
column and the row.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from sumo_ayss.records.table import Column, TableSchema, read_table, write_rows
from sumo_ayss.util.errors import CheckpointError

__all__ = ["EVAL_SCHEMA", "read_eval_table", "write_eval_table"]

EVAL_SCHEMA = TableSchema(
    "eval.csv",
    (
        Column("step", "int", "-", "training transitions when the candidate was stored"),
        Column("mean_return", "float", "-", "mean episode reward over the evaluation scenarios"),
        Column("std_return", "float", "-", "its standard deviation (NaN: one scenario)", True),
        Column("crash_rate", "float", "-", "fraction of episodes with a collision, in [0, 1]"),
        Column("lane_change_rate", "float", "-", "fraction with a POV lane change (cut-in)"),
        Column("mean_final_headway_m", "float", "m", "mean headway after the last step"),
        Column("n_episodes", "int", "-", "evaluation episodes"),
        Column("wall_s", "float", "s", "wall time of the evaluation"),
        Column("checkpoint", "str", "-", "the candidate's model, relative to the run folder"),
    ),
)
"""The columns of ``eval.csv``, in file order."""


def write_eval_table(path: Path, rows: Sequence[dict[str, Any]]) -> None:
    """Write ``rows`` (dicts with exactly :data:`EVAL_SCHEMA`'s columns) as ``eval.csv``."""
    write_rows(path, EVAL_SCHEMA.names, rows)


def read_eval_table(path: Path, *, skip_bad_rows: bool = False) -> list[dict[str, Any]]:
    """The rows of ``eval.csv`` in file order (none if it does not exist).

    Args:
        path: The file; a missing file has no rows.
        skip_bad_rows: Leave out a row with a bad cell instead of raising (the progress
            display shows the rest of a damaged table).

    Raises:
        CheckpointError: The file is unreadable, lacks a column, or (unless
            ``skip_bad_rows``) has a bad cell; the message names the file, column and row.
    """
    if not path.is_file():
        return []
    table = read_table(path, EVAL_SCHEMA, error=CheckpointError, skip_bad_rows=skip_bad_rows)
    return list(table.rows())
