"""Named compute budgets of a pipeline: training transitions, candidate cadence, seeds.

A pipeline's ``budget`` names one of :data:`BUDGETS`; the pipeline's own ``total_timesteps``,
``eval_every`` and ``grid.seeds``, where given, win over it, and ``budget: null`` leaves
every experiment's ``train`` section as its file says (the behaviour before budgets).

* ``verdict`` (the default): 20,000 transitions per run, a candidate every 5,000, four
  training seeds per VUT to start with and **adaptive seeding** up to six (a case whose
  cross-play ranking has not settled gets one more seed per VUT at a time,
  :mod:`sumo_ayss.grid.adaptive`), 20,000 AYSS draws. Chosen from the verdict's learning curve
  (docs/performance.md, ``scripts/verdict_curve.py``): on the braking and ACC ladders (six
  seeds each, every 4-seed subset) the cross-play ranking had Kendall τ = 1 with significant
  ends in both cases at 20,000 transitions with four seeds, at under a third of the
  CPU-seconds of three seeds at 100,000 (the paper's budget). Real runs on fresh seeds
  ordered every ladder right (τ = 1) with significant ends on all but one ladder-case with
  four seeds (minGap, car-following: p 0.11); adaptive seeding settled it at five (p 0.037).
  The AYSS draws feed only the paper's reading (``report.mode: paper``), not the cross-play
  verdict; that reading wants the paper budget.
* ``quick``: 10,000 transitions per run, a candidate every 5,000, five seeds per VUT to start
  with, adaptive up to seven, 20,000 AYSS draws: about 0.6 of ``verdict``'s training
  transitions. Chosen from the frontier (issue 40): on fresh seeds it ordered every ladder as
  ``verdict`` does (τ = 1 where the known order is recovered, the known ends significant),
  but its leaderboard tells fewer adjacent VUTs apart (braking and minGap car-following: none
  under Holm, where ``verdict`` tells all): faster, weaker claims; not the default
  (docs/performance.md, results/budget_validation/).
* ``paper``: the paper's protocol, 100,000 transitions, a candidate every 10,000, three
  seeds: what every committed study before budgets ran.

Adaptive seeding applies only when the budget chose the seeds: a pipeline that names
``grid.seeds`` (or ``--seeds``) gets exactly those, unless it also sets ``max_seeds``.

A budget is recorded in the run folders through the resolved configuration (``pipeline.json``
and each run's ``config.yaml`` hold the numbers it set).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

__all__ = [
    "BUDGETS",
    "BUDGET_CHOICES",
    "BUDGET_HELP",
    "DEFAULT_BUDGET",
    "PAPER_LEARNING_RATE",
    "Budget",
]

PAPER_LEARNING_RATE = 1e-5
"""The paper's Adam learning rate (made for 100,000 transitions): ``agent.learning_rate`` of
the shipped case configs and of :class:`~sumo_ayss.agents.hparams.DQNHyperParams`; a budget
that names no learning rate was validated with it."""


@dataclass(frozen=True)
class Budget:
    """One named budget.

    Attributes:
        total_timesteps: Training transitions per run (``train.total_timesteps``).
        eval_every: Transitions between two SPCP candidates (``train.eval_every``).
        seeds: Training seeds per VUT when ``grid.seeds`` is not given (seeds 0 .. n-1).
        summary: One line for help texts and the benchmark.
        n_ayss: AYSS Monte Carlo draws per run when neither ``evaluate.n_ayss`` nor
            ``evaluate.ayss.n_samples`` is given; None: the AYSS section's default (100,000).
        max_seeds: Adaptive seeding's cap when the budget also chose the seeds: a case
            whose cross-play ranking has not settled gets one more seed per VUT at a time,
            up to this many (:mod:`sumo_ayss.grid.adaptive`); None: a fixed grid of ``seeds``.
        learning_rate: The learner's Adam learning rate in every experiment
            (``agent.learning_rate``) when the pipeline names none; None: each
            experiment's own (the shipped configs: the paper's 1e-5, made for 100,000
            transitions).
    """

    total_timesteps: int
    eval_every: int
    seeds: int
    summary: str
    n_ayss: int | None = None
    max_seeds: int | None = None
    learning_rate: float | None = None

    @property
    def validated_learning_rate(self) -> float:
        """The learning rate the budget was validated with: its own, else the paper's."""
        return PAPER_LEARNING_RATE if self.learning_rate is None else self.learning_rate

    def describe(self) -> str:
        """``"20,000 transitions, a candidate every 5,000, 4 seeds per VUT: ..."``."""
        ayss = "" if self.n_ayss is None else f", {self.n_ayss:,} AYSS draws"
        if self.learning_rate is not None:
            ayss += f", learning rate {self.learning_rate:g}"
        seeds = f"{self.seeds} seeds per VUT"
        if self.max_seeds is not None and self.max_seeds > self.seeds:
            seeds = f"{self.seeds} seeds per VUT, up to {self.max_seeds} until the ranking settles"
        return (
            f"{self.total_timesteps:,} transitions, a candidate every {self.eval_every:,}, "
            f"{seeds}{ayss}: {self.summary}"
        )


BUDGETS: Mapping[str, Budget] = MappingProxyType(
    {
        "verdict": Budget(
            20_000,
            5_000,
            4,
            "the least compute that ordered every validation ladder right (docs/performance.md)",
            n_ayss=20_000,
            max_seeds=6,
        ),
        "quick": Budget(
            10_000,
            5_000,
            5,
            "half the transitions, one more seed: every ladder ordered right with the ends "
            "significant, fewer adjacent pairs told apart (docs/performance.md)",
            n_ayss=20_000,
            max_seeds=7,
        ),
        "fast": Budget(
            5_000,
            5_000,
            5,
            "a quarter of the transitions at 5x the paper's learning rate, one more seed "
            "(issue 40; docs/performance.md)",
            n_ayss=20_000,
            max_seeds=7,
            learning_rate=5e-5,
        ),
        "paper": Budget(100_000, 10_000, 3, "the paper's protocol"),
    }
)
"""Budget name -> :class:`Budget`."""

DEFAULT_BUDGET = "verdict"
"""The budget of a pipeline that names none."""

BUDGET_HELP = (
    "replace the config's budget: "
    + "; ".join(f"{name} = {b.describe()}" for name, b in BUDGETS.items())
    + "; none = every experiment's train section (default: the config's, else "
    + DEFAULT_BUDGET
    + ")"
)
"""``--budget`` help of ``pipeline`` and ``rank``."""

BUDGET_CHOICES = (*BUDGETS, "none")
"""Values of ``--budget`` ("none": no named budget)."""
