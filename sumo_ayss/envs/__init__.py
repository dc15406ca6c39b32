"""Gymnasium envs of the testbed; importing :mod:`sumo_ayss` registers their ids.

The env classes are imported lazily: the pure modules of this package (``rewards``,
``odd``) must be importable without loading libsumo (the report stage uses them).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from sumo_ayss.cases import get_case

if TYPE_CHECKING:
    from sumo_ayss.config import EnvConfig
    from sumo_ayss.envs.car_following import CarFollowingEnv
    from sumo_ayss.envs.cut_in import CutInEnv
    from sumo_ayss.envs.odd import InitialCondition
    from sumo_ayss.envs.pair_env import PairEnv

_LAZY = {
    "CarFollowingEnv": "sumo_ayss.envs.car_following",
    "CutInEnv": "sumo_ayss.envs.cut_in",
    "InitialCondition": "sumo_ayss.envs.odd",
    "PairEnv": "sumo_ayss.envs.pair_env",
}


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def make_env(config: EnvConfig, sumo_seed: int | None = None) -> PairEnv:
    """The env of ``config.case`` (its registered :attr:`~sumo_ayss.cases.Case.env`, no
    wrappers), SUMO not started yet."""
    env: PairEnv = get_case(config.case).env_class()(config, sumo_seed=sumo_seed)
    return env


__all__ = ["CarFollowingEnv", "CutInEnv", "InitialCondition", "PairEnv", "make_env"]
