"""Schema'd CSV tables: typed columns, an exact on-disk encoding, one writer, one reader.

Every column has a name, a dtype, a unit and a meaning (:class:`Column`);
:func:`schema_markdown` prints them as a Markdown table for the docs. Encoding on disk
(stdlib :mod:`csv`, no pandas; a person can open the file in any spreadsheet):

* ``float``: Python's ``repr`` of the float64 value (shortest text that reads back to the
  same number), ``inf`` / ``-inf`` / ``nan`` for non-finite values. A column accepts NaN only
  when ``nullable`` (an empty cell then also reads as NaN) and ±inf only when ``allow_inf``.
* ``int``: decimal integer. ``bool``: ``0`` / ``1`` (``true`` / ``false`` accepted on read).
* ``str``: the text; ``choices`` restricts it to a set (fixed, or a function's current
  answer: the ``ayss.csv`` indicator names follow the case registry). A table of ``str``
  columns (:func:`text_schema`: ``ranking.csv``, ``measures.csv``) reads every cell as
  written, so a script that writes one back keeps every digit.

:func:`write_table` writes atomically (temporary file in the same folder, then
:func:`os.replace`), so a reader never sees half a table; :func:`write_rows` writes rows of
Python values under a header (the study files, ``eval.csv``, ``discriminability.csv``).
:func:`read_table` is the one CSV reader of the package: it checks the header (missing and
extra columns), every cell's dtype, NaN / inf where they are not allowed, and the choices,
and raises a :class:`~sumo_ayss.util.errors.StoredFileError` (:class:`TableError` unless the
caller names another, e.g. ``eval.csv``'s :class:`CheckpointError`) naming the file, column
and row.

Nothing here knows a file: the schemas of the run folder's tables are in
:mod:`sumo_ayss.run_folder.schemas` (and ``eval.csv``'s in
:mod:`sumo_ayss.run_folder.eval_table`, the study files' in :mod:`sumo_ayss.run_folder.study`).
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from sumo_ayss.util.atomic import atomic_write_text
from sumo_ayss.util.errors import StoredFileError, TableError

__all__ = [
    "Column",
    "Table",
    "TableSchema",
    "read_table",
    "schema_markdown",
    "table_from_rows",
    "text_schema",
    "write_rows",
    "write_table",
]

Dtype = Literal["int", "float", "bool", "str"]

_NUMPY_DTYPE: dict[str, type] = {"int": np.int64, "float": np.float64, "bool": np.bool_}
_TRUE = frozenset({"1", "true", "True", "TRUE"})
_FALSE = frozenset({"0", "false", "False", "FALSE"})


# --------------------------------------------------------------------------- schemas


@dataclass(frozen=True)
class Column:
    """One column of a table.

    Attributes:
        name: Header text, unique in its table.
        dtype: ``"int"``, ``"float"``, ``"bool"`` or ``"str"``.
        unit: Physical unit (``"m"``, ``"m/s"``, ``"m/s²"``, ``"s"``) or ``"-"``.
        meaning: What the value is, with its sign convention.
        nullable: NaN allowed (float columns only).
        allow_inf: ±inf allowed (float columns only).
        choices: Allowed values of a ``str`` column, or a function returning them (asked at
            each check); ``None`` = any text.
        since: A column added after files were written (a ``nullable`` float or a ``str``
            column): a file without it reads as all-NaN, or all empty text (the writer's
            version predates it, and the reader says "not recorded"); one *with* it is
            checked like any other column.
    """

    name: str
    dtype: Dtype
    unit: str
    meaning: str
    nullable: bool = False
    allow_inf: bool = False
    choices: tuple[str, ...] | Callable[[], tuple[str, ...]] | None = None
    since: bool = False

    def __post_init__(self) -> None:
        if self.since and not ((self.dtype == "float" and self.nullable) or self.dtype == "str"):
            raise ValueError(f"column {self.name}: 'since' needs a nullable float or str column")

    def missing(self, n: int) -> npt.NDArray[Any]:
        """The column of a table written before it existed: NaN, or empty text."""
        return np.full(n, "", dtype=str) if self.dtype == "str" else np.full(n, math.nan)

    def allowed(self) -> tuple[str, ...] | None:
        """The allowed values now (:attr:`choices`, called when it is a function)."""
        return self.choices() if callable(self.choices) else self.choices


@dataclass(frozen=True)
class TableSchema:
    """An ordered set of columns with a name (used in error messages and docs)."""

    name: str
    columns: tuple[Column, ...]
    by_name: Mapping[str, Column] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        names = [c.name for c in self.columns]
        if len(set(names)) != len(names):
            raise ValueError(f"schema {self.name}: duplicate column names in {names}")
        object.__setattr__(self, "by_name", {c.name: c for c in self.columns})

    @property
    def names(self) -> list[str]:
        """Column names in file order."""
        return [c.name for c in self.columns]


def text_schema(name: str, columns: Sequence[str], added: Sequence[str] = ()) -> TableSchema:
    """A schema of ``str`` columns (cells read as written); ``added`` are the columns a file
    written before them lacks (read as empty)."""
    return TableSchema(name, tuple(Column(c, "str", "-", c, since=c in added) for c in columns))


def schema_markdown(schema: TableSchema) -> str:
    """The schema as a Markdown table: column, dtype, unit, meaning."""
    lines = ["| column | dtype | unit | meaning |", "|---|---|---|---|"]
    for c in schema.columns:
        extra = []
        if c.nullable:
            extra.append("NaN allowed")
        if c.allow_inf:
            extra.append("inf allowed")
        if c.allowed():
            extra.append("one of " + ", ".join(f"`{v}`" for v in c.allowed() or ()))
        note = f" ({'; '.join(extra)})" if extra else ""
        lines.append(f"| `{c.name}` | {c.dtype} | {c.unit} | {c.meaning}{note} |")
    return "\n".join(lines) + "\n"


# --------------------------------------------------------------------------- table object


@dataclass(frozen=True)
class Table:
    """A validated, column-oriented table: one 1-D numpy array per schema column.

    Attributes:
        schema: The schema the columns follow.
        columns: ``name -> array``, all the same length. Any array-like is accepted and
            stored as a numpy array of the column's dtype (int64, float64, bool or str).
        n_dropped: Rows of the file left out because a cell was bad (a
            :func:`read_table` with ``skip_bad_rows``; else 0).
    """

    schema: TableSchema
    columns: Mapping[str, Any]
    n_dropped: int = 0

    def __post_init__(self) -> None:
        object.__setattr__(self, "columns", _coerce_columns(self.schema, self.columns))

    def __len__(self) -> int:
        return len(next(iter(self.columns.values()))) if self.columns else 0

    def __getitem__(self, name: str) -> npt.NDArray[Any]:
        column: npt.NDArray[Any] = self.columns[name]
        return column

    def rows(self) -> Iterator[dict[str, Any]]:
        """Rows as dicts of Python scalars, in order."""
        lists = {name: arr.tolist() for name, arr in self.columns.items()}
        for i in range(len(self)):
            yield {name: lists[name][i] for name in self.schema.names}

    def equals(self, other: Table) -> bool:
        """Same schema and identical values (NaN equal to NaN)."""
        if self.schema != other.schema or len(self) != len(other):
            return False
        for name in self.schema.names:
            a, b = self.columns[name], other.columns[name]
            if a.dtype.kind == "f":
                if not np.array_equal(a, b, equal_nan=True):
                    return False
            elif not np.array_equal(a, b):
                return False
        return True


def table_from_rows(schema: TableSchema, rows: Sequence[Mapping[str, Any]]) -> Table:
    """Build a :class:`Table` from row dicts holding exactly the schema's columns (a column
    marked ``since`` may be left out: NaN, not recorded)."""
    late = [c.name for c in schema.columns if c.since]
    for i, row in enumerate(rows):
        _check_names(schema, [*row, *(n for n in late if n not in row)], f"{schema.name} row {i}")
    return Table(
        schema,
        {
            c.name: [row.get(c.name, "" if c.dtype == "str" else math.nan) for row in rows]
            for c in schema.columns
        },
    )


def _check_names(
    schema: TableSchema, names: Sequence[str], where: str, error: type[StoredFileError] = TableError
) -> None:
    missing = [n for n in schema.names if n not in names]
    extra = [n for n in names if n not in schema.by_name]
    if missing or extra:
        parts = []
        if missing:
            parts.append(f"missing column(s) {missing}")
        if extra:
            parts.append(f"unexpected column(s) {extra}")
        raise error(f"{where}: {'; '.join(parts)} (schema {schema.name}: {schema.names})")


def _coerce_columns(schema: TableSchema, columns: Mapping[str, Any]) -> dict[str, npt.NDArray[Any]]:
    """Arrays of the schema's dtypes, checked for length, NaN, inf and choices; a column
    marked ``since`` that is left out is NaN throughout (not recorded), as in a file."""
    late = [c for c in schema.columns if c.since and c.name not in columns]
    if late and columns:
        n = len(next(iter(columns.values())))
        columns = {**columns, **{c.name: c.missing(n) for c in late}}
    _check_names(schema, list(columns), f"table {schema.name}")
    out: dict[str, npt.NDArray[Any]] = {}
    for col in schema.columns:
        arr = _coerce_column(col, columns[col.name], schema.name)
        _check_values(col, arr, f"table {schema.name}")
        out[col.name] = arr
    lengths = {name: len(arr) for name, arr in out.items()}
    if len(set(lengths.values())) > 1:
        raise TableError(f"table {schema.name}: columns differ in length: {lengths}")
    return out


def _coerce_column(col: Column, values: Any, table: str) -> npt.NDArray[Any]:
    where = f"table {table}, column {col.name!r}"
    arr = np.asarray(values)
    if arr.ndim != 1:
        raise TableError(f"{where}: expected a 1-D sequence, got shape {arr.shape}")
    if col.dtype == "str":
        if arr.size and arr.dtype.kind not in "UO":
            raise TableError(f"{where}: expected text, got dtype {arr.dtype}")
        return arr.astype(str)
    kinds = {"int": "iub", "bool": "biu", "float": "fiu"}[col.dtype]
    if arr.size and arr.dtype.kind not in kinds:
        raise TableError(f"{where}: expected {col.dtype} values, got dtype {arr.dtype}")
    if (
        col.dtype == "bool"
        and arr.size
        and arr.dtype.kind in "iu"
        and not np.isin(arr, (0, 1)).all()
    ):
        raise TableError(f"{where}: expected 0/1 booleans")
    if col.dtype == "int" and arr.dtype.kind == "b":
        arr = arr.astype(np.int64)
    return arr.astype(_NUMPY_DTYPE[col.dtype])


def _check_values(
    col: Column, arr: npt.NDArray[Any], where: str, error: type[StoredFileError] = TableError
) -> None:
    """NaN / inf / choices rules of ``col`` on the already typed ``arr``."""
    if col.dtype == "float":
        bad_nan = np.flatnonzero(np.isnan(arr)) if not col.nullable else np.array([], int)
        if bad_nan.size:
            raise error(f"{where}, column {col.name!r}, row {bad_nan[0]}: NaN not allowed")
        bad_inf = np.flatnonzero(np.isinf(arr)) if not col.allow_inf else np.array([], int)
        if bad_inf.size:
            raise error(f"{where}, column {col.name!r}, row {bad_inf[0]}: inf not allowed")
    allowed = col.allowed()
    if allowed is not None:
        bad = np.flatnonzero(~np.isin(arr, allowed))
        if bad.size:
            raise error(
                f"{where}, column {col.name!r}, row {bad[0]}: {str(arr[bad[0]])!r} is not one of "
                f"{list(allowed)}"
            )


# --------------------------------------------------------------------------- writing


def _format_column(col: Column, values: npt.NDArray[Any]) -> list[str]:
    """Cells of one column as text (see the module docstring for the encoding)."""
    items = values.tolist()
    if col.dtype == "float":
        return [repr(float(v)) for v in items]
    if col.dtype == "bool":
        return ["1" if v else "0" for v in items]
    if col.dtype == "int":
        return [str(int(v)) for v in items]
    return [str(v) for v in items]


def write_table(path: str | Path, table: Table) -> None:
    """Write ``table`` as CSV (header = schema column order), atomically.

    Args:
        path: Destination file; its folder is created if needed.
        table: A :class:`Table` (validated when it was built).
    """
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    cols = table.schema.columns
    writer.writerow([c.name for c in cols])
    writer.writerows(zip(*(_format_column(c, table.columns[c.name]) for c in cols), strict=True))
    atomic_write_text(path, buf.getvalue())


# --------------------------------------------------------------------------- reading


def write_rows(path: Path, columns: Sequence[str], rows: Sequence[Mapping[str, Any]]) -> None:
    """Write ``rows`` under the header ``columns``, each cell as ``str()`` of its value (a
    missing cell is written empty), atomically.

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


# --------------------------------------------------------------------------- reading


def read_table(
    path: str | Path,
    schema: TableSchema,
    *,
    error: type[StoredFileError] = TableError,
    skip_bad_rows: bool = False,
) -> Table:
    """Read a CSV file and validate it against ``schema``: the one CSV reader.

    Args:
        path: The CSV file.
        schema: The schema it must follow (column order may differ; the set may not).
        error: The :class:`~sumo_ayss.util.errors.StoredFileError` to raise (``eval.csv``,
            a run's own record, raises :class:`CheckpointError`).
        skip_bad_rows: Leave out a row with the wrong number of cells or a bad cell instead
            of raising (counted in :attr:`Table.n_dropped`): a damaged learning curve is shown
            without its bad rows.

    Returns:
        The validated :class:`Table` (columns in schema order).

    Raises:
        StoredFileError: (``error``) If the file is missing, empty or not UTF-8 text, a column
            is missing or unexpected, a row has the wrong number of cells, a cell does not
            parse as its column's dtype, or a value breaks the column's NaN / inf / choices
            rules. The message names the file, the column and the (0-based data) row.
    """
    path = Path(path)
    if not path.is_file():
        raise error(f"{path}: table file not found")
    try:
        with path.open(newline="", encoding="utf-8") as f:
            rows = list(csv.reader(f))
    except UnicodeDecodeError as e:
        raise error(f"{path}: not UTF-8 text, not a table ({e})") from None
    except (OSError, csv.Error) as e:
        raise error(f"{path}: cannot read the table ({e})") from None
    if not rows:
        raise error(f"{path}: empty file, expected a header with {schema.names}")
    header, body = rows[0], rows[1:]
    late = [c for c in schema.columns if c.since and c.name not in header]
    _check_names(schema, header + [c.name for c in late], str(path), error)
    if len(set(header)) != len(header):
        raise error(f"{path}: duplicate column names in header {header}")
    kept = [row for row in body if _row_ok(schema, header, row, path)] if skip_bad_rows else body
    for i, row in enumerate(kept):
        if len(row) != len(header):
            raise error(f"{path}: row {i} has {len(row)} cells, header has {len(header)}")
    columns = _typed_columns(schema, header, kept, path, error)
    for col in late:  # written before the column existed
        columns[col.name] = col.missing(len(kept))
    table = {name: columns[name] for name in schema.names}
    return Table(schema, table, n_dropped=len(body) - len(kept))


def _typed_columns(
    schema: TableSchema,
    header: Sequence[str],
    body: Sequence[Sequence[str]],
    path: Path,
    error: type[StoredFileError],
) -> dict[str, npt.NDArray[Any]]:
    cells = list(zip(*body, strict=True)) if body else [() for _ in header]
    columns = {}
    for j, name in enumerate(header):
        col = schema.by_name[name]
        arr = _parse_column(col, cells[j], path, error)
        _check_values(col, arr, str(path), error)
        columns[name] = arr
    return columns


def _row_ok(schema: TableSchema, header: Sequence[str], row: Sequence[str], path: Path) -> bool:
    """Whether one row has its cells and every cell is valid."""
    if len(row) != len(header):
        return False
    try:
        _typed_columns(schema, header, [row], path, TableError)
    except TableError:
        return False
    return True


def _parse_column(
    col: Column, texts: Sequence[str], path: Path, error: type[StoredFileError]
) -> npt.NDArray[Any]:
    """Parse one column's cells, naming the first bad cell on failure."""
    if col.dtype == "str":
        return np.array(texts, dtype=str)
    if col.dtype == "bool":
        out = np.empty(len(texts), dtype=np.bool_)
        for i, t in enumerate(texts):
            if t in _TRUE:
                out[i] = True
            elif t in _FALSE:
                out[i] = False
            else:
                raise _cell_error(path, col, i, t, error)
        return out
    if col.dtype == "float" and col.nullable:
        texts = ["nan" if t.strip() == "" else t for t in texts]
    try:
        return np.array(texts, dtype=_NUMPY_DTYPE[col.dtype]).reshape(len(texts))
    except (TypeError, ValueError, OverflowError):
        pass
    parse = int if col.dtype == "int" else float
    for i, t in enumerate(texts):
        try:
            parse(t)
        except (TypeError, ValueError, OverflowError):
            raise _cell_error(path, col, i, t, error) from None
    raise error(f"{path}: column {col.name!r}: values do not parse as {col.dtype}")


def _cell_error(
    path: Path, col: Column, row: int, text: str, error: type[StoredFileError]
) -> StoredFileError:
    return error(f"{path}: column {col.name!r}, row {row}: expected {col.dtype}, got {text!r}")
