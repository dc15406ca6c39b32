"""Run a policy on a fixed list of initial conditions and tabulate each episode.

The same code evaluates SPCP candidates during training (paper: 100 scenarios every
10,000 steps) and produces the outcome tables (200 scenarios per SPCP). A policy here is
any callable from a batch of observations ``(N, obs_dim)`` to actions ``(N,)``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.envs.pair_env import PairEnv

Policy = Callable[[npt.NDArray[np.float32]], npt.NDArray[np.integer]]


@dataclass(frozen=True)
class EpisodeResult:
    """One episode. Headways in m; ``lane_changed`` is False in car-following."""

    episode_return: float
    collided: bool
    final_headway_m: float
    n_steps: int
    lane_changed: bool


@dataclass(frozen=True)
class ScenarioSummary:
    """Aggregate over a scenario set (the paper's Tables II and III columns)."""

    n_episodes: int
    mean_return: float
    std_return: float
    crash_rate: float
    lane_change_rate: float
    mean_final_headway_m: float

    def as_dict(self) -> dict[str, float | int]:
        return dict(self.__dict__)


def run_episode(env: PairEnv, policy: Policy, ic: InitialCondition) -> EpisodeResult:
    """Roll ``policy`` greedily from one initial condition until the episode ends.

    Uses ``env.unwrapped`` and ``reset(options={"initial_condition": ic})``, so the env's RNG
    is not consumed. ``policy`` is called on a batch of one observation, shape ``(1, d)``.
    """
    base = env.unwrapped
    assert isinstance(base, PairEnv)
    obs, _ = base.reset(options={"initial_condition": ic})
    total, steps, changed = 0.0, 0, False
    while True:
        action = int(np.asarray(policy(obs[None, :])).reshape(-1)[0])
        obs, reward, terminated, truncated, info = base.step(action)
        total += float(reward)
        steps += 1
        changed = changed or bool(info.get("lane_change_started", False))
        if terminated or truncated:
            break
    return EpisodeResult(total, bool(info["collision"]), float(info["headway_m"]), steps, changed)


def run_episodes(
    env: PairEnv, policy: Policy, scenarios: Sequence[InitialCondition]
) -> list[EpisodeResult]:
    """:func:`run_episode` on each initial condition in turn.

    A training env evaluated between training phases continues its own random stream, as
    no reset here consumes the env's RNG.
    """
    return [run_episode(env, policy, ic) for ic in scenarios]


def summarize(results: Sequence[EpisodeResult]) -> ScenarioSummary:
    """Means over episodes; ``std_return`` is the sample standard deviation (ddof = 1)."""
    returns = np.array([r.episode_return for r in results], dtype=float)
    n = len(results)
    return ScenarioSummary(
        n_episodes=n,
        mean_return=float(returns.mean()) if n else math.nan,
        std_return=float(returns.std(ddof=1)) if n > 1 else math.nan,
        crash_rate=float(np.mean([r.collided for r in results])) if n else math.nan,
        lane_change_rate=float(np.mean([r.lane_changed for r in results])) if n else math.nan,
        mean_final_headway_m=float(np.mean([r.final_headway_m for r in results]))
        if n
        else math.nan,
    )
