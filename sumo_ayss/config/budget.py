"""Named compute budgets of a pipeline: training transitions, candidate cadence, seeds.

A pipeline's ``budget`` names one of :data:`BUDGETS`; the pipeline's own ``total_timesteps``,
``eval_every`` and ``grid.seeds``, where given, win over it, and ``budget: null`` leaves
every experiment's ``train`` section as its file says (the behaviour before budgets).

* ``fast`` (the default, since session 13): 5,000 transitions per run, one SPCP candidate (at
  the end), five seeds per VUT to start with and **adaptive seeding** up to seven (a case
  whose cross-play ranking has not settled gets one more seed per VUT at a time,
  :mod:`sumo_ayss.grid.adaptive`), 20,000 AYSS draws, and the learner's learning rate 5e-5,
  five times the paper's (whose 1e-5 was made for 100,000 transitions; a pipeline's own
  ``learning_rate`` wins). Chosen from the frontier (issue 40): on the braking ladder the
  learning rate moved the cheapest point at which every seed subset ranked right with
  Holm-significant ends from 10k × 7 to 5k × 5. Real 5k runs on fresh seeds ordered every
  committed ladder right (τ = 1 where the known order is recovered) with the known ends
  significant (minGap car-following at 7 seeds, careful-human cut-in at 6), telling apart
  23 of 30 adjacent pairs under Holm (``verdict`` on other fresh seeds: 26; ``quick``: 21);
  a 3-VUT ladder, both cases, in 4.4 min on this 2-core machine (docs/performance.md,
  results/budget_validation/fast/). The AYSS draws feed only the paper's reading
  (``report.mode: paper``), not the cross-play verdict; that reading wants the paper budget.
* ``verdict``: 20,000 transitions per run, a candidate every 5,000, four seeds per VUT,
  adaptive up to six, 20,000 AYSS draws, the paper's learning rate (the default before
  session 13). Chosen from the verdict's learning curve (docs/performance.md,
  ``scripts/verdict_curve.py``): on the braking and ACC ladders (six seeds each, every 4-seed
  subset) the cross-play ranking had Kendall τ = 1 with significant ends in both cases, at
  under a third of the CPU-seconds of three seeds at 100,000 (the paper's budget). Real runs
  on fresh seeds ordered every ladder right (τ = 1) with significant ends (minGap
  car-following after a fifth seed). Slower than ``fast``; its leaderboards tell a few more
  neighbours apart.
* ``quick``: 10,000 transitions per run, a candidate every 5,000, five seeds per VUT to start
  with, adaptive up to seven, 20,000 AYSS draws, the paper's learning rate: about 0.6 of
  ``verdict``'s training transitions (issue 40, session 12). On fresh seeds it ordered every
  ladder as ``verdict`` does, but its leaderboard tells fewer adjacent VUTs apart (braking
  and minGap car-following: none under Holm); ``fast`` is cheaper and tells more apart.
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
        "fast": Budget(
            5_000,
            5_000,
            5,
            "every validation ladder ordered right with the ends significant on fresh seeds, "
            "a 3-VUT ladder in under 5 minutes on 2 cores (docs/performance.md)",
            n_ayss=20_000,
            max_seeds=7,
            learning_rate=5e-5,
        ),
        "verdict": Budget(
            20_000,
            5_000,
            4,
            "the default before session 13: slower than fast, tells a few more neighbours apart",
            n_ayss=20_000,
            max_seeds=6,
        ),
        "quick": Budget(
            10_000,
            5_000,
            5,
            "half of verdict's transitions, one more seed: every ladder ordered right with the "
            "ends significant, fewer adjacent pairs told apart (docs/performance.md)",
            n_ayss=20_000,
            max_seeds=7,
        ),
        "paper": Budget(100_000, 10_000, 3, "the paper's protocol"),
    }
)
"""Budget name -> :class:`Budget`."""

DEFAULT_BUDGET = "fast"
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
