"""Whether a study's training can be trusted: training budget, seeds, SPCP still improving.

They read each run's :class:`Training` (from ``config.yaml``,
``eval.csv`` and ``spcp.json``, read with the run record); no file. The report writes them
at its top, the pipeline and ``rank`` print them on the terminal.

- :func:`training_status` — the state of a run's learning curve at the end (its
  :class:`Training`, read with the run): the SPCP is the last
  candidate (the curve was still at its best when training stopped: it may still be
  improving), the last candidate's mean evaluation reward is within :data:`NOISE_SE`
  standard errors of the SPCP's (a plateau: the SPCP is one of several candidates equal
  within noise), or it is clearly below (the curve peaked earlier).
- :func:`all_same` — a run whose SPCP candidates all scored the same (the choice of SPCP is
  arbitrary: one line of its problems, :func:`sumo_ayss.run_folder.read_run`);
  :func:`mixing_problems` — runs that must not be pooled into one report (a run twice, or
  one case's runs at different budgets or configurations;
  :func:`sumo_ayss.run_folder.load_runs` refuses them).
- :func:`trust_warnings` — sentences for the top of a report (and the terminal) when the
  budget is below :data:`TRUSTED_TIMESTEPS`, the seeds too few for it (no named budget of
  :mod:`sumo_ayss.config.budget` covers the protocol), or SPCPs may still be improving at
  such a budget; :func:`budget_note` — at a validated budget, what was validated and what
  was not, once.

Imports neither SUMO nor torch.
"""

from __future__ import annotations

import math
from collections import Counter, defaultdict
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sumo_ayss.config.budget import BUDGETS, Budget


@dataclass(frozen=True)
class Training:
    """A run's training budget and the state of its SPCP at the end of training.

    Attributes:
        total_timesteps: ``train.total_timesteps`` (transitions), None if unknown.
        eval_every: ``train.eval_every`` (transitions between candidates), None if unknown.
        config_key: :func:`~sumo_ayss.config.identity.config_key` of ``config.yaml``, "" if unknown.
        n_candidates: Rows of ``eval.csv``.
        spcp_step: The SPCP's training step, None if unknown.
        last_step: The last candidate's training step, None if no candidate.
        gap_se: (SPCP's mean evaluation reward − the last candidate's) / the SPCP's
            standard error (``std_return / sqrt(n_episodes)``); NaN if unknown.
        still_improving: True when the SPCP is the last candidate; None when unknown.
        learning_rate: ``agent.learning_rate``, None if unknown.
    """

    total_timesteps: int | None = None
    eval_every: int | None = None
    config_key: str = ""
    n_candidates: int = 0
    spcp_step: int | None = None
    last_step: int | None = None
    gap_se: float = math.nan
    still_improving: bool | None = None
    learning_rate: float | None = None


def _int_or_none(value: Any) -> int | None:
    return int(value) if isinstance(value, int | float) and not isinstance(value, bool) else None


def training_of(
    train: Any,
    key: str,
    rows: Sequence[Mapping[str, Any]],
    spcp_step: int | None,
    agent: Any = None,
) -> Training:
    """The :class:`Training` of a run (:func:`sumo_ayss.run_folder.read_run` computes it as
    it reads): its stored ``train`` section (None: unknown), its
    :func:`~sumo_ayss.config.identity.config_key` ("" if unknown), its ``eval.csv`` rows
    sorted by step, its SPCP's step and its stored ``agent`` section (None: unknown)."""
    total = every = None
    if isinstance(train, Mapping):
        total = _int_or_none(train.get("total_timesteps"))
        every = _int_or_none(train.get("eval_every"))
    lr = agent.get("learning_rate") if isinstance(agent, Mapping) else None
    rate = float(lr) if isinstance(lr, int | float) and not isinstance(lr, bool) else None
    if not rows or spcp_step is None:
        return Training(total, every, key, len(rows), spcp_step, learning_rate=rate)
    last = rows[-1]
    spcp = next((r for r in rows if int(r["step"]) == spcp_step), None)
    gap = math.nan
    if spcp is not None:
        se = spcp["std_return"] / math.sqrt(spcp["n_episodes"]) if spcp["n_episodes"] > 0 else 0
        diff = spcp["mean_return"] - last["mean_return"]
        gap = diff / se if se > 0 else (0.0 if diff == 0 else math.inf)
    improving = int(last["step"]) == spcp_step
    return Training(
        total, every, key, len(rows), spcp_step, int(last["step"]), gap, improving, rate
    )


def all_same(returns: NDArray[np.float64], no_signal: tuple[str, float] | None) -> str | None:
    """A sentence (after the file's name) when two or more SPCP candidates all scored exactly
    the same: their mean reward in ``eval.csv`` (``returns``), or the selection's criterion
    and score as ``spcp.json`` records it when it found no signal (``no_signal``; None when it
    did, or without the file). The opponent's actions changed nothing it is paid for (e.g. an
    ODD that pins the VUT's speed at 0), so which one is the SPCP is arbitrary; None
    otherwise."""
    if returns.size >= 2 and np.all(returns == returns[0]):
        what, value, n = "mean reward", float(returns[0]), f" {returns.size}"
    elif no_signal is not None:
        (what, value), n = no_signal, ""
    else:
        return None
    return (
        f"all{n} SPCP candidates scored exactly the same {what} ({value:.4f}): "
        "the opponent's actions changed nothing it is paid for (e.g. an ODD that pins the "
        "VUT's speed), so the SPCP is an arbitrary candidate and its scores carry no signal"
    )


def mixing_problems(
    runs: Sequence[tuple[str, str, int | None, str | Path, Training]],
) -> list[str]:
    """Sentences naming runs that must not be pooled into one report.

    Args:
        runs: ``(case, vut, seed, path, training)`` per run.

    Returns:
        One sentence per duplicate (case, VUT, seed) and per case whose runs have different
        budgets or configurations (besides VUT and seed); empty when the runs can be pooled.
    """
    out = []
    by_key: dict[tuple[str, str, int | None], list[str | Path]] = defaultdict(list)
    for case, vut, seed, path, _ in runs:
        by_key[(case, vut, seed)].append(path)
    for (case, vut, seed), paths in by_key.items():
        if len(paths) > 1:
            out.append(
                f"{case} {vut} seed {seed} appears {len(paths)} times: "
                + ", ".join(str(p) for p in paths)
            )
    by_case: dict[str, dict[tuple[int | None, int | None, str], list[str | Path]]] = defaultdict(
        lambda: defaultdict(list)
    )
    for case, _, _, path, t in runs:
        by_case[case][(t.total_timesteps, t.eval_every, t.config_key)].append(path)
    for case, groups in by_case.items():
        if len(groups) < 2:
            continue
        parts = []
        for (total, every, key), paths in groups.items():
            parts.append(
                f"total_timesteps={total}, eval_every={every}, config {key or '?'}: "
                + ", ".join(str(p) for p in paths)
            )
        out.append(
            f"{case}: runs with different training budgets or configurations — " + "; ".join(parts)
        )
    return out


TRUSTED_TIMESTEPS = min(b.total_timesteps for b in BUDGETS.values())
"""Training transitions per run below which verdicts are flagged as not to be trusted: the
smallest named budget's (``fast``, 5,000 at its learning rate), the least that ordered every
validation ladder right with its seeds (docs/performance.md)."""


def _rates_fit(b: Budget, rates: Iterable[float | None]) -> bool:
    """Whether every known learning rate is the one ``b`` was validated with."""
    return all(r is None or math.isclose(r, b.validated_learning_rate, rel_tol=1e-9) for r in rates)


def _sized(total: int, seeds_per_vut: int) -> list[tuple[str, Budget]]:
    """The named budgets whose transitions and seeds a protocol meets."""
    return [
        (name, b)
        for name, b in BUDGETS.items()
        if total >= b.total_timesteps and seeds_per_vut >= b.seeds
    ]


NOISE_SE = 2.0
"""The last candidate counts as "within noise" of the SPCP when its mean evaluation reward
is less than this many standard errors (SPCP's ``std_return / sqrt(n_episodes)``) lower."""


def training_status(t: Training) -> str:
    """A run's SPCP state (:class:`Training`) in one phrase, for a
    table cell."""
    if t.still_improving is None:
        return "unknown"
    if t.still_improving:
        return "may still improve: SPCP is the last candidate"
    if t.gap_se < NOISE_SE:
        return f"plateau: last candidate within {t.gap_se:.1f} SE of the SPCP"
    return f"peaked: last candidate {t.gap_se:.1f} SE below the SPCP"


def fewest_seeds(keys: Iterable[tuple[str, str]]) -> int | None:
    """The fewest runs (training seeds) of any (case, VUT) among ``keys``, one key per run;
    None without runs."""
    counts = Counter(keys)
    return min(counts.values()) if counts else None


def validated_budget(
    runs: Sequence[tuple[str, Training]], seeds_per_vut: int | None
) -> tuple[str, Budget] | None:
    """The largest named budget (:data:`~sumo_ayss.config.budget.BUDGETS`) whose transitions
    and seeds ``runs`` meet (every run's budget known) at the learning rate it was validated
    with (where a run's is known), or None."""
    totals = [t.total_timesteps for _, t in runs]
    if not totals or seeds_per_vut is None or any(t is None for t in totals):
        return None
    total = min(t for t in totals if t is not None)
    rates = [t.learning_rate for _, t in runs]
    met = [(name, b) for name, b in _sized(total, seeds_per_vut) if _rates_fit(b, rates)]
    return max(met, key=lambda nb: nb[1].total_timesteps) if met else None


def trust_warnings(
    runs: Sequence[tuple[str, Training]], seeds_per_vut: int | None = None
) -> list[str]:
    """Sentences that say why verdicts built on ``runs`` (``(label, training)``) are weak.

    Empty when every run trained at least :data:`TRUSTED_TIMESTEPS` transitions and the
    protocol (the smallest budget, ``seeds_per_vut`` when given: the fewest seeds of any VUT)
    meets one of the named budgets validated on ladders (:data:`~sumo_ayss.config.budget.
    BUDGETS`: at least its transitions and its seeds). SPCPs that were the last candidate of
    their training are a warning only at a budget no ladder validated: at a validated one the
    verdict curve found the ranking unchanged by more training, and :func:`budget_note` says
    so (issue 35: a warning on every default run taught users to ignore it).
    """
    out = []
    budgets_known = {t.total_timesteps for _, t in runs if t.total_timesteps is not None}
    small = sorted(b for b in budgets_known if b < TRUSTED_TIMESTEPS)
    if small:
        budgets = ", ".join(f"{b:,}" for b in small)
        out.append(
            f"Small training budget: {budgets} transitions per run, below the "
            f"{TRUSTED_TIMESTEPS:,} of the smallest budget that ordered every validation "
            "ladder right. The SPCPs are undertrained; the verdicts and rankings below are "
            "NOT to be trusted (a demonstration of the machinery, not a result)."
        )
    elif budgets_known and seeds_per_vut is not None:
        total = min(budgets_known)
        sized = _sized(total, seeds_per_vut)
        rates = sorted({t.learning_rate for _, t in runs if t.learning_rate is not None})
        if sized and not any(_rates_fit(b, rates) for _, b in sized):
            validated = "; ".join(f"{b.validated_learning_rate:g} ({name})" for name, b in sized)
            out.append(
                f"Learning rate {', '.join(f'{r:g}' for r in rates)} at {total:,} transitions "
                f"per run with {seeds_per_vut} seeds per VUT: the budgets validated on ladders "
                f"at this many transitions and seeds trained at {validated}. In a short run the "
                "learning rate sets how strong the opponents get; no ladder validated this "
                "protocol's ranking."
            )
        if not sized:
            validated = "; ".join(
                f"{b.seeds} at {b.total_timesteps:,} ({name})" for name, b in BUDGETS.items()
            )
            out.append(
                f"Few training seeds: {seeds_per_vut} per VUT at {total:,} transitions per "
                f"run, fewer than a protocol validated on ladders uses (seeds at transitions: "
                f"{validated}). With fewer seeds the tests miss real differences more often: "
                "a 'no significant difference' here is weak evidence."
            )
    unknown = [label for label, t in runs if t.total_timesteps is None]
    if unknown:
        out.append(
            f"Training budget unknown (no readable train.total_timesteps in config.yaml) for "
            f"{len(unknown)} of {len(runs)} runs: " + ", ".join(unknown) + "."
        )
    improving = [label for label, t in runs if t.still_improving]
    if improving and (out or validated_budget(runs, seeds_per_vut) is None):
        out.append(
            f"{len(improving)} of {len(runs)} SPCPs may still be improving (the SPCP is the "
            "last candidate of its training), at a budget whose ranking no ladder validated: "
            "more training could change them and the verdicts (the runs are listed under "
            "Inputs)."
        )
    return out


def budget_note(runs: Sequence[tuple[str, Training]], seeds_per_vut: int | None) -> str | None:
    """What the evidence for this protocol's budget covers and what it does not, one
    paragraph, at a budget validated on ladders (:func:`validated_budget`) with nothing to
    warn about (:func:`trust_warnings` empty); None otherwise."""
    found = validated_budget(runs, seeds_per_vut)
    if found is None or trust_warnings(runs, seeds_per_vut):
        return None
    name, b = found
    total = min(t.total_timesteps or 0 for _, t in runs)
    rate = f", learning rate {b.learning_rate:g}" if b.learning_rate is not None else ""
    curve = (
        ", and the verdict curve found the same order at every budget it tried, from 10,000 "
        "to 100,000 transitions"
        if b.total_timesteps >= 10_000
        else " on fresh seeds with the known ends significant"
    )
    improving = sum(1 for _, t in runs if t.still_improving)
    last = (
        f"{improving} of {len(runs)} SPCPs were the last candidate of their training (listed "
        "under Inputs); on the ladders the ranking did not depend on that"
        if improving
        else "every SPCP had peaked or reached a plateau"
    )
    paper = (
        "; the paper mode's AYSS reading was validated at the paper budget only"
        if name != "paper"
        else ""
    )
    return (
        f"Budget: {total:,} transitions per run and {seeds_per_vut} or more seeds per VUT, at "
        f"least the '{name}' budget ({b.total_timesteps:,} transitions, {b.seeds} seeds{rate}). "
        "Validated at this budget: the cross-play ranking of the validation ladders (braking, "
        "ACC time gap, minGap, time headway; reaction time in cut-in) came out in their known "
        f"order{curve} (docs/performance.md). Not validated: that each SPCP "
        "has converged ("
        f"{last}); VUT kinds unlike the ladders' (the reaction-time ladder's car-following "
        f"order is inverted at every budget){paper}."
    )


def improving_runs(runs: Sequence[tuple[str, Training]]) -> list[str]:
    """The labels of the runs whose SPCP is the last candidate of their training."""
    return [label for label, t in runs if t.still_improving]
