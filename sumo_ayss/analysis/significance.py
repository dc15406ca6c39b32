"""The report's significance rule for pairs of VUTs in paper mode (numpy and stdlib only).

A difference between two VUTs is called significant only when BOTH the hierarchical-bootstrap
interval of the difference of their safety indices excludes 0 AND the seed-level Welch
t-test on the per-seed indices gives p < ``welch_alpha`` (with three seeds the bootstrap alone
is anti-conservative, see :func:`sumo_ayss.analysis.safety_index.safety_index`). The paper
mode words the rule and its verdicts (:mod:`sumo_ayss.modes.paper`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

from sumo_ayss.analysis.safety_index import Indicator, SafetyIndex
from sumo_ayss.analysis.verdict import Verdict, compare

__all__ = ["PairVerdict", "SignificanceOptions", "pair_verdict"]


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
    """

    verdict: Verdict
    significant: bool
    safer: str | None
    welch_alpha: float = 0.05


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
