"""Argument checks shared by the statistics modules (numpy and the stdlib only)."""

from __future__ import annotations

import numbers

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sumo_ayss.util.errors import ConfigError

__all__ = ["check_level", "finite_1d", "is_real"]


def is_real(value: object) -> bool:
    """True for real numbers (numpy scalars included), False for bools and the rest."""
    return isinstance(value, numbers.Real) and not isinstance(value, bool | np.bool_)


def check_level(level: float, name: str = "level") -> float:
    """Validates a confidence level or probability.

    Args:
        level: Candidate value.
        name: Argument name used in the error message.

    Returns:
        ``level`` as a float.

    Raises:
        ConfigError: If ``level`` is not a real number strictly between 0 and 1.
    """
    if not is_real(level) or not 0.0 < float(level) < 1.0:
        raise ConfigError(f"{name}: expected a number in (0, 1), got {level!r}")
    return float(level)


def finite_1d(x: ArrayLike, name: str) -> NDArray[np.float64]:
    """Returns ``x`` as a finite 1-D float array (scalars become length 1)."""
    try:
        arr = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ConfigError(f"{name}: expected real numbers") from exc
    if arr.ndim > 1:
        raise ConfigError(f"{name}: expected a 1-D array, got shape {arr.shape}")
    arr = np.atleast_1d(arr)
    if not np.all(np.isfinite(arr)):
        raise ConfigError(f"{name}: contains NaN or infinite values")
    return arr
