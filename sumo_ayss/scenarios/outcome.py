"""Overall safety outcome of an SPCP (paper Tables II and III), with confidence intervals.

:func:`run_outcome` rolls a policy greedily over ``n`` initial conditions drawn from the
env's ODD by :func:`~sumo_ayss.envs.odd.scenario_set` with a fixed seed, so
every SPCP (every VUT, every training seed) meets the *same* scenarios (paper: 200). The
default seed :data:`DEFAULT_OUTCOME_SEED` differs from the training's candidate-evaluation
seed (``train.eval_seed``, 2024), so an SPCP is not scored on the scenarios it was selected
on.

One row per episode goes to the outcome table (:data:`~sumo_ayss.run_folder.
OUTCOME_SCHEMA`); :func:`summarize_outcome` reduces it to

* crash rate and lane-change rate: proportions with a Wilson score interval
  (:func:`~sumo_ayss.analysis.stats.wilson_interval`), which stays inside [0, 1] and is
  informative at 0 crashes;
* mean episode reward and mean final headway: Student t intervals
  (:func:`sumo_ayss.analysis.stats.mean_ci`);
* for cut-in, also the paper's Table III reading: mean reward and headway over the episodes
  with a lane change and no collision (``lane_change_no_collision``). Both are reported.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
from tqdm import tqdm

from sumo_ayss.analysis.stats import mean_ci, wilson_interval
from sumo_ayss.cases import get_case
from sumo_ayss.envs.odd import InitialCondition, scenario_set, with_followers
from sumo_ayss.envs.pair_env import PairEnv
from sumo_ayss.records.table import Table
from sumo_ayss.run_folder import OUTCOME_SCHEMA
from sumo_ayss.scenarios.rollout import EpisodeResult, Policy, measure_columns, run_episode
from sumo_ayss.util.errors import ConfigError

__all__ = [
    "DEFAULT_OUTCOME_N",
    "DEFAULT_OUTCOME_SEED",
    "MeanInterval",
    "OutcomeResult",
    "OutcomeSummary",
    "Proportion",
    "outcome_table",
    "run_outcome",
    "summarize_outcome",
]

#: Episodes per SPCP (paper: 200).
DEFAULT_OUTCOME_N = 200
#: Seed of the outcome scenario set, shared by every SPCP; not ``train.eval_seed`` (2024).
DEFAULT_OUTCOME_SEED = 4242


# --------------------------------------------------------------------------- statistics


@dataclass(frozen=True)
class Proportion:
    """A rate with its Wilson interval. ``value``, ``lo``, ``hi`` are fractions in [0, 1]."""

    count: int
    n: int
    value: float
    lo: float
    hi: float
    level: float

    @classmethod
    def of(cls, flags: npt.ArrayLike, level: float = 0.95) -> Proportion:
        """The proportion of True in ``flags`` (NaN value and bounds when empty)."""
        arr = np.asarray(flags, dtype=bool)
        n, count = int(arr.size), int(arr.sum())
        if n == 0:
            return cls(0, 0, math.nan, math.nan, math.nan, level)
        lo, hi = wilson_interval(count, n, level)
        return cls(count, n, count / n, lo, hi, level)


@dataclass(frozen=True)
class MeanInterval:
    """A mean with its Student t interval, in the unit of the averaged quantity.

    ``n = 0`` gives NaN everywhere, ``n = 1`` NaN bounds (see :func:`mean_ci`).
    """

    n: int
    mean: float
    lo: float
    hi: float
    level: float

    @classmethod
    def of(cls, values: npt.ArrayLike, level: float = 0.95) -> MeanInterval:
        arr = np.asarray(values, dtype=float)
        mean, lo, hi = mean_ci(arr, level)
        return cls(int(arr.size), mean, lo, hi, level)


@dataclass(frozen=True)
class OutcomeSummary:
    """Paper Tables II / III for one SPCP.

    Attributes:
        case: The case name.
        n_episodes: Episodes summarised.
        crash_rate: Share of episodes that ended in a collision.
        lane_change_rate: Share of episodes with a started lane change (cut-in); ``None``
            in car-following.
        mean_return: Mean undiscounted episode reward, all episodes.
        mean_final_headway_m: Mean headway after the last step [m], all episodes.
        lc_no_collision_return: Cut-in only (else ``None``): mean episode reward over the
            episodes with a lane change and no collision (paper Table III's r̄_epi).
        lc_no_collision_final_headway_m: Cut-in only: mean final headway [m] over the same
            episodes (paper Table III's h̄).
    """

    case: str
    n_episodes: int
    crash_rate: Proportion
    lane_change_rate: Proportion | None
    mean_return: MeanInterval
    mean_final_headway_m: MeanInterval
    lc_no_collision_return: MeanInterval | None
    lc_no_collision_final_headway_m: MeanInterval | None

    def as_dict(self) -> dict[str, Any]:
        """Nested plain dict (NaN stays NaN; ``run_folder.write_json`` writes it as null)."""
        return asdict(self)


def summarize_outcome(table: Table, case: str, level: float = 0.95) -> OutcomeSummary:
    """Reduce an outcome table (e.g. read back from ``outcome.csv``) to its summary.

    Args:
        table: Rows of :data:`OUTCOME_SCHEMA`.
        case: A registered case; one whose POV changes lanes
            (:attr:`~sumo_ayss.cases.Case.lane_change`, cut-in) adds the lane-change figures.
        level: Confidence level of every interval.

    Returns:
        The :class:`OutcomeSummary`.
    """
    if table.schema != OUTCOME_SCHEMA:
        raise ConfigError(f"summarize_outcome: expected an outcome table, got {table.schema.name}")
    collided, changed = table["collided"], table["lane_changed"]
    returns, headway = table["episode_return"], table["final_headway_m"]
    lc = get_case(case).lane_change
    subset = changed & ~collided
    return OutcomeSummary(
        case=case,
        n_episodes=len(table),
        crash_rate=Proportion.of(collided, level),
        lane_change_rate=Proportion.of(changed, level) if lc else None,
        mean_return=MeanInterval.of(returns, level),
        mean_final_headway_m=MeanInterval.of(headway, level),
        lc_no_collision_return=MeanInterval.of(returns[subset], level) if lc else None,
        lc_no_collision_final_headway_m=MeanInterval.of(headway[subset], level) if lc else None,
    )


# --------------------------------------------------------------------------- running


def outcome_table(
    scenarios: Sequence[InitialCondition],
    episodes: Sequence[EpisodeResult],
    labels: npt.ArrayLike | None = None,
) -> Table:
    """The outcome table of episodes run from ``scenarios`` (same order, same length);
    ``labels``: each episode's ``crash_preventable`` (None: not labelled, NaN)."""
    if len(scenarios) != len(episodes):
        raise ConfigError(f"{len(scenarios)} scenarios but {len(episodes)} episodes")
    return Table(
        OUTCOME_SCHEMA,
        {
            "scenario": np.arange(len(scenarios), dtype=np.int64),
            "v_pov0_mps": [ic.pov_speed_mps for ic in scenarios],
            "v_vut0_mps": [ic.vut_speed_mps for ic in scenarios],
            "gap0_m": [ic.gap_m for ic in scenarios],
            "episode_return": [e.episode_return for e in episodes],
            "collided": np.array([e.collided for e in episodes], dtype=bool),
            "lane_changed": np.array([e.lane_changed for e in episodes], dtype=bool),
            "final_headway_m": [e.final_headway_m for e in episodes],
            "n_steps": np.array([e.n_steps for e in episodes], dtype=np.int64),
            "near_miss_pay": [e.near_miss_pay for e in episodes],
            "vut_mean_speed_mps": [e.vut_mean_speed_mps for e in episodes],
            **measure_columns(episodes),
            "crash_preventable": (
                np.full(len(episodes), math.nan) if labels is None else np.asarray(labels, float)
            ),
        },
    )


@dataclass(frozen=True)
class OutcomeResult:
    """What :func:`run_outcome` returns.

    Attributes:
        table: One row per episode (:data:`OUTCOME_SCHEMA`).
        summary: Rates and means with intervals.
        seed: Seed of the scenario set.
        n: Number of scenarios.
        wall_s: Wall-clock time of the rollouts [s].
        scenarios: The initial conditions, in order.
        episodes: The episodes (with their recorded actions), in order.
    """

    table: Table
    summary: OutcomeSummary
    seed: int
    n: int
    wall_s: float
    scenarios: tuple[InitialCondition, ...] = ()
    episodes: tuple[EpisodeResult, ...] = ()

    def labelled(self, labels: npt.ArrayLike) -> OutcomeResult:
        """This result with the crashes' ``crash_preventable`` labels in its table."""
        table = outcome_table(self.scenarios, self.episodes, labels)
        return dataclasses.replace(self, table=table)


def run_outcome(
    env: PairEnv,
    policy: Policy,
    n: int = DEFAULT_OUTCOME_N,
    seed: int = DEFAULT_OUTCOME_SEED,
    *,
    level: float = 0.95,
    progress: bool = False,
) -> OutcomeResult:
    """Roll ``policy`` over ``n`` ODD scenarios of ``seed`` and summarise the outcome.

    Args:
        env: The case's env (its ODD gives the scenarios); SUMO starts at the first reset.
            Its RNG is not consumed.
        policy: ``obs (N, d) float32 -> actions (N,)``; called with ``N = 1`` per step.
        n: Number of scenarios (episodes), >= 1.
        seed: Seed of :func:`scenario_set`; keep it fixed across SPCPs.
        level: Confidence level of the summary's intervals.
        progress: Show a tqdm progress bar over the episodes.

    Returns:
        The :class:`OutcomeResult`.
    """
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise ConfigError(f"n: expected an integer >= 1, got {n!r}")
    base = env.unwrapped
    assert isinstance(base, PairEnv)
    cfg = base.config
    scenarios = with_followers(scenario_set(cfg, n, seed), cfg.follower, seed)
    t0 = time.perf_counter()
    bar = tqdm(scenarios, desc="outcome", unit="ep", disable=not progress, leave=False)
    episodes = [run_episode(base, policy, ic) for ic in bar]
    wall = time.perf_counter() - t0
    table = outcome_table(scenarios, episodes)
    summary = summarize_outcome(table, base.config.case, level)
    return OutcomeResult(table, summary, seed, n, wall, tuple(scenarios), tuple(episodes))


def supporting_pov_summary(episodes: Sequence[EpisodeResult]) -> dict[str, Any] | None:
    """``outcome.json``'s ``supporting_pov`` section of a case with a second POV
    (``lead_and_cut_in``), else None: the share of episodes the POVs ended by a forbidden
    contact (and of them by kind: the supporting POV touched the VUT, the two POVs touched),
    and per safety measure against the supporting POV its median and smallest
    value over the episodes (finite values only; None where there is none)."""
    support = [e.support_measures for e in episodes if e.support_measures is not None]
    if not support:
        return None
    rows = [m.as_row() for m in support]
    measures: dict[str, dict[str, float | None]] = {}
    for name in rows[0]:
        values = np.array([r[name] for r in rows], dtype=np.float64)
        finite = values[np.isfinite(values)]
        measures[name] = {
            "median": float(np.median(finite)) if finite.size else None,
            "min": float(finite.min()) if finite.size else None,
            "n_finite": int(finite.size),
        }
    return {
        "n": len(episodes),
        "pov_failure_rate": float(np.mean([e.pov_failure for e in episodes])),
        "support_vut_rate": float(np.mean([e.support_vut_contact for e in episodes])),
        "pov_pov_rate": float(np.mean([e.pov_pov_contact for e in episodes])),
        "measures": measures,
    }
