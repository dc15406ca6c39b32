"""Per-VUT measure distributions and per-measure rankings on a hand-made pool."""

from __future__ import annotations

import math

import numpy as np

from sumo_ayss.analysis.measure_ranking import _median, measure_rankings, r157_rows

# two VUTs, two opponents (o1, o2), two episodes each
VUT = ["a"] * 4 + ["b"] * 4
OPP = ["o1", "o1", "o2", "o2"] * 2
COLUMNS = {
    # a: 1, 2, 3, inf -> median (2nd of 4, no interpolation) 2; b: 0.5, 0.5, 1 (one NaN) -> 0.5
    "min_ttc_s": [1.0, 2.0, 3.0, math.inf, 0.5, 0.5, 1.0, math.nan],
    # lower is safer: b brakes less
    "max_drac_mps2": [3.0, 3.0, 3.0, 3.0, 1.0, 1.0, 1.0, 1.0],
    # equal medians: a tie
    "pet_s": [1.0] * 8,
}


def rankings():
    out = measure_rankings(VUT, OPP, COLUMNS, vuts=["a", "b"], primary_order=["a", "b"], n_boot=200)
    return {m.spec.column: m for m in out}


def test_medians_quantiles_and_ranks() -> None:
    r = rankings()
    assert list(r) == ["min_ttc_s", "max_drac_mps2", "pet_s"]  # measures without a column: out
    a, b = r["min_ttc_s"].rows
    assert (a.n, a.n_total, a.median, a.p10, a.p90, a.share_inf) == (4, 4, 2.0, 1.0, math.inf, 0.25)
    assert (b.n, b.median) == (3, 0.5)
    assert (a.rank, b.rank) == (1, 2) and r["min_ttc_s"].order == ("a", "b")
    assert r["min_ttc_s"].tau == 1.0
    assert a.lo <= a.median <= a.hi
    # lower DRAC is safer: b first, the opposite of the primary order
    assert r["max_drac_mps2"].order == ("b", "a") and r["max_drac_mps2"].tau == -1.0
    # constant values: the interval collapses on the median
    drac_b = r["max_drac_mps2"].rows[1]
    assert drac_b.lo == drac_b.hi == 1.0
    # a tie is no ranking: both rank 1, tau undefined
    pet = r["pet_s"]
    assert pet.ties and [row.rank for row in pet.rows] == [1, 1] and math.isnan(pet.tau)


def test_the_summaries_are_reproducible() -> None:
    assert rankings()["min_ttc_s"].rows == rankings()["min_ttc_s"].rows


def test_r157_share_per_vut() -> None:
    must = [1.0, 1.0, 0.0, math.nan, math.nan, math.nan, math.nan, math.nan]
    collided = [False, True, False, False] * 2
    a, b = r157_rows(VUT, must, collided, vuts=["a", "b"])
    assert (a.n_intrusions, a.n_required, a.n_handled, a.share) == (3, 2, 1, 0.5)
    assert a.lo < 0.5 < a.hi
    assert (b.n_intrusions, b.n_required) == (0, 0) and math.isnan(b.share)
    assert np.isnan([b.lo, b.hi]).all()


def test_a_float_tie_is_a_tie() -> None:
    """Two medians that differ only in the last bits (5.999999999999997 vs
    6.000000000000003: the same braking reached by two float paths) are a tie, not ranks
    2 and 1 with tau -1 (issue 35)."""
    cols = {"vut_max_braking_mps2": [5.999999999999997] * 4 + [6.000000000000003] * 4}
    (m,) = measure_rankings(VUT, OPP, cols, vuts=["a", "b"], primary_order=["a", "b"], n_boot=50)
    assert m.ties and [row.rank for row in m.rows] == [1, 1] and math.isnan(m.tau)


def test_the_median_is_the_inverted_cdf_order_statistic_with_infinities() -> None:
    """The bootstrap's median (np.partition) is np.quantile's ``inverted_cdf`` median to the
    bit, at every size, odd and even, with infinite values (a measure's ∞: no conflict) and
    ties; an even size takes the lower middle, never an average."""
    rng = np.random.default_rng(7)
    for n in range(1, 41):
        for _ in range(25):
            x = rng.normal(size=n).round(1)  # ties
            x[rng.random(n) < 0.3] = np.inf
            assert _median(x) == np.quantile(x, 0.5, method="inverted_cdf")
    assert _median(np.array([1.0, 2.0, 3.0, 4.0])) == 2.0
    assert _median(np.array([1.0, np.inf])) == 1.0 and _median(np.array([np.inf])) == np.inf
