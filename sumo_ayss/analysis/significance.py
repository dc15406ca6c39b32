"""The report's significance rule for pairs of VUTs in paper mode (numpy and stdlib only).

A difference between two VUTs is called significant only when BOTH the hierarchical-bootstrap
interval of the difference of their safety indices excludes 0 AND the seed-level Welch
t-test on the per-seed indices gives p < ``welch_alpha`` (with three seeds the bootstrap alone
is anti-conservative, see :func:`sumo_ayss.analysis.safety_index.safety_index`).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Protocol

from sumo_ayss.analysis.formatting import fmt_p
from sumo_ayss.analysis.safety_index import Indicator, SafetyIndex
from sumo_ayss.analysis.verdict import Verdict, compare

__all__ = ["PairVerdict", "SignificanceOptions", "pair_verdict", "significance_rule"]


class SignificanceOptions(Protocol):
    """The settings of the rule (e.g. :class:`sumo_ayss.config.report.ReportOptions`)."""

    @property
    def level(self) -> float: ...

    @property
    def welch_alpha(self) -> float: ...


def significance_rule(options: SignificanceOptions) -> str:
    """The rule of the paper mode, in words, for the report."""
    pct = f"{100 * options.level:g} %"
    return (
        "Paper-mode significance rule: a difference between two VUTs is called significant "
        "only when "
        f"BOTH the {pct} hierarchical-bootstrap interval of the difference of their safety "
        "indices excludes 0 AND the seed-level Welch t-test on the per-seed indices gives "
        f"p < {options.welch_alpha:g}. With only a few seeds per VUT the bootstrap alone is "
        "anti-conservative (resampling a few seeds understates the seed-to-seed spread), so the "
        "Welch test, which treats each seed's SPCP as one observation, must agree."
    )


@dataclass(frozen=True)
class PairVerdict:
    """A pairwise verdict under the report's significance rule.

    Attributes:
        verdict: The bootstrap verdict of :func:`sumo_ayss.analysis.ranking.compare`.
        significant: Whether BOTH the bootstrap interval excludes 0 AND the seed-level
            Welch p-value is below ``welch_alpha``.
        safer: The safer VUT under that rule, or None.
        sentence: One quotable sentence stating the verdict under that rule.
    """

    verdict: Verdict
    significant: bool
    safer: str | None
    sentence: str


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
        indicator: How the indicator is named in the sentence.
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
    if v.significant and not significant:
        neutral = dataclasses.replace(v, safer=None, significant=False).sentence()
        why = (
            f"the seed-level Welch test gives p {fmt_p(v.p_seed_welch)} (needs < {welch_alpha:g})"
            if math.isfinite(v.p_seed_welch)
            else "the seed-level Welch test is undefined (it needs two seeds per VUT with spread)"
        )
        sentence = (
            f"{neutral} The bootstrap interval alone excludes 0, but {why}, so the difference "
            "is not called significant."
        )
    else:
        welch = (
            f"p {fmt_p(v.p_seed_welch)}"
            if math.isfinite(v.p_seed_welch)
            else "undefined (it needs two seeds per VUT with spread)"
        )
        sentence = f"{v.sentence()} Seed-level Welch test: {welch}."
    return PairVerdict(v, significant, v.safer if significant else None, sentence)
