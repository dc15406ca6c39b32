"""SPCP selection: pick one candidate from a training run's evaluation table.

The paper keeps the candidate with the highest mean episode reward on the fixed evaluation
scenarios. Criteria are pluggable (:data:`CRITERIA`); ties are broken in favour of the
*earliest* candidate (fewest training steps), so the choice is deterministic.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from sumo_ayss.errors import ConfigError

Row = Mapping[str, Any]


def _mean_reward(row: Row) -> float:
    return float(row["mean_return"])


def _safe_mean_reward(row: Row) -> float:
    """Mean reward, but any crash on the evaluation set ranks below every crash-free one."""
    return float(row["mean_return"]) - 1e6 * float(row["crash_rate"] > 0)


#: Criterion name -> score (higher is better).
CRITERIA: dict[str, Callable[[Row], float]] = {
    "mean_reward": _mean_reward,
    "mean_reward_crash_free": _safe_mean_reward,
}


@dataclass(frozen=True)
class Selection:
    """The chosen candidate, its score, and a sentence saying why."""

    index: int
    step: int
    score: float
    criterion: str
    reason: str


def select_spcp(rows: Sequence[Row], criterion: str = "mean_reward") -> Selection:
    """Argmax of ``criterion`` over ``rows`` (each with ``step`` and the criterion's columns).

    Raises:
        ConfigError: unknown criterion or empty table.
    """
    if criterion not in CRITERIA:
        raise ConfigError(f"train.selection must be one of {sorted(CRITERIA)}, got {criterion!r}")
    if not rows:
        raise ConfigError("cannot select an SPCP from an empty evaluation table")
    score = CRITERIA[criterion]
    scores = [score(r) for r in rows]
    best = max(scores)
    index = scores.index(best)  # first maximum = earliest candidate
    ties = sum(1 for s in scores if s == best)
    step = int(rows[index]["step"])
    reason = (
        f"candidate at step {step} has the highest {criterion} ({best:.4f}) of {len(rows)} "
        f"candidates" + (f"; {ties} tied, the earliest wins" if ties > 1 else "")
    )
    return Selection(index, step, best, criterion, reason)
