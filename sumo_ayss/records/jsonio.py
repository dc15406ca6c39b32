"""Stored JSON objects: strict JSON, one writer, one reader.

:func:`read_json` is the one JSON reader of the package and :func:`json_field` its one field
check: every stored JSON file (the run folder's summaries and records,
:mod:`sumo_ayss.run_folder`; the checkpoints' own, :mod:`sumo_ayss.training.checkpoint_files`)
is read through them, and every error they raise names the file and the field
(:class:`~sumo_ayss.util.errors.StoredFileError`, the common base of the ``TableError`` and
``CheckpointError`` callers catch). Nothing here knows a file.

Non-finite floats are written as ``null`` (strict JSON has no NaN); numpy scalars and arrays
become Python numbers and lists; paths become strings. Files are indented, key-sorted and
written atomically.
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from sumo_ayss.util.atomic import atomic_write_text
from sumo_ayss.util.errors import StoredFileError, TableError

__all__ = ["json_field", "json_list", "json_number", "json_records", "read_json", "write_json"]

_R = TypeVar("_R")


def _jsonable(obj: Any) -> Any:
    """Plain JSON types: numpy scalars/arrays to Python, tuples to lists, NaN/inf to None."""
    if isinstance(obj, Mapping):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _jsonable(obj.tolist())
    if isinstance(obj, np.generic):
        return _jsonable(obj.item())
    if isinstance(obj, Path):
        return str(obj)
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def write_json(path: str | Path, data: Mapping[str, Any]) -> None:
    """Write a summary as indented, key-sorted JSON, atomically.

    Non-finite floats (NaN, ±inf) are written as ``null`` (strict JSON has no NaN); numpy
    scalars and arrays become Python numbers and lists; paths become strings.
    """
    text = json.dumps(_jsonable(data), indent=2, sort_keys=True, allow_nan=False)
    atomic_write_text(path, text + "\n")


def read_json(path: str | Path, *, error: type[StoredFileError] = TableError) -> dict[str, Any]:
    """Read a JSON object from a stored file: the one JSON reader.

    Args:
        path: The file.
        error: The :class:`~sumo_ayss.util.errors.StoredFileError` to raise: a summary or
            study file raises :class:`TableError` (the default), a run's own records
            (``seeds.json``, ``spcp.json``, checkpoints) :class:`CheckpointError`.

    Raises:
        StoredFileError: (``error``) If the file is missing or unreadable, not UTF-8 JSON,
            or not a JSON object; the message starts with the file.
    """
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise error(f"{path}: file not found") from None
    except UnicodeDecodeError as exc:
        raise error(f"{path}: unreadable JSON: not UTF-8 text ({exc})") from None
    except json.JSONDecodeError as exc:
        raise error(f"{path}: unreadable JSON: not valid JSON ({exc})") from None
    except OSError as exc:
        raise error(f"{path}: unreadable JSON: cannot read ({exc})") from None
    if not isinstance(data, dict):
        raise error(f"{path}: expected a JSON object, got {type(data).__name__}")
    return data


def json_field(
    data: Mapping[str, Any],
    key: str,
    kind: type | tuple[type, ...],
    where: str,
    *,
    error: type[StoredFileError] = TableError,
) -> Any:
    """``data[key]``, checked to be present and of ``kind`` (a boolean is never an ``int``
    or ``float`` here unless ``kind`` names ``bool``).

    Args:
        data: A JSON object as read.
        key: The field.
        kind: The allowed type(s); ``object`` allows any value.
        where: The file and the object's place in it (``"<path>: cases[2]"``).
        error: The error type to raise (as :func:`read_json`).

    Raises:
        StoredFileError: ``<where>: missing field 'key'`` or ``<where>: key: expected int,
            got ...``.
    """
    if key not in data:
        raise error(f"{where}: missing field {key!r}")
    value = data[key]
    kinds = kind if isinstance(kind, tuple) else (kind,)
    if (isinstance(value, bool) and bool not in kinds and object not in kinds) or not isinstance(
        value, kinds
    ):
        names = " or ".join(k.__name__ for k in kinds)
        raise error(f"{where}: {key}: expected {names}, got {value!r}")
    return value


def json_number(
    data: Mapping[str, Any], key: str, where: str, *, error: type[StoredFileError] = TableError
) -> float:
    """``data[key]`` as a float: a JSON number, or NaN for ``null`` (how :func:`write_json`
    writes a non-finite float); checked as :func:`json_field`."""
    value = json_field(data, key, (int, float, type(None)), where, error=error)
    return math.nan if value is None else float(value)


def json_list(
    data: Mapping[str, Any],
    key: str,
    kind: type,
    where: str,
    *,
    error: type[StoredFileError] = TableError,
) -> tuple[Any, ...]:
    """``data[key]``, a list whose every element is of ``kind`` (a boolean is never an
    ``int``), as a tuple; checked as :func:`json_field`."""
    values = json_field(data, key, object, where, error=error)
    if not isinstance(values, list) or not all(
        isinstance(v, kind) and (kind is bool or not isinstance(v, bool)) for v in values
    ):
        raise error(f"{where}: {key}: expected a list of {kind.__name__}, got {values!r}")
    return tuple(values)


#: The field annotations :func:`json_records` reads with :func:`json_field`.
_KINDS: dict[str, type] = {"str": str, "int": int, "bool": bool}


def json_records(
    data: Mapping[str, Any],
    key: str,
    cls: type[_R],
    where: str,
    *,
    error: type[StoredFileError] = TableError,
) -> tuple[_R, ...]:
    """``data[key]``, a list of JSON objects, as records of the flat dataclass ``cls``: each
    field read by its annotation (``str``, ``int``, ``bool`` as :func:`json_field`;
    ``float`` as :func:`json_number`, ``null`` read as NaN; ``tuple[str, ...]`` as
    :func:`json_list`). The schema is the dataclass: no per-field reader is written by hand.

    Raises:
        StoredFileError: As :func:`json_field`, the element named (``<where>: looks[2]:
            n_seeds: expected int, got True``), or ``<where>: looks[2]: expected an
            object, got ...``.
    """
    out = []
    for i, item in enumerate(json_field(data, key, list, where, error=error)):
        at = f"{where}: {key}[{i}]"
        if not isinstance(item, Mapping):
            raise error(f"{at}: expected an object, got {item!r}")
        fields: dict[str, Any] = {}
        for f in dataclasses.fields(cls):  # type: ignore[arg-type]
            kind = str(f.type)
            if kind == "float":
                fields[f.name] = json_number(item, f.name, at, error=error)
            elif kind == "tuple[str, ...]":
                fields[f.name] = json_list(item, f.name, str, at, error=error)
            else:
                fields[f.name] = json_field(item, f.name, _KINDS[kind], at, error=error)
        out.append(cls(**fields))
    return tuple(out)
