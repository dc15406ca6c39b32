"""How the paper mode words its verdicts: pairwise, under the significance rule, the headline."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from sumo_ayss.analysis.case_verdict import CaseVerdict, paper_verdict
from sumo_ayss.analysis.ranking import (
    DELTA_V_BAR,
    POV_ACCELERATION,
    Indicator,
    RankedVut,
    Verdict,
    compare,
    safety_index,
)
from sumo_ayss.analysis.significance import PairVerdict
from sumo_ayss.config.report import ReportOptions
from sumo_ayss.modes.paper import (
    PaperResult,
    pair_sentence,
    paper_headline,
    significance_rule,
    verdict_sentence,
)
from tests.analysis.test_ranking import _vut


def test_a_safer_verdict_reads_the_same_whichever_vut_comes_first() -> None:
    rng = np.random.default_rng(42)
    pi1 = safety_index(*_vut(0.0, rng), n_boot=500, rng=1)
    pi2 = safety_index(*_vut(-1.5, rng), n_boot=500, rng=2)  # SPCPs brake 1.5 m/s² harder
    verdict = compare(pi1, pi2, name_a="pi1", name_b="pi2", indicator=POV_ACCELERATION)
    text = verdict_sentence(verdict)
    assert text.startswith("pi2 is safer than pi1: its SPCPs brake 1.")
    assert "m/s² harder" in text and "P(pi2 safer) > 0.999" in text and "3 vs 3 seeds" in text
    swapped = compare(pi2, pi1, name_a="pi2", name_b="pi1", indicator=POV_ACCELERATION)
    assert verdict_sentence(swapped) == text


def test_no_difference_reads_as_such() -> None:
    rng = np.random.default_rng(2024)
    first = safety_index(*_vut(0.0, rng), n_boot=1000, rng=5)
    again = safety_index(*_vut(0.0, rng), n_boot=1000, rng=6)
    verdict = compare(first, again, name_a="pi1", name_b="pi1'", indicator=DELTA_V_BAR)
    assert verdict_sentence(verdict).startswith(
        "No significant difference in safety between pi1 and"
    )


def test_verdict_sentence_golden() -> None:
    verdict = Verdict(
        name_a="pi1",
        name_b="pi2",
        safer="pi2",
        difference=-1.234,
        diff_lo=-1.6,
        diff_hi=-0.8,
        level=0.95,
        p_a_safer=0.02,
        cohens_d=-0.9,
        significant=True,
        p_seed_welch=0.01,
        n_seeds_a=3,
        n_seeds_b=3,
        h_range=(0.0, 5.0),
        same_bins=True,
        indicator=POV_ACCELERATION,
    )
    assert verdict_sentence(verdict) == (
        "pi2 is safer than pi1: its SPCPs brake 1.23 m/s² harder on average over "
        "adversarial-yet-safe states with h ≤ 5 m (95 % CI 0.80–1.60; P(pi2 safer) = 0.980; "
        "3 vs 3 seeds)."
    )


def test_verdict_sentence_no_difference_and_caveat() -> None:
    verdict = Verdict(
        name_a="x",
        name_b="y",
        safer=None,
        difference=0.05,
        diff_lo=-0.3,
        diff_hi=0.4,
        level=0.9,
        p_a_safer=0.6,
        cohens_d=0.01,
        significant=False,
        p_seed_welch=0.7,
        n_seeds_a=3,
        n_seeds_b=2,
        h_range=(1.0, 5.0),
        same_bins=False,
        indicator=Indicator("Δv̄", "m/s"),
    )
    assert verdict_sentence(verdict) == (
        "No significant difference in safety between x and y: over adversarial-yet-safe "
        "states with 1 m ≤ h ≤ 5 m, the mean Δv̄ of y's SPCPs minus x's is 0.05 m/s "
        "(no interval with 2 seeds; P(x safer) = 0.600; 3 vs 2 seeds). "
        "Caution: the two indices average over different headway bins."
    )


def _verdict(significant: bool, p_welch: float) -> Verdict:
    return Verdict(
        name_a="A",
        name_b="B",
        safer="A" if significant else None,
        difference=0.5,
        diff_lo=0.4,
        diff_hi=0.6,
        level=0.95,
        p_a_safer=0.9995,
        cohens_d=0.8,
        significant=significant,
        p_seed_welch=p_welch,
        n_seeds_a=3,
        n_seeds_b=3,
        h_range=(0.0, 5.0),
        same_bins=True,
        indicator=POV_ACCELERATION,
    )


def test_pair_sentence_under_the_rule() -> None:
    both = PairVerdict(_verdict(True, 0.01), True, "A", 0.05)
    assert pair_sentence(both).endswith("Seed-level Welch test: p = 0.010.")
    assert pair_sentence(both).startswith("A is safer than B")
    bootstrap_only = PairVerdict(_verdict(True, 0.2), False, None, 0.05)
    text = pair_sentence(bootstrap_only)
    assert text.startswith("No significant difference in safety between A and B")
    assert text.endswith(
        "The bootstrap interval alone excludes 0, but the seed-level Welch test gives "
        "p = 0.200 (needs < 0.05), so the difference is not called significant."
    )
    undefined = PairVerdict(_verdict(False, float("nan")), False, None, 0.05)
    assert pair_sentence(undefined).endswith(
        "Seed-level Welch test: undefined (it needs two seeds per VUT with spread)."
    )


def test_significance_rule_names_the_level_and_alpha() -> None:
    rule = significance_rule(ReportOptions(level=0.9, welch_alpha=0.01))
    assert (
        "BOTH the 90 % hierarchical-bootstrap interval" in rule
        and "p < 0.01, that p adjusted by Holm" in rule
    )


def test_paper_headline_words_the_verdict_record() -> None:
    pair = PairVerdict(_verdict(True, 0.01), True, "A", 0.05)
    ranking = [_ranked("A", 1), _ranked("B", 2)]
    v = paper_verdict("paper", ranking, [pair])
    a = _analysis(PaperResult(v, ranking=ranking, pairs=[pair]))
    assert paper_headline(a, v) == "[paper mode] " + pair_sentence(pair)
    v = paper_verdict("paper", ranking, [pair], premise_met=False)
    assert paper_headline(a, v).endswith("does not isolate the VUTs' safety.")
    only = [_ranked("A", 1)]
    one = _analysis(PaperResult(paper_verdict("paper", only, []), ranking=only))
    assert paper_headline(one, paper_verdict("paper", only, [])) == (
        "[paper mode] No verdict yet: only A has AYSS samples; a verdict needs two VUTs."
    )
    assert paper_headline(a, CaseVerdict("paper", "warning", missing="no_samples")) == (
        "[paper mode] No verdict yet: no VUT of this case has AYSS samples (ayss.csv)."
    )
    assert paper_headline(a, paper_verdict("paper", ranking, [])).startswith(
        "[paper mode] No verdict: the safety indices of the top two VUTs are not comparable."
    )


def _analysis(result: PaperResult) -> SimpleNamespace:
    """As much of a case's analysis as the headline reads: the paper mode's result."""
    return SimpleNamespace(case="car_following", results={"paper": result})


def _ranked(name: str, rank: int) -> RankedVut:
    return RankedVut(rank, name, 1.0 / rank, 0.0, 2.0, 3, None, None)
