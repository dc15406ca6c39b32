"""SPCP selection: pick one candidate from a training run's evaluation table.

The paper keeps the candidate with the highest mean episode reward on the fixed evaluation
scenarios. Criteria are pluggable (:data:`CRITERIA`); ties are broken in favour of the
*earliest* candidate (fewest training steps), so the choice is deterministic.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from sumo_ayss.util.errors import ConfigError

logger = logging.getLogger(__name__)

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
    """The chosen candidate, its score, and a sentence saying why.

    ``no_signal``: every one of two or more candidates scored the same, so the evaluation
    could not tell them apart and the earliest was taken (e.g. an ODD that pins the VUT at
    0 m/s: no opponent earns any reward); written to ``spcp.json`` with the rest.
    """

    index: int
    step: int
    score: float
    criterion: str
    reason: str
    no_signal: bool = False


def select_spcp(rows: Sequence[Row], criterion: str = "mean_reward", run: str = "") -> Selection:
    """Argmax of ``criterion`` over ``rows`` (each with ``step`` and the criterion's columns).

    When two or more candidates all score the same, the selection has no signal: it says so
    in the reason and :attr:`Selection.no_signal`, and logs a warning naming ``run`` (the
    run folder).

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
    no_signal = len(rows) > 1 and ties == len(rows)
    if no_signal:
        reason += "; no signal: every candidate scored the same"
        logger.warning(
            "%s: all %d SPCP candidates scored %.4f on %s: the evaluation cannot tell them "
            "apart (no signal; e.g. an ODD in which no opponent can earn reward), so the "
            "earliest (step %d) is the SPCP; check env.odd and env.reward",
            run or "this run",
            len(rows),
            best,
            criterion,
            step,
        )
    return Selection(index, step, best, criterion, reason, no_signal)
