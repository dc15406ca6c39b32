"""Early stopping of a run: stop training once its SPCP candidates stop moving.

The rule itself and its check on synthetic nulls are pure
(:mod:`sumo_ayss.analysis.early_stop`); here it is applied to a run's evaluation table.

A run's SPCP is the best of its candidates (:func:`~sumo_ayss.training.selection.select_spcp`),
each scored on the same fixed evaluation scenarios. Once the last ``patience`` candidates
have not beaten the best candidate before them by more than ``margin_se`` standard errors of
that candidate's evaluation mean (its ``std_return`` over the square root of its
``n_episodes``), more training is unlikely to change the SPCP beyond what the evaluation can
tell apart, and the run stops (:func:`stop_decision`). The SPCP is then selected as always,
among the candidates trained so far: a stopped run is the prefix of the same run trained to
the end (same seed, same transitions), so stopping changes which candidates exist, never a
candidate.

With ``patience`` k the earliest stop is after k + 1 candidates. A criterion whose score is
not the mean return (``mean_reward_crash_free`` puts every crashing candidate 10^6 below the
crash-free ones) still uses the mean return's standard error: a jump between the two groups
is always an improvement.

Configured by ``train.early_stop_patience`` (None, the default: train to
``total_timesteps``) and ``train.early_stop_margin_se``; validated on synthetic candidate
curves and on the committed runs' evaluation tables (docs/performance.md, "Stop a run when
its candidates stop moving").
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from sumo_ayss.analysis.early_stop import evaluation_se, stop_index
from sumo_ayss.training.selection import CRITERIA
from sumo_ayss.util.validation import check_choice, check_int, check_number

if TYPE_CHECKING:
    from sumo_ayss.config.experiment import TrainConfig

__all__ = ["StopDecision", "check_early_stop", "rule_stops", "stop_decision"]

logger = logging.getLogger(__name__)


def check_early_stop(patience: Any, margin_se: Any, where: str = "train") -> None:
    """Refuse a bad rule, naming the field (``train.early_stop_patience`` must be an int >= 1
    or null, ``train.early_stop_margin_se`` a finite number >= 0).

    Raises:
        ConfigError: naming the field and what it must be.
    """
    check_int(f"{where}.early_stop_patience", patience, 1, none_ok=True)
    check_number(f"{where}.early_stop_margin_se", margin_se, 0.0)


@dataclass(frozen=True)
class StopDecision:
    """Whether a run stops after its latest candidate, and why.

    Attributes:
        stop: True when the rule stops the run now.
        step: The latest candidate's step.
        reference_step: The step of the best candidate before the last ``patience``.
        reason: One sentence for the log and ``spcp.json``.
    """

    stop: bool
    step: int
    reference_step: int | None
    reason: str


def stop_decision(
    rows: Sequence[Mapping[str, Any]], criterion: str, patience: int, margin_se: float
) -> StopDecision:
    """The rule (:func:`stop_index`) applied to a run's evaluation table so far.

    A table on which the rule would have stopped earlier stops now (the trainer asks after
    every candidate, so for it the stop is always at the latest one).

    Args:
        rows: The evaluation table's rows in training order (``step``, ``mean_return``,
            ``std_return``, ``n_episodes`` and the criterion's columns).
        criterion: The SPCP criterion (:data:`~sumo_ayss.training.selection.CRITERIA`).
        patience: ``train.early_stop_patience``.
        margin_se: ``train.early_stop_margin_se``.

    Raises:
        ConfigError: An unknown criterion or a bad rule, naming the field.
    """
    check_choice("train.selection", criterion, sorted(CRITERIA))
    check_early_stop(patience, margin_se)
    if not rows:
        return StopDecision(False, 0, None, "no candidate yet")
    score = CRITERIA[criterion]
    scores = [score(r) for r in rows]
    ses = [evaluation_se(r) for r in rows]
    step = int(rows[-1]["step"])
    at = stop_index(scores, ses, patience, margin_se)
    if at is None:
        return StopDecision(False, step, None, "still improving")
    ref = max(range(at - patience + 1), key=lambda i: (scores[i], -i))
    reason = (
        f"early stop after the candidate at step {step}: none of the last {patience} "
        f"candidates beat the best before them (step {int(rows[ref]['step'])}, {criterion} "
        f"{scores[ref]:.4f}) by more than {margin_se:g} standard errors ({ses[ref]:.4f} each)"
    )
    return StopDecision(True, step, int(rows[ref]["step"]), reason)


def rule_stops(
    train: TrainConfig, rows: Sequence[Mapping[str, Any]], run: str
) -> StopDecision | None:
    """The decision when ``train``'s rule (``train.early_stop_patience``) stops the run
    ``run`` after ``rows``, logged; None when the rule is off or does not stop it."""
    if train.early_stop_patience is None:
        return None
    decision = stop_decision(
        rows, train.selection, train.early_stop_patience, train.early_stop_margin_se
    )
    if not decision.stop:
        return None
    logger.info("%s: %s", run, decision.reason)
    return decision
