"""The verdict record of a case: which mode, the ranking, the top pair, the kind."""

from __future__ import annotations

import math

from sumo_ayss.analysis.case_verdict import paper_verdict, seed_verdict
from sumo_ayss.analysis.ranking import POV_ACCELERATION, RankedVut, Verdict
from sumo_ayss.analysis.seeds import SeedComparison, SeedRankRow
from sumo_ayss.analysis.significance import PairVerdict


def _pair(a: str, b: str, significant: bool) -> PairVerdict:
    v = Verdict(
        name_a=a,
        name_b=b,
        safer=a if significant else None,
        difference=0.5,
        diff_lo=0.1 if significant else -0.1,
        diff_hi=0.9,
        level=0.95,
        p_a_safer=0.99,
        cohens_d=0.5,
        significant=significant,
        p_seed_welch=0.01 if significant else 0.3,
        n_seeds_a=3,
        n_seeds_b=3,
        h_range=(0.0, 5.0),
        same_bins=True,
        indicator=POV_ACCELERATION,
    )
    return PairVerdict(v, significant, a if significant else None)


def _ranked(*names: str) -> list[RankedVut]:
    return [RankedVut(i + 1, n, -i, -i - 1, -i + 1, 3, None, None) for i, n in enumerate(names)]


def test_paper_verdict_of_a_ranked_case() -> None:
    pairs = [_pair("a", "b", True), _pair("a", "c", True), _pair("b", "c", False)]
    v = paper_verdict("paper", _ranked("a", "b", "c"), pairs)
    assert (v.mode, v.kind, v.missing, v.caveat) == ("paper", "safer", "", "")
    assert v.order == ("a", "b", "c") and v.apart == (True, False)
    assert v.top is pairs[0] and v.pairs == tuple(pairs)
    confounded = paper_verdict("paper", _ranked("a", "b", "c"), pairs, premise_met=False)
    assert (confounded.kind, confounded.caveat) == ("warning", "premise_not_met")
    none = paper_verdict("paper", _ranked("b", "c"), pairs[2:])
    assert none.kind == "none" and none.apart == (False,)


def test_paper_verdict_says_why_there_is_none() -> None:
    assert paper_verdict("paper", [], []).missing == "no_samples"
    one = paper_verdict("paper", _ranked("a"), [])
    assert (one.missing, one.kind, one.order) == ("one_vut", "warning", ())
    apart = paper_verdict("paper", _ranked("a", "b"), [])  # the pair was not comparable
    assert (apart.missing, apart.order, apart.top) == ("not_comparable", (), None)
    assert paper_verdict("paper", [], [], premise_met=False).caveat == "premise_not_met"


def _cmp(a: str, b: str, p: float) -> SeedComparison:
    return SeedComparison(a, b, -0.2, -0.3, -0.1, p, "paired t", 3, 3, 0.95, 0.05)


def test_seed_verdict() -> None:
    ab, bc = _cmp("a", "b", 0.01), _cmp("b", "c", 0.4)
    rows = [
        SeedRankRow(1, "a", 0.1, math.nan, math.nan, 3, ab),
        SeedRankRow(2, "b", 0.3, math.nan, math.nan, 3, bc),
        SeedRankRow(3, "c", 0.4, math.nan, math.nan, 3, None),
    ]
    v = seed_verdict("exposure", rows, [ab, bc])
    assert (v.mode, v.kind, v.order, v.apart, v.top) == (
        "exposure",
        "safer",
        ("a", "b", "c"),
        (True, False),
        ab,
    )
    careful = seed_verdict("exposure", rows, [ab, bc], caution=True)
    assert (careful.kind, careful.caveat) == ("warning", "case_caution")
    assert seed_verdict("crossplay", rows[1:], [bc]).kind == "none"
    one = seed_verdict("exposure", rows[2:], [])
    assert (one.missing, one.kind, one.order, one.top) == ("too_few", "warning", ("c",), None)
    assert seed_verdict("exposure", [], []).order == ()
