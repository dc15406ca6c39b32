"""Run a policy on a fixed list of initial conditions and tabulate each episode.

The same code evaluates SPCP candidates during training (paper: 100 scenarios every
10,000 steps) and produces the outcome tables (200 scenarios per SPCP). A policy here is
any callable from a batch of observations ``(N, obs_dim)`` to actions ``(N,)``.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from sumo_ayss.analysis.hazards import HAZARD_NAMES, HazardMeasures
from sumo_ayss.analysis.safety_measures import MEASURE_NAMES, EpisodeMeasures
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.envs.pair_env import PairEnv
from sumo_ayss.scenarios.trajectory import hazards_of, measures_of, support_measures_of

Policy = Callable[[npt.NDArray[np.float32]], npt.NDArray[np.integer]]


@dataclass(frozen=True)
class EpisodeResult:
    """One episode.

    Attributes:
        episode_return: Sum of the rewards R (a collision step pays ``-alpha_collision``).
        collided: The episode ended in a collision.
        final_headway_m: Headway h after the last step [m].
        n_steps: Decisions taken.
        lane_changed: The POV started a lane change (always False in car-following).
        near_miss_pay: Sum of ``alpha_A·R_A`` over the episode: the return without the
            collision term (a collision step pays no R_A).
        vut_mean_speed_mps: Mean of the VUT's speed at the end of each decision [m/s].
        measures: The episode's surrogate safety measures (:func:`run_episode` records
            them; ``None`` where the episode was not recorded, e.g. training's vec-env
            evaluation).
        actions: The POV's actions, in order (:func:`run_episode` records them; empty
            where not recorded): what a counterfactual replays open loop
            (:mod:`sumo_ayss.scenarios.preventability`).
        hazards: What the VUT did to the traffic behind it (:mod:`sumo_ayss.analysis.
            hazards`; ``None`` where not recorded).
        support_measures: The measures against a case's second (supporting) POV
            (``lead_and_cut_in``); ``None`` in a case with one POV or where not recorded.
        pov_failure: The episode ended by a contact the POVs were not allowed (a supporting
            POV touching the VUT, or two POVs touching); always False with one POV.
        support_vut_contact: Of those, the supporting POV touched the VUT.
        pov_pov_contact: Of those, the two POVs touched (both kinds in one step: both true).
    """

    episode_return: float
    collided: bool
    final_headway_m: float
    n_steps: int
    lane_changed: bool
    near_miss_pay: float = math.nan
    vut_mean_speed_mps: float = math.nan
    # Not part of equality: the same episode tabulated from a vec env has no trajectory.
    measures: EpisodeMeasures | None = field(default=None, compare=False)
    actions: tuple[int, ...] = field(default=(), compare=False)
    hazards: HazardMeasures | None = field(default=None, compare=False)
    support_measures: EpisodeMeasures | None = field(default=None, compare=False)
    pov_failure: bool = field(default=False, compare=False)
    support_vut_contact: bool = field(default=False, compare=False)
    pov_pov_contact: bool = field(default=False, compare=False)

    def measure_row(self) -> dict[str, float]:
        """The measures as table columns (NaN throughout when not recorded)."""
        if self.measures is None:
            return dict.fromkeys(MEASURE_NAMES, math.nan)
        return self.measures.as_row()

    def hazard_row(self) -> dict[str, float]:
        """The hazards as table columns (NaN throughout when not recorded)."""
        if self.hazards is None:
            return dict.fromkeys(HAZARD_NAMES, math.nan)
        return self.hazards.as_row()


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
    The episode's trajectory is recorded and reduced to its safety measures
    (:mod:`sumo_ayss.scenarios.trajectory`).
    """
    base = env.unwrapped
    assert isinstance(base, PairEnv)
    obs, reset_info = base.reset(options={"initial_condition": ic})
    rewards: list[float] = []
    infos: list[dict[str, Any]] = []
    actions: list[int] = []
    while True:
        action = int(np.asarray(policy(obs[None, :])).reshape(-1)[0])
        actions.append(action)
        obs, reward, terminated, truncated, info = base.step(action)
        rewards.append(float(reward))
        infos.append(info)
        if terminated or truncated:
            break
    result = episode_result(rewards, infos)
    measures = measures_of(base.config, reset_info, infos)
    hazards = hazards_of(base.config, reset_info, infos)
    return dataclasses.replace(
        result,
        measures=measures,
        actions=tuple(actions),
        hazards=hazards,
        support_measures=support_measures_of(base.config, reset_info, infos),
        pov_failure=bool(infos[-1].get("pov_failure", False)),
        support_vut_contact=bool(infos[-1].get("support_vut_contact", False)),
        pov_pov_contact=bool(infos[-1].get("pov_pov_contact", False)),
    )


def episode_result(rewards: Sequence[float], infos: Sequence[Mapping[str, Any]]) -> EpisodeResult:
    """The :class:`EpisodeResult` of one episode's rewards and step infos (in order).

    The one tabulation of an episode, whichever env ran it (the single env here, the pairs
    of a :class:`~sumo_ayss.envs.vec_env.PairVecEnv` in training's evaluation).
    """
    total = pay = speed_sum = 0.0
    changed = False
    for reward, info in zip(rewards, infos, strict=True):
        total += float(reward)
        if not info.get("contact", info["collision"]):  # a case with several POVs: any
            pay += float(reward)
        speed_sum += float(info["vut_speed_mps"])
        changed = changed or bool(info.get("lane_change_started", False))
    last = infos[-1]
    return EpisodeResult(
        total,
        bool(last["collision"]),
        float(last["headway_m"]),
        len(rewards),
        changed,
        near_miss_pay=pay,
        vut_mean_speed_mps=speed_sum / len(rewards),
    )


def measure_columns(episodes: Sequence[EpisodeResult]) -> dict[str, list[float]]:
    """The measure and hazard columns of a table of ``episodes``: column name -> one value
    each."""
    rows = [{**e.measure_row(), **e.hazard_row()} for e in episodes]
    return {name: [r[name] for r in rows] for name in (*MEASURE_NAMES, *HAZARD_NAMES)}


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
