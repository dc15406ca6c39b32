"""Surrogate safety measures and aggressiveness indicators (pure numpy, no SUMO).

Conventions used throughout this module:

* Distances are in m, speeds in m/s, times in s.
* Longitudinal quantities are measured along the direction of travel; the *follower* is the
  vehicle behind, the *leader* the vehicle ahead, and the *gap* is bumper to bumper
  (leader's rear bumper minus follower's front bumper), so a gap <= 0 means the two bodies
  touch or overlap.
* The *closing speed* is ``v_follower - v_leader``: positive when the gap shrinks.
* Planar vectors are arrays whose last axis has length 2 (x, y) in any fixed Cartesian frame.

Every function is vectorised with numpy broadcasting. A function called with scalars returns
a Python ``float``; called with arrays it returns an ``np.ndarray`` of the broadcast shape.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sumo_ayss.util.errors import ConfigError

__all__ = [
    "delta_v_bar",
    "delta_v_bar_between",
    "time_to_collision",
    "ttc_longitudinal",
]

FloatOrArray = float | NDArray[np.float64]


def _as_float_array(value: ArrayLike, name: str) -> NDArray[np.float64]:
    """Converts ``value`` to a float64 array, naming ``name`` if that is impossible."""
    try:
        return np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ConfigError(f"{name}: expected real numbers, got {value!r}") from exc


def _scalar_or_array(result: NDArray[np.float64]) -> FloatOrArray:
    """Returns a Python float for a 0-d result, the array otherwise."""
    return float(result) if result.ndim == 0 else result


def time_to_collision(gap_m: ArrayLike, closing_speed_mps: ArrayLike) -> FloatOrArray:
    """Time to collision of a follower and its leader at constant speeds.

    ``TTC = gap / closing_speed`` with the conventions:

    * ``gap_m <= 0`` (already touching or overlapping): ``TTC = 0``, whatever the speeds.
    * ``gap_m > 0`` and ``closing_speed_mps <= 0`` (gap opening or constant): ``TTC = +inf``.
    * ``gap_m > 0`` and ``closing_speed_mps > 0``: ``TTC = gap_m / closing_speed_mps > 0``.
    * NaN in either input gives NaN.

    Args:
        gap_m: Bumper-to-bumper gap in m (leader rear minus follower front); any shape.
        closing_speed_mps: ``v_follower - v_leader`` in m/s, positive when the gap shrinks;
            any shape broadcastable with ``gap_m``.

    Returns:
        TTC in s, in ``[0, +inf]``, with the broadcast shape of the inputs (a ``float`` for
        scalar inputs).

    Raises:
        ConfigError: If an input is not numeric or the shapes do not broadcast.
    """
    gap = _as_float_array(gap_m, "gap_m")
    closing = _as_float_array(closing_speed_mps, "closing_speed_mps")
    try:
        gap, closing = np.broadcast_arrays(gap, closing)
    except ValueError as exc:
        raise ConfigError(
            f"gap_m and closing_speed_mps: shapes {gap.shape} and {closing.shape} do not broadcast"
        ) from exc
    ttc = np.full(gap.shape, np.inf, dtype=np.float64)
    closing_in = (gap > 0.0) & (closing > 0.0)
    with np.errstate(over="ignore"):  # a tiny closing speed gives +inf, which is right
        np.divide(gap, closing, out=ttc, where=closing_in)
    ttc[gap <= 0.0] = 0.0
    ttc[np.isnan(gap) | np.isnan(closing)] = np.nan
    return _scalar_or_array(ttc)


def ttc_longitudinal(
    gap_m: ArrayLike, v_leader_mps: ArrayLike, v_follower_mps: ArrayLike
) -> FloatOrArray:
    """Longitudinal time to collision from the two speeds.

    Same conventions as :func:`time_to_collision` with closing speed
    ``v_follower_mps - v_leader_mps``.

    Args:
        gap_m: Bumper-to-bumper gap in m (leader rear minus follower front); any shape.
        v_leader_mps: Longitudinal speed of the leader (vehicle ahead) in m/s.
        v_follower_mps: Longitudinal speed of the follower (vehicle behind) in m/s.

    Returns:
        TTC in s, in ``[0, +inf]``, with the broadcast shape of the inputs (a ``float`` for
        scalar inputs).

    Raises:
        ConfigError: If an input is not numeric or the shapes do not broadcast.
    """
    leader = _as_float_array(v_leader_mps, "v_leader_mps")
    follower = _as_float_array(v_follower_mps, "v_follower_mps")
    try:
        closing = follower - leader
    except ValueError as exc:
        raise ConfigError(
            f"v_leader_mps and v_follower_mps: shapes {leader.shape} and {follower.shape} do "
            "not broadcast"
        ) from exc
    return time_to_collision(gap_m, closing)


def _planar(value: ArrayLike, name: str) -> NDArray[np.float64]:
    """Converts ``value`` to a float array whose last axis has length 2."""
    arr = _as_float_array(value, name)
    if arr.ndim == 0 or arr.shape[-1] != 2:
        raise ConfigError(f"{name}: expected shape (..., 2) (x, y), got shape {arr.shape}")
    return arr


def delta_v_bar(rel_pos: ArrayLike, rel_vel: ArrayLike) -> FloatOrArray:
    """Relative velocity projected on the relative position, Δv̄ (Borrmann et al., 2015).

    ``Δv̄ = (Δp / |Δp|) · Δv`` with ``Δp = p_j - p_i`` and ``Δv = v_j - v_i`` for the *same*
    ordered pair (i, j). Δv̄ is the rate of change of the distance ``|Δp|`` in m/s:

    * ``Δv̄ < 0``: the two approach (more negative = more aggressive);
    * ``Δv̄ > 0``: they separate; ``Δv̄ = 0``: the distance is momentarily constant.

    It is symmetric in (i, j) (swapping both flips both signs), invariant under rotation and
    translation of the frame, and for a follower i directly behind a leader j (no lateral
    offset) it equals ``-(v_i - v_j)``, minus the 1-D closing speed. Positions are whatever
    reference points the caller uses (vehicle centres in this project).

    Args:
        rel_pos: Δp in m, shape ``(..., 2)``.
        rel_vel: Δv in m/s, shape ``(..., 2)``, broadcastable with ``rel_pos``.

    Returns:
        Δv̄ in m/s with the broadcast shape of the inputs minus the last axis (a ``float`` for
        single vectors). NaN where ``|Δp| = 0`` (the direction is undefined) or an input is
        NaN.

    Raises:
        ConfigError: If an input does not have a last axis of length 2 or the shapes do not
            broadcast.
    """
    dp = _planar(rel_pos, "rel_pos")
    dv = _planar(rel_vel, "rel_vel")
    try:
        dp, dv = np.broadcast_arrays(dp, dv)
    except ValueError as exc:
        raise ConfigError(
            f"rel_pos and rel_vel: shapes {dp.shape} and {dv.shape} do not broadcast"
        ) from exc
    dist = np.hypot(dp[..., 0], dp[..., 1])
    dot = dp[..., 0] * dv[..., 0] + dp[..., 1] * dv[..., 1]
    out = np.full(dist.shape, np.nan, dtype=np.float64)
    np.divide(dot, dist, out=out, where=dist > 0.0)
    return _scalar_or_array(out)


def delta_v_bar_between(
    pos_i: ArrayLike, vel_i: ArrayLike, pos_j: ArrayLike, vel_j: ArrayLike
) -> FloatOrArray:
    """Δv̄ of vehicles i and j from absolute states; see :func:`delta_v_bar`.

    Forms ``Δp = pos_j - pos_i`` and ``Δv = vel_j - vel_i`` so that the sign convention
    cannot be mixed up: negative when the two approach.

    Args:
        pos_i: Position of vehicle i in m, shape ``(..., 2)``.
        vel_i: Velocity of vehicle i in m/s, shape ``(..., 2)``.
        pos_j: Position of vehicle j in m, shape ``(..., 2)``.
        vel_j: Velocity of vehicle j in m/s, shape ``(..., 2)``.

    Returns:
        Δv̄ in m/s, shape ``(...)`` (a ``float`` for single vectors); NaN where the two
        positions coincide.

    Raises:
        ConfigError: If an input does not have a last axis of length 2 or the shapes do not
            broadcast.
    """
    p_i, v_i = _planar(pos_i, "pos_i"), _planar(vel_i, "vel_i")
    p_j, v_j = _planar(pos_j, "pos_j"), _planar(vel_j, "vel_j")
    try:
        rel_pos, rel_vel = p_j - p_i, v_j - v_i
    except ValueError as exc:
        raise ConfigError("pos_i, vel_i, pos_j, vel_j: shapes do not broadcast") from exc
    return delta_v_bar(rel_pos, rel_vel)
