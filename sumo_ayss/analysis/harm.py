"""The harm score: how much harm an opponent brought about against a VUT, monotone in harm.

Every mode that reads outcomes (cross-play, exposure) scores a VUT by the mean *harm* of its
episodes, lower = safer. One episode's harm, a number in [0, 1]:

* an episode without a collision: its near-miss pay (the adversarial reward paid,
  ``sum of alpha_A·R_A``, the collision term left out) over the most an episode can pay,
  ``alpha_A · decisions`` (the peak near-miss at every decision): ``pay / max_pay``;
* an episode that ended in a collision: **1**, the worst there is.

Why not the mean episode *reward* (the score before issue 22): a collision pays the opponent
``-alpha_collision`` and ends its episode, so an opponent that crashes into a weak VUT
extracts *less* reward from it than from a strong one, and the VUT that is crashed into most
ranks safest (a braking ladder came out inverted in cut-in). The reward is built to train an
adversary that stays safe; it is not a measure of the harm done to the VUT.

Properties (``tests/analysis/test_harm.py``), under the same opponents and scenarios:

* a collision is never less harmful than any episode without one (harm 1 >= pay / max_pay,
  because ``R_A <= 1``), so turning any episode into a collision never lowers a VUT's score;
* among episodes without a collision, more near-miss pay (the opponent got closer, longer)
  is more harm;
* so a VUT that is crashed into more often, or lets the opponent closer, never scores safer.

A lexicographic score (crash rate first, near-miss pay second) has the same order on
dominating pairs but makes the test's decision jump between two statistics; the harm is one
number per episode, averaged like the reward was, so the same paired tests apply unchanged.
The collision weight 1 is the smallest that keeps a crash at least as bad as every near-miss;
a larger one would be a choice about how many near-misses a crash is worth, which the
method does not make.

Imports neither SUMO nor torch; reads no file.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
import numpy.typing as npt

from sumo_ayss.analysis.hazards import overbraking_flags
from sumo_ayss.analysis.stats import wilson_interval
from sumo_ayss.util.errors import ConfigError

__all__ = [
    "HARM_RANGE",
    "MOBILITY_FLOOR",
    "EpisodeStats",
    "HarmScale",
    "ScorableRun",
    "episode_harm",
    "episode_stats",
    "harm_scale_of",
    "mobility_flags",
    "run_episodes",
]

HARM_RANGE = (0.0, 1.0)
"""The possible range of a harm per episode (and of any mean of harms): intervals of a
harm score are clipped to it."""

#: A VUT whose mobility (mean speed under the same opponents and scenarios) is below this
#: share of the median VUT's is flagged: it may be "safe" by standing still.
MOBILITY_FLOOR = 0.8


@dataclass(frozen=True)
class HarmScale:
    """The constants that turn a table's episodes into harm.

    Attributes:
        max_episode_pay: The most near-miss pay an episode can hold, ``alpha_A ·
            decisions`` (25 with the defaults): the pay of the peak near-miss at every
            decision.
        collision_penalty: ``alpha_collision``: the reward of a collision step; recovers the
            near-miss pay from ``episode_return`` in tables written before they held it.
    """

    max_episode_pay: float
    collision_penalty: float

    def __post_init__(self) -> None:
        for name in ("max_episode_pay", "collision_penalty"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ConfigError(f"harm scale: {name} must be a finite number > 0, got {value}")

    def near_miss_pay(
        self, near_miss_pay: npt.ArrayLike, episode_return: npt.ArrayLike, collided: npt.ArrayLike
    ) -> npt.NDArray[np.float64]:
        """The recorded pay where there is one, else ``return + alpha_C`` for a collision
        and ``return`` otherwise (a collision step pays ``-alpha_C`` and no R_A)."""
        pay = np.asarray(near_miss_pay, dtype=np.float64)
        ret = np.asarray(episode_return, dtype=np.float64)
        crash = np.asarray(collided, dtype=bool)
        derived = ret + np.where(crash, self.collision_penalty, 0.0)
        return np.where(np.isnan(pay), derived, pay)


@dataclass(frozen=True)
class EpisodeStats:
    """One run's outcome episodes (its own SPCP against its VUT), reduced.

    Attributes:
        mean_harm: Mean harm per episode, in [0, 1].
        crashes: Episodes that ended in a collision.
        n: Episodes.
        mobility: Mean of the episodes' VUT mean speed [m/s]; NaN: not recorded.
    """

    mean_harm: float
    crashes: int
    n: int
    mobility: float

    @classmethod
    def of(
        cls, harm: npt.ArrayLike, collided: npt.ArrayLike, mobility: npt.ArrayLike
    ) -> EpisodeStats:
        h = np.asarray(harm, dtype=np.float64)
        mob = np.asarray(mobility, dtype=np.float64)
        if h.size == 0:
            raise ConfigError("episode stats: no episodes")
        return cls(
            mean_harm=float(h.mean()),
            crashes=int(np.asarray(collided, dtype=bool).sum()),
            n=int(h.size),
            mobility=float(mob.mean()) if np.all(np.isfinite(mob)) else math.nan,
        )


def episode_harm(
    near_miss_pay: npt.ArrayLike, collided: npt.ArrayLike, max_episode_pay: float
) -> npt.NDArray[np.float64]:
    """Harm of each episode in [0, 1]: 1 for a collision, else ``pay / max_episode_pay``.

    Args:
        near_miss_pay: Sum of ``alpha_A·R_A`` per episode (>= 0).
        collided: Whether each episode ended in a collision.
        max_episode_pay: :attr:`HarmScale.max_episode_pay`, > 0.

    Raises:
        ConfigError: If the shapes differ, a pay is negative or not finite, or a pay
            exceeds ``max_episode_pay`` (by more than rounding): then the scale is wrong.
    """
    pay = np.asarray(near_miss_pay, dtype=np.float64)
    crash = np.asarray(collided, dtype=bool)
    if pay.shape != crash.shape:
        raise ConfigError(f"harm: {pay.shape} pays but {crash.shape} collision flags")
    if not np.all(np.isfinite(pay)) or np.any(pay < -1e-9):
        raise ConfigError("harm: near-miss pay must be finite and >= 0")
    if np.any(pay > max_episode_pay * (1 + 1e-9)):
        raise ConfigError(
            f"harm: a near-miss pay of {float(pay.max()):g} exceeds the most an episode can "
            f"pay ({max_episode_pay:g} = alpha_A · decisions): the harm scale does not match "
            "the runs' reward or episode length"
        )
    return np.where(crash, 1.0, np.clip(pay / max_episode_pay, 0.0, 1.0))


def mobility_flags(mobility: dict[str, float], floor: float = MOBILITY_FLOOR) -> dict[str, bool]:
    """Which VUTs move far less than the others: mean speed < ``floor`` × the median VUT's.

    Args:
        mobility: VUT -> its mean speed [m/s] over the same episodes (NaN: not recorded).
        floor: Share of the median below which a VUT is flagged, in (0, 1].

    Returns:
        VUT -> flagged; never flagged without at least two recorded values.
    """
    if not 0 < floor <= 1:
        raise ConfigError(f"mobility floor must be in (0, 1], got {floor}")
    known = [v for v in mobility.values() if math.isfinite(v)]
    if len(known) < 2:
        return {name: False for name in mobility}
    median = float(np.median(known))
    return {name: math.isfinite(v) and v < floor * median for name, v in mobility.items()}


@dataclass(frozen=True)
class VutOutcome:
    """What a ranking shows beside a VUT's harm score: its crashes and its mobility.

    Attributes:
        crashes: Episodes that ended in a collision.
        episodes: Episodes behind the numbers.
        crash_lo: Lower end of the crash rate's Wilson interval, in [0, 1].
        crash_hi: Upper end, in [0, 1].
        mobility: Mean VUT speed over the episodes [m/s]; NaN: not recorded.
        timid: Mobility below :data:`MOBILITY_FLOOR` × the median VUT's
            (:func:`mobility_flags`): it may be "safe" by standing still. It misses a VUT
            that brakes for nothing in car-following, where the leader sets the pace:
            ``overbraking`` catches that one.
        hazards: The hazards it caused, means over the same episodes
            (:func:`~sumo_ayss.analysis.hazards.vut_hazards`); None: not recorded.
        overbraking: It braked for nothing far more than the others
            (:func:`~sumo_ayss.analysis.hazards.overbraking_flags`).
    """

    crashes: int
    episodes: int
    crash_lo: float
    crash_hi: float
    mobility: float
    timid: bool
    hazards: Mapping[str, float] | None = None
    overbraking: bool = False

    @property
    def crash_rate(self) -> float:
        return self.crashes / self.episodes if self.episodes else math.nan


def vut_outcomes(
    counts: dict[str, tuple[int, int, float]],
    level: float = 0.95,
    hazards: Mapping[str, Mapping[str, float]] | None = None,
) -> dict[str, VutOutcome]:
    """Per VUT ``(crashes, episodes, mobility)`` -> its :class:`VutOutcome`.

    ``hazards``: per VUT, the hazards it caused (cross-play's); their unjustified braking
    sets the OVER-BRAKING flag. The crash rate's interval is Wilson's over the episodes
    pooled: it stays inside [0, 1] and is informative at 0 crashes, but treats the episodes
    as independent, which episodes of one opponent are not (it is a description beside the
    score; the verdict's test is the score's, over training-seed blocks).
    """
    flags = mobility_flags({v: mob for v, (_c, _n, mob) in counts.items()})
    dv = {v: (hazards or {}).get(v, {}).get("unjustified_dv_mps", math.nan) for v in counts}
    over = overbraking_flags(dv)
    out = {}
    for vut, (crashes, n, mob) in counts.items():
        lo, hi = wilson_interval(crashes, n, level) if n else (math.nan, math.nan)
        mine = None if hazards is None else hazards.get(vut)
        out[vut] = VutOutcome(crashes, n, lo, hi, mob, flags[vut], mine, over[vut])
    return out


# --------------------------------------------------------------------------- a run, scored


class RewardLike(Protocol):
    """The reward weights the harm scale needs (:class:`sumo_ayss.config.RewardConfig`)."""

    @property
    def alpha_adversarial(self) -> float: ...

    @property
    def alpha_collision(self) -> float: ...


class ColumnsLike(Protocol):
    """A table as read: ``name -> array`` (:class:`sumo_ayss.records.table.Table`)."""

    @property
    def columns(self) -> Mapping[str, Any]: ...


class ScorableRun(Protocol):
    """What scoring a run's outcome episodes reads of it, as stored
    (:class:`sumo_ayss.run_folder.RunRecord` is one)."""

    @property
    def reward(self) -> RewardLike | None: ...

    @property
    def decisions_per_episode(self) -> int | None: ...

    @property
    def outcome_table(self) -> ColumnsLike | None: ...


def harm_scale_of(run: ScorableRun) -> HarmScale | None:
    """The harm scale of a run: ``alpha_A ·`` decisions per episode, and ``alpha_C``; None
    when its ``config.yaml`` gives no reward or episode timing.

    Raises:
        ConfigError: If the weights do not make a scale (:class:`HarmScale`).
    """
    if run.reward is None or run.decisions_per_episode is None:
        return None
    return HarmScale(
        run.reward.alpha_adversarial * run.decisions_per_episode, run.reward.alpha_collision
    )


def episode_stats(columns: Mapping[str, Any], scale: HarmScale) -> EpisodeStats:
    """An outcome table's columns reduced to harm, crashes and mobility (a table written
    before ``near_miss_pay`` existed derives it from the return).

    Raises:
        ConfigError: If the table holds no episode or a pay does not fit the scale.
    """
    from sumo_ayss.analysis.hazards import harm_crash

    c = columns
    pay = scale.near_miss_pay(c["near_miss_pay"], c["episode_return"], c["collided"])
    crash = harm_crash(c["collided"], c["rear_end_unjustified"])  # issue 33
    harm = episode_harm(pay, crash, scale.max_episode_pay)
    return EpisodeStats.of(harm, c["collided"], c["vut_mean_speed_mps"])


def run_episodes(run: ScorableRun) -> EpisodeStats | None:
    """A run's outcome episodes (``outcome.csv``) scored on its harm scale, or None without
    a table or a scale.

    Raises:
        ConfigError: If the scale is invalid or the table does not fit it.
    """
    scale = harm_scale_of(run)
    if run.outcome_table is None or scale is None:
        return None
    return episode_stats(run.outcome_table.columns, scale)
