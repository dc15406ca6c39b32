"""The early-stopping rule of a training run, and its check on synthetic null grids.

**The rule** (:func:`stop_index`): a run's candidates are scored on the same fixed evaluation
scenarios; after candidate ``j`` the reference is the best candidate before the last
``patience`` (the first maximum, as SPCP selection breaks ties), and the run stops when
none of the last ``patience`` candidates beats it by more than ``margin_se`` standard errors
of its evaluation mean (:func:`evaluation_se`). The trainer applies it after every candidate
(:mod:`sumo_ayss.training.early_stop`).

**Why it keeps a ranking's false-positive rate** (:func:`null_false_claims`). Cross-play
drives every VUT against the same opponents of a seed block, so an opponent's strength is
common to all VUTs and cancels in their paired differences, except where an opponent is
better against its *own* VUT (it was trained there). When every VUT is equally safe, the
runs against each VUT are alike in distribution, and a rule that reads only a run's own
candidates stops them alike: the grid stays exchangeable between VUTs and the paired tests
keep their level. A rule that stopped one VUT's runs earlier than the others' would not:
its own opponents would be weaker and it would look safer. The synthetic grids here model
that (learning curves, evaluation noise, the own-VUT advantage) and count, over null grids,
how often the product's ranking (:func:`~sumo_ayss.analysis.seeds.rank_seeds`: paired t,
Holm over the adjacent pairs) makes any "safer than" claim, with every run trained to the
end and with every run stopped by the rule.

Pure: numpy and this package's analysis only.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from sumo_ayss.analysis.seeds import SeedScores, rank_seeds

__all__ = ["NullClaims", "evaluation_se", "null_false_claims", "stop_index"]


def evaluation_se(row: Mapping[str, Any]) -> float:
    """Standard error of a candidate's mean return: ``std_return / sqrt(n_episodes)``
    (0 for fewer than two episodes or a missing spread)."""
    n = int(row.get("n_episodes", 0) or 0)
    std = float(row.get("std_return", 0.0) or 0.0)
    if n < 2 or not math.isfinite(std):
        return 0.0
    return std / math.sqrt(n)


def stop_index(
    scores: Sequence[float], ses: Sequence[float], patience: int, margin_se: float
) -> int | None:
    """The 0-based index of the candidate after which the rule stops the run, or None.

    After candidate ``j`` (``j >= patience``), the reference is the best of candidates
    ``0 .. j - patience`` (the first maximum); the run stops when none of the last
    ``patience`` candidates scores above ``reference + margin_se * se(reference)``.

    Args:
        scores: Each candidate's selection score, in training order (higher is better).
        ses: Each candidate's evaluation standard error (same length).
        patience: Candidates without improvement before stopping (>= 1).
        margin_se: The improvement that counts, in standard errors (>= 0).

    Returns:
        The first such ``j``; None if the rule never stops on these candidates.

    Raises:
        ValueError: If the lengths differ.

    Example:
        ``stop_index([10, 12, 12.1, 11.9], [0.5] * 4, 2, 1.0)`` is 3: after candidate 3,
        neither 12.1 nor 11.9 beats 12 + 0.5.
    """
    if len(scores) != len(ses):
        raise ValueError(f"{len(scores)} scores but {len(ses)} standard errors")
    best = 0
    for j in range(patience, len(scores)):
        ref_end = j - patience  # the reference is the best of 0 .. ref_end
        if scores[ref_end] > scores[best]:
            best = ref_end
        window = scores[ref_end + 1 : j + 1]
        if max(window) <= scores[best] + margin_se * ses[best]:
            return j
    return None


@dataclass(frozen=True)
class NullClaims:
    """What :func:`null_false_claims` counted.

    Attributes:
        grids: Null grids drawn.
        rate_full: Share of grids with at least one significant adjacent claim (Holm), every
            run trained to its last candidate.
        rate_stopped: The same with every run stopped by the rule.
        stopped_share: Share of runs the rule stopped before their last candidate.
        mean_budget: Mean share of the candidates a stopped-or-not run trained.
    """

    grids: int
    rate_full: float
    rate_stopped: float
    stopped_share: float
    mean_budget: float


def null_false_claims(
    rng: np.random.Generator,
    *,
    grids: int,
    vuts: int,
    seeds: int,
    patience: int,
    margin_se: float,
    candidates: int = 8,
    eval_se: float = 0.72,
    own_advantage: float = 0.3,
    cell_sd: float = 0.02,
    biased_vut: bool = False,
) -> NullClaims:
    """Family-wise false-claim rate of the cross-play ranking on synthetic null grids.

    Each run (VUT ``v``, seed ``s``) has a learning curve over ``candidates`` candidates:
    true quality ``Q (1 - exp(-t / tau)) + jitter`` (Q ~ N(15, 3), tau log-normal around a
    third of the run, jitter N(0, 1) per candidate), observed with evaluation noise
    N(0, ``eval_se``) (the median standard error of the committed runs' candidates is
    0.72). The SPCP is the best observed candidate of the run's trained prefix. Harm of
    VUT ``u`` against opponent (``v``, ``s``): ``0.02 · quality · (1 + own_advantage · [u = v])``
    plus N(0, ``cell_sd``); a VUT's block score is its mean over the block's opponents.
    Every VUT is equally safe, so every claim is false.

    Args:
        rng: The random generator.
        grids: Null grids to draw.
        vuts: VUTs per grid.
        seeds: Seed blocks per grid.
        patience: The rule's ``patience``.
        margin_se: The rule's ``margin_se``.
        candidates: Candidates per run at the cap.
        eval_se: Evaluation noise of a candidate's score.
        own_advantage: How much more an opponent extracts from its own VUT.
        cell_sd: Noise of one cross-play cell's mean harm.
        biased_vut: Stop the runs of VUT 0 after their first candidate whatever the rule
            says (a VUT-dependent rule; the check must catch it).

    Returns:
        The :class:`NullClaims` counts.
    """
    t = np.arange(1, candidates + 1) / candidates
    false_full = false_stopped = 0
    stopped = runs = 0
    budget = 0.0
    names = [f"v{i}" for i in range(vuts)]
    for _ in range(grids):
        strength = np.empty((2, vuts, seeds))
        for v in range(vuts):
            for s in range(seeds):
                q = rng.normal(15.0, 3.0)
                tau = rng.lognormal(math.log(0.3), 0.6)
                quality = q * (1.0 - np.exp(-t / tau)) + rng.normal(0.0, 1.0, candidates)
                observed = quality + rng.normal(0.0, eval_se, candidates)
                at = stop_index(observed.tolist(), [eval_se] * candidates, patience, margin_se)
                if biased_vut and v == 0:
                    at = 0
                end = candidates - 1 if at is None else at
                runs += 1
                stopped += at is not None
                budget += (end + 1) / candidates
                strength[0, v, s] = quality[int(np.argmax(observed))]
                strength[1, v, s] = quality[int(np.argmax(observed[: end + 1]))]
        for k in range(2):
            own = np.eye(vuts)[:, :, None] * own_advantage  # [u, v, 1]
            harm = 0.02 * strength[k][None, :, :] * (1.0 + own)  # [u, v, s]
            harm = harm + rng.normal(0.0, cell_sd, harm.shape)
            block = harm.mean(axis=1)  # [u, s]
            scores = [
                SeedScores(names[u], {s: float(block[u, s]) for s in range(seeds)})
                for u in range(vuts)
            ]
            rows, _ = rank_seeds(scores, higher_is_safer=False)
            if any(bool(r.significant_vs_next) for r in rows[:-1]):
                if k == 0:
                    false_full += 1
                else:
                    false_stopped += 1
    return NullClaims(
        grids=grids,
        rate_full=false_full / grids,
        rate_stopped=false_stopped / grids,
        stopped_share=stopped / runs,
        mean_budget=budget / runs,
    )
