"""The report's significance rule for pairs of VUTs in paper mode (numpy and stdlib only).

A difference between two VUTs is called significant only when BOTH the hierarchical-bootstrap
interval of the difference of their safety indices excludes 0 AND the seed-level Welch
t-test on the per-seed indices gives p < ``welch_alpha`` (with three seeds the bootstrap alone
is anti-conservative, see :func:`sumo_ayss.analysis.safety_index.safety_index`). In a ranking
the Welch p-values of the adjacent pairs form one family, Holm-adjusted
(:func:`family_adjusted`, :mod:`.multiplicity`). The paper mode words the rule and its
verdicts (:mod:`sumo_ayss.modes.paper`).
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

from sumo_ayss.analysis.multiplicity import chain_adjusted
from sumo_ayss.analysis.safety_index import Indicator, SafetyIndex
from sumo_ayss.analysis.verdict import Verdict, compare

__all__ = ["PairVerdict", "SignificanceOptions", "family_adjusted", "pair_verdict"]


class SignificanceOptions(Protocol):
    """The settings of the rule (e.g. :class:`sumo_ayss.config.report.ReportOptions`)."""

    @property
    def level(self) -> float: ...

    @property
    def welch_alpha(self) -> float: ...


@dataclass(frozen=True)
class PairVerdict:
    """A pairwise verdict under the report's significance rule.

    Attributes:
        verdict: The bootstrap verdict of :func:`sumo_ayss.analysis.ranking.compare`.
        significant: Whether BOTH the bootstrap interval excludes 0 AND the seed-level
            Welch p-value is below ``welch_alpha``.
        safer: The safer VUT under that rule, or None.
        welch_alpha: The threshold of the seed-level Welch p-value the rule used.
        p_family: The Welch p adjusted for the ranking's family of claims
            (:func:`family_adjusted`); None for a pair judged on its own.
    """

    verdict: Verdict
    significant: bool
    safer: str | None
    welch_alpha: float = 0.05
    p_family: float | None = None


def pair_verdict(
    a: SafetyIndex,
    b: SafetyIndex,
    *,
    name_a: str,
    name_b: str,
    indicator: Indicator,
    level: float = 0.95,
    welch_alpha: float = 0.05,
) -> PairVerdict:
    """Compares two VUTs and applies the report's significance rule.

    Args:
        a: Safety index of VUT A.
        b: Safety index of VUT B (same ``h_range``, ``n_bins`` and ``n_boot`` as ``a``).
        name_a: Name of A.
        name_b: Name of B.
        indicator: How the indicator is named in the verdict.
        level: Confidence level of the bootstrap interval.
        welch_alpha: Threshold of the seed-level Welch p-value.

    Returns:
        The :class:`PairVerdict`.

    Raises:
        ConfigError: If the two indices are not comparable.
    """
    v = compare(a, b, name_a=name_a, name_b=name_b, level=level, indicator=indicator)
    welch_ok = math.isfinite(v.p_seed_welch) and v.p_seed_welch < welch_alpha
    significant = v.significant and welch_ok
    return PairVerdict(v, significant, v.safer if significant else None, welch_alpha)


def family_adjusted(pairs: Sequence[PairVerdict], order: Sequence[str]) -> list[PairVerdict]:
    """The pairs of a ranking with the seed-level Welch p adjusted for its family of claims.

    The Welch p-values of the adjacent pairs of ``order`` are Holm-adjusted, a pair further
    apart takes the largest adjusted p along the chain between them
    (:func:`~.multiplicity.chain_adjusted`); a pair is then significant when its bootstrap
    interval excludes 0 AND its adjusted p is below ``welch_alpha``. A pair missing from
    ``pairs`` (not comparable) counts as a step with no test.

    Args:
        pairs: Verdicts with A ranked above B.
        order: The ranking, safest first.

    Returns:
        The pairs, in their order, with ``p_family`` set and ``significant``/``safer``
        decided by it.
    """
    by = {(p.verdict.name_a, p.verdict.name_b): p for p in pairs}
    adjacent = [
        by[k].verdict.p_seed_welch if k in by else math.nan for k in itertools.pairwise(order)
    ]
    family = chain_adjusted(order, adjacent)
    out = []
    for p in pairs:
        q = family.get((p.verdict.name_a, p.verdict.name_b), math.nan)
        significant = p.verdict.significant and math.isfinite(q) and q < p.welch_alpha
        safer = p.verdict.safer if significant else None
        out.append(dataclasses.replace(p, significant=significant, safer=safer, p_family=q))
    return out
