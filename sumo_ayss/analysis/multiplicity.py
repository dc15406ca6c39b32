"""Family-wise control of a ranking's "safer than" claims (numpy-free, the stdlib only).

A leaderboard of K VUTs prints a claim for each of its K − 1 adjacent pairs ("A is safer
than B", the ``>`` of a ranking line). Each was its own t-test at ``alpha``, so with many
VUTs some claim was likely wrong even when all VUTs were equally safe. The procedure here
is **Holm's step-down over the adjacent pairs of the ranking** (:func:`holm`): sort the
family's m p-values ascending, multiply the i-th smallest by ``m − i + 1``, make the result
monotone and cap it at 1; a pair is significant when its adjusted p is below ``alpha``.

Why this family and this procedure (docs/ranking.md says it in prose):

* The claims the product prints are the adjacent pairs (the leaderboard's "vs next", the
  ``>`` signs of a ranking line, the headline's top pair). A claim between non-adjacent
  VUTs follows from a chain of adjacent ones, and is true whenever they are (true means
  are ordered transitively).
* Holm controls the family-wise error rate in the strong sense for any dependence between
  the tests, needs no assumption beyond each test's own validity (the paired t over seed
  blocks, whose false-positive rate is tested), and is uniformly more powerful than
  Bonferroni. The family is chosen by the data (which pairs end up adjacent); adjacent
  pairs are the *closest* means, so that choice makes the tests conservative rather than
  liberal: ``tests/analysis/test_multiplicity.py`` and ``scripts/fwer.py`` measure the
  family-wise rate on null grids of 3 to 32 VUTs and on partial nulls.
* An omnibus-F gate (Fisher's protected LSD) controls the rate only when *every* VUT is
  equally safe; with a few real differences the gate passes and the uncorrected pairs
  behind it are again on their own (measured in ``scripts/fwer.py``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

__all__ = ["PROCEDURE", "chain_adjusted", "holm"]

PROCEDURE = "Holm over the adjacent pairs"
"""The family-wise procedure's name, as the report and ``ranking.csv`` state it."""


def holm(p_values: Sequence[float]) -> list[float]:
    """Holm's step-down adjusted p-values of one family of tests.

    Args:
        p_values: The raw p-values, each in [0, 1]; NaN for a test that could not be made
            (it is not part of the family: it rejects nothing and costs nothing).

    Returns:
        The adjusted p-values, in the input's order, each in [raw, 1]; NaN where the raw
        p was NaN. A test is significant at family-wise level ``alpha`` when its adjusted
        p is below ``alpha``.

    Example:
        ``holm([0.01, 0.04, 0.03])`` is ``[0.03, 0.06, 0.06]``.
    """
    finite = sorted((p, i) for i, p in enumerate(p_values) if math.isfinite(p))
    m = len(finite)
    out = [math.nan] * len(p_values)
    running = 0.0
    for rank, (p, i) in enumerate(finite):
        running = max(running, min(1.0, (m - rank) * p))
        out[i] = running
    return out


def chain_adjusted(
    order: Sequence[str], adjacent_p: Sequence[float]
) -> dict[tuple[str, str], float]:
    """The family-adjusted p of every pair of a ranking, from its adjacent pairs' raw p.

    The adjacent pairs (``order[i]``, ``order[i + 1]``) are the family (:func:`holm`). A
    pair further apart is claimed only through the chain of adjacent claims between them:
    its adjusted p is the largest adjusted p along that chain (NaN if one is NaN), so it is
    significant exactly when every step is, and true whenever they are.

    Args:
        order: VUTs in ranking order, safest first.
        adjacent_p: Raw p of each adjacent pair, ``len(order) - 1`` of them (NaN: no test).

    Returns:
        ``{(a, b): adjusted p}`` for every pair with ``a`` ranked above ``b``.

    Raises:
        ValueError: If the lengths do not match.
    """
    if len(adjacent_p) != max(len(order) - 1, 0):
        raise ValueError(f"{len(adjacent_p)} adjacent p-values for {len(order)} VUTs")
    adj = holm(adjacent_p)
    out: dict[tuple[str, str], float] = {}
    for i, a in enumerate(order):
        worst = 0.0
        for j in range(i + 1, len(order)):
            step = adj[j - 1]
            worst = math.nan if not math.isfinite(step) or math.isnan(worst) else max(worst, step)
            out[(a, order[j])] = worst
    return out
