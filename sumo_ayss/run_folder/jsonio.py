"""JSON summaries of the run folder (``outcome.json``, ``ayss.json``): strict JSON, one
writer, one reader.

Non-finite floats are written as ``null`` (strict JSON has no NaN); numpy scalars and arrays
become Python numbers and lists; paths become strings. Files are indented, key-sorted and
written atomically.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from sumo_ayss.util.atomic import atomic_write_text
from sumo_ayss.util.errors import TableError

__all__ = ["read_json", "write_json"]


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


def read_json(path: str | Path) -> dict[str, Any]:
    """Read a summary written by :func:`write_json`.

    Raises:
        TableError: If the file is missing or unreadable, not UTF-8 JSON, or not a JSON
            object.
    """
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise TableError(f"{path}: summary file not found") from None
    except UnicodeDecodeError as exc:
        raise TableError(f"{path}: not UTF-8 text, not JSON ({exc})") from None
    except json.JSONDecodeError as exc:
        raise TableError(f"{path}: not valid JSON ({exc})") from None
    except OSError as exc:
        raise TableError(f"{path}: cannot read ({exc})") from None
    if not isinstance(data, dict):
        raise TableError(f"{path}: expected a JSON object, got {type(data).__name__}")
    return data
