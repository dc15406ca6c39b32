"""Gymnasium envs of the testbed; importing :mod:`sumo_ayss` registers their ids."""

from sumo_ayss.envs.car_following import CarFollowingEnv
from sumo_ayss.envs.odd import InitialCondition

__all__ = ["CarFollowingEnv", "InitialCondition"]
