"""Gymnasium envs of the testbed; importing :mod:`sumo_ayss` registers their ids."""

from __future__ import annotations

from sumo_ayss.config import EnvConfig
from sumo_ayss.envs.car_following import CarFollowingEnv
from sumo_ayss.envs.cut_in import CutInEnv
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.envs.pair_env import PairEnv


def make_env(config: EnvConfig, sumo_seed: int | None = None) -> PairEnv:
    """The env of ``config.case`` (no wrappers), SUMO not started yet."""
    if config.case == "cut_in":
        return CutInEnv(config, sumo_seed=sumo_seed)
    return CarFollowingEnv(config, sumo_seed=sumo_seed)


__all__ = ["CarFollowingEnv", "CutInEnv", "InitialCondition", "PairEnv", "make_env"]
