"""The follower in an episode (issue 33): whether it is there, where it starts, what the
step infos record of it.

An episode has a follower when the env's ``env.follower.enabled`` and its initial condition
carries a follower start (:func:`~sumo_ayss.envs.odd.with_followers`: the outcome and
cross-play scenario sets). Training, candidate selection and the AYSS Monte Carlo sample
initial conditions without one: the follower never changes the VUT-POV episode (it is
behind the VUT, whose law and the POV's do not look behind, and a rear-end is not a VUT-POV
crash), so the POV is trained on the same episodes either way and pays nothing for it.
"""

from __future__ import annotations

import math
from typing import Any

from sumo_ayss.config import EnvConfig
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.sim.follower import Follower
from sumo_ayss.sim.pair import PairPlacement, VehiclePair
from sumo_ayss.util.errors import ConfigError

__all__ = ["check_follower_start", "follower_info", "follower_wanted", "place_follower"]


def follower_wanted(config: EnvConfig, ic: InitialCondition) -> bool:
    """Whether the episode of ``ic`` has a follower."""
    return config.follower.enabled and ic.follower_gap_m is not None


def check_follower_start(ic: InitialCondition) -> None:
    """Refuse a given follower start that is not a place behind the VUT."""
    where = "reset options['initial_condition']"
    gap, speed = ic.follower_gap_m, ic.follower_speed_mps
    if (gap is None) != (speed is None):
        raise ConfigError(
            f"{where}: follower_gap_m and follower_speed_mps go together, got {gap!r} and {speed!r}"
        )
    if gap is None:
        return
    for name, value in (("follower_gap_m", gap), ("follower_speed_mps", speed)):
        ok = isinstance(value, int | float) and not isinstance(value, bool)
        if not ok or not math.isfinite(float(value)):  # type: ignore[arg-type]
            raise ConfigError(f"{where}.{name} must be a finite number, got {value!r}")
    if gap <= 0:
        raise ConfigError(
            f"{where}.follower_gap_m must be > 0 m (VUT rear minus follower front; 0 or less "
            f"starts the follower inside the VUT), got {gap!r}"
        )
    if speed is not None and speed < 0:
        raise ConfigError(f"{where}.follower_speed_mps must be >= 0, got {speed!r}")


def place_follower(
    pair: VehiclePair, placement: PairPlacement, ic: InitialCondition, config: EnvConfig
) -> None:
    """Put the episode's follower ``ic.follower_gap_m`` behind the VUT's rear, in its lane."""
    assert ic.follower_gap_m is not None and ic.follower_speed_mps is not None
    pos = placement.vut_pos_m - config.vut_type.length_m - ic.follower_gap_m
    if pos < 0.0:
        raise ConfigError(
            f"reset options['initial_condition'].follower_gap_m = {ic.follower_gap_m:g} m "
            f"puts the follower before the road's start ({pos:.1f} m)"
        )
    pair.place_follower(placement.vut_lane, pos, ic.follower_speed_mps)


def follower_info(follower: Follower) -> dict[str, Any]:
    """The follower's part of a step's info: front lane position [m], speed [m/s],
    acceleration [m/s²] (NaN once gone), and whether it has run into the VUT."""
    pos, speed, accel = follower.state()
    return {
        "follower_pos_m": pos,
        "follower_speed_mps": speed,
        "follower_accel_mps2": accel,
        "rear_end": follower.rear_end,
    }
