"""Small CSV files of named columns (a study's ranking and measures, a case's
discriminability shares): written atomically, read back as written.

The episode tables (``outcome.csv``, ``ayss.csv``, ``crossplay.csv``) have typed schemas
(:mod:`.table`); these files are read cell by cell as strings, so that a script that
writes one back keeps every digit.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from sumo_ayss.util.atomic import atomic_write_text
from sumo_ayss.util.errors import TableError

__all__ = ["read_csv_rows", "write_csv_rows"]


def write_csv_rows(path: Path, columns: Sequence[str], rows: Sequence[Mapping[str, Any]]) -> None:
    """Write ``rows`` under the header ``columns`` (a missing cell is written empty).

    Raises:
        ValueError: A row holds a column the file does not have.
    """
    unknown = sorted({k for r in rows for k in r} - set(columns))
    if unknown:
        raise ValueError(f"{path.name}: rows hold columns it does not have: {unknown}")
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=list(columns), lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    atomic_write_text(path, buf.getvalue())


def read_csv_rows(
    path: Path, columns: Sequence[str], optional: Sequence[str] = ()
) -> list[dict[str, str]]:
    """The rows of ``path`` as ``{column: cell}`` for ``columns``, cells as written.

    Args:
        path: The file.
        columns: The columns returned, in order.
        optional: Those of ``columns`` a file may lack (written before they existed): their
            cells are then "".

    Raises:
        TableError: The file is missing or unreadable, lacks a column that is not
            optional, or has a row with too few or too many cells (naming the file and the
            line).
    """
    try:
        with path.open(encoding="utf-8", newline="") as f:
            reader = csv.DictReader(f)
            header = reader.fieldnames or []
            missing = [c for c in columns if c not in header and c not in optional]
            if missing:
                raise TableError(f"{path}: missing columns {missing}")
            rows = list(reader)
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        raise TableError(f"{path}: unreadable ({exc})") from exc
    for line, row in enumerate(rows, start=2):
        if None in row or any(row[c] is None for c in header):
            raise TableError(f"{path}, line {line}: expected {len(header)} cells")
    return [{c: row.get(c, "") for c in columns} for row in rows]
