"""Named compute budgets of a pipeline: training transitions, candidate cadence, seeds.

A pipeline's ``budget`` names one of :data:`BUDGETS`; the pipeline's own ``total_timesteps``,
``eval_every`` and ``grid.seeds``, where given, win over it, and ``budget: null`` leaves
every experiment's ``train`` section as its file says (the behaviour before budgets).

* ``verdict`` (the default): 20,000 transitions per run, a candidate every 5,000, four
  training seeds per VUT. Chosen from the verdict's learning curve (docs/performance.md,
  ``scripts/verdict_curve.py``): on the braking and ACC ladders (six seeds each, every
  4-seed subset) the cross-play ranking had Kendall τ = 1 with significant ends in both
  cases from 10,000 transitions on with four seeds, where three seeds at 100,000 (the paper's
  budget) took about 3.5 times the CPU-seconds.
* ``paper``: the paper's protocol, 100,000 transitions, a candidate every 10,000, three
  seeds: what every committed study before budgets ran.

A budget is recorded in the run folders through the resolved configuration (``pipeline.json``
and each run's ``config.yaml`` hold the numbers it set).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

__all__ = ["BUDGETS", "BUDGET_CHOICES", "BUDGET_HELP", "DEFAULT_BUDGET", "Budget"]


@dataclass(frozen=True)
class Budget:
    """One named budget.

    Attributes:
        total_timesteps: Training transitions per run (``train.total_timesteps``).
        eval_every: Transitions between two SPCP candidates (``train.eval_every``).
        seeds: Training seeds per VUT when ``grid.seeds`` is not given (seeds 0 .. n-1).
        summary: One line for help texts and the benchmark.
    """

    total_timesteps: int
    eval_every: int
    seeds: int
    summary: str

    def describe(self) -> str:
        """``"20,000 transitions, a candidate every 5,000, 4 seeds per VUT: ..."``."""
        return (
            f"{self.total_timesteps:,} transitions, a candidate every {self.eval_every:,}, "
            f"{self.seeds} seeds per VUT: {self.summary}"
        )


BUDGETS: Mapping[str, Budget] = MappingProxyType(
    {
        "verdict": Budget(
            20_000,
            5_000,
            4,
            "the least compute that ranked every ladder right (issue 26, docs/performance.md)",
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
