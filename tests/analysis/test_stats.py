"""Tests of sumo_ayss.analysis.stats: t quantiles, intervals, binning, bootstrap."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sumo_ayss.analysis.stats import (
    binned_mean_ci,
    bootstrap_ci,
    cohens_d,
    hierarchical_bootstrap,
    mean_ci,
    student_t_sf,
    t_quantile,
    welch_t_test,
)
from sumo_ayss.util.errors import ConfigError

# --------------------------------------------------------------------------- t quantile


# References: mpmath (findroot on the regularized incomplete beta), 20 digits.
@pytest.mark.parametrize(
    ("p", "df", "expected"),
    [
        (0.975, 1, 12.7062047),
        (0.975, 2, 4.3026527),
        (0.975, 3, 3.1824463),
        (0.975, 10, 2.2281389),
        (0.975, 30, 2.0422725),
        (0.975, 1000, 1.9623391),
        (0.975, 10**7, 1.9599642),
        (0.975, math.inf, 1.9599640),
        (0.95, 20, 1.7247182),
        (0.995, 5, 4.0321430),
        (0.9, 1.5, 2.1963984),
    ],
)
def test_t_quantile_known_values(p: float, df: float, expected: float) -> None:
    assert t_quantile(p, df) == pytest.approx(expected, abs=1e-4)


def test_t_quantile_symmetry_and_median() -> None:
    assert t_quantile(0.5, 7) == 0.0
    assert t_quantile(0.025, 10) == pytest.approx(-t_quantile(0.975, 10), abs=1e-12)


def test_t_quantile_general_path_matches_closed_forms() -> None:
    # Continuity of scipy.stats.t around df = 1 and 2 (closed forms in some implementations).
    assert t_quantile(0.975, 1 + 1e-9) == pytest.approx(t_quantile(0.975, 1), abs=1e-6)
    assert t_quantile(0.975, 2 + 1e-9) == pytest.approx(t_quantile(0.975, 2), abs=1e-6)
    # Continuity at large df.
    assert t_quantile(0.975, 99_999) == pytest.approx(t_quantile(0.975, 100_001), abs=1e-8)


def test_t_quantile_inverts_survival_function() -> None:
    for df in (1, 3, 8.5, 40):
        assert student_t_sf(t_quantile(0.99, df), df) == pytest.approx(0.01, rel=1e-8)


@pytest.mark.parametrize(("p", "df"), [(0.0, 3), (1.0, 3), (0.5, 0), (0.9, -1), (True, 3)])
def test_t_quantile_rejects_bad_input(p: float, df: float) -> None:
    with pytest.raises(ConfigError):
        t_quantile(p, df)


# --------------------------------------------------------------------------- mean_ci


def test_mean_ci_known_case() -> None:
    mean, lo, hi = mean_ci([1, 2, 3, 4, 5])
    half = 2.776445 * math.sqrt(2.5) / math.sqrt(5)
    assert mean == 3.0
    assert lo == pytest.approx(3.0 - half, abs=1e-5)
    assert hi == pytest.approx(3.0 + half, abs=1e-5)


def test_mean_ci_small_samples() -> None:
    mean, lo, hi = mean_ci([4.0])
    assert mean == 4.0
    assert math.isnan(lo) and math.isnan(hi)
    assert all(math.isnan(v) for v in mean_ci([]))
    assert mean_ci([2.0, 2.0, 2.0]) == (2.0, 2.0, 2.0)


def test_mean_ci_rejects_bad_input() -> None:
    with pytest.raises(ConfigError, match="level"):
        mean_ci([1.0, 2.0], level=1.5)
    with pytest.raises(ConfigError, match="x"):
        mean_ci([1.0, np.nan])
    with pytest.raises(ConfigError, match="x"):
        mean_ci(np.ones((2, 2)))


# --------------------------------------------------------------------------- binning


def test_binned_mean_ci_by_hand() -> None:
    # Bins [0, 1), [1, 2), [2, 3]; -0.1 and 3.1 fall outside and are dropped.
    x = [-0.1, 0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.1]
    y = [99.0, 1.0, 3.0, 10.0, 20.0, 30.0, 5.0, 7.0, 99.0]
    res = binned_mean_ci(x, y, edges=[0.0, 1.0, 2.0, 3.0])
    np.testing.assert_array_equal(res.centers, [0.5, 1.5, 2.5])
    np.testing.assert_array_equal(res.counts, [2, 2, 3])
    np.testing.assert_allclose(res.means, [2.0, 15.0, 14.0])
    # Bin 0: mean 2, s = sqrt(2), n = 2 -> half-width t_{0.975,1} · sqrt(2) / sqrt(2).
    assert res.lo[0] == pytest.approx(2.0 - 12.7062047, abs=1e-6)
    assert res.hi[0] == pytest.approx(2.0 + 12.7062047, abs=1e-6)
    # Bin 2: y = 30, 5, 7: s² = (16² + 9² + 7²) / 2 = 193.
    half = 4.3026527 * math.sqrt(193.0 / 3.0)
    assert res.hi[2] - res.means[2] == pytest.approx(half, abs=1e-5)


def test_binned_mean_ci_min_count_masks_sparse_bins() -> None:
    res = binned_mean_ci([0.2, 0.4, 1.5, 2.5, 2.6, 2.7], [1, 2, 3, 4, 5, 6], [0, 1, 2, 3], 0.9, 3)
    np.testing.assert_array_equal(res.counts, [2, 1, 3])
    assert np.isnan(res.means[:2]).all() and np.isnan(res.lo[:2]).all()
    assert res.means[2] == pytest.approx(5.0)
    assert res.level == 0.9


def test_binned_mean_ci_single_sample_bin_has_mean_but_no_bounds() -> None:
    res = binned_mean_ci([0.5], [7.0], [0.0, 1.0], min_count=1)
    assert res.means[0] == 7.0 and np.isnan(res.lo[0]) and np.isnan(res.hi[0])


def test_binned_mean_ci_rejects_bad_input() -> None:
    with pytest.raises(ConfigError, match="edges"):
        binned_mean_ci([1.0], [1.0], [0.0, 0.0])
    with pytest.raises(ConfigError, match="x and y"):
        binned_mean_ci([1.0, 2.0], [1.0], [0.0, 3.0])
    with pytest.raises(ConfigError, match="min_count"):
        binned_mean_ci([1.0], [1.0], [0.0, 3.0], min_count=0)


# --------------------------------------------------------------------------- bootstrap


def test_hierarchical_bootstrap_resamples_groups() -> None:
    # Constant groups: a replicate's mean depends only on which groups are drawn, so it is
    # 0 (both draws group 0), 5 (one of each) or 10, with probabilities 1/4, 1/2, 1/4.
    dist = hierarchical_bootstrap([np.zeros(3), np.full(5, 10.0)], n_boot=4000, rng=0)
    assert dist.shape == (4000,)
    values, counts = np.unique(np.round(dist, 9), return_counts=True)
    assert set(values) <= {0.0, 3.75, 6.25, 10.0}  # pooled sizes differ: 3+5 rows
    frac = counts / dist.size
    assert frac[0] == pytest.approx(0.25, abs=0.03) and frac[-1] == pytest.approx(0.25, abs=0.03)


def test_hierarchical_bootstrap_resamples_within_groups() -> None:
    dist = hierarchical_bootstrap([np.array([0.0, 1.0])], n_boot=4000, rng=1)
    values, counts = np.unique(dist, return_counts=True)
    np.testing.assert_array_equal(values, [0.0, 0.5, 1.0])
    np.testing.assert_allclose(counts / dist.size, [0.25, 0.5, 0.25], atol=0.03)


def test_hierarchical_bootstrap_reproducible_and_2d() -> None:
    groups = [np.arange(10.0).reshape(5, 2), np.ones((3, 2))]

    def stat(rows: np.ndarray) -> float:
        return float(rows[:, 1].max())

    first = hierarchical_bootstrap(groups, stat, n_boot=50, rng=np.random.default_rng(7))
    second = hierarchical_bootstrap(groups, stat, n_boot=50, rng=7)
    np.testing.assert_array_equal(first, second)


@pytest.mark.parametrize(
    ("groups", "n_boot", "match"),
    [
        ([], 10, "groups"),
        ([np.array([])], 10, r"groups\[0\]"),
        ([np.array([1.0]), np.array([np.nan])], 10, r"groups\[1\]"),
        ([np.array([1.0])], 0, "n_boot"),
        ([np.ones(2), np.ones((2, 2))], 10, "trailing shape"),
    ],
)
def test_hierarchical_bootstrap_rejects_bad_input(groups: list, n_boot: int, match: str) -> None:
    with pytest.raises(ConfigError, match=match):
        hierarchical_bootstrap(groups, n_boot=n_boot, rng=0)


def test_bootstrap_ci_percentiles() -> None:
    assert bootstrap_ci(np.arange(101.0), level=0.9) == pytest.approx((5.0, 95.0))
    with pytest.raises(ConfigError, match="dist"):
        bootstrap_ci([1.0, np.nan])
    with pytest.raises(ConfigError, match="dist"):
        bootstrap_ci([])


def test_cohens_d_known_case() -> None:
    assert cohens_d([1.0, 2.0, 3.0], [4.0, 5.0, 6.0]) == pytest.approx(-3.0)
    assert math.isnan(cohens_d([1.0, 1.0], [1.0, 1.0]))
    with pytest.raises(ConfigError):
        cohens_d([1.0], [2.0])


def test_welch_t_test_known_case() -> None:
    # Reference: t and df by hand, p from mpmath's regularized incomplete beta.
    t, df, p = welch_t_test([1.0, 2.0, 3.0, 4.0], [2.0, 4.0, 6.0, 8.0, 10.0])
    assert t == pytest.approx(-2.2514363, abs=1e-6)
    assert df == pytest.approx(5.5207877, abs=1e-6)
    assert p == pytest.approx(0.0691336, abs=1e-6)
    assert all(math.isnan(v) for v in welch_t_test([1.0, 1.0], [2.0, 2.0]))
    with pytest.raises(ConfigError):
        welch_t_test([1.0], [1.0, 2.0])


def test_binned_mean_bootstrap_reproduces_the_generic_bootstrap() -> None:
    """Same draws, same order of summation: the replicates are equal bit for bit."""
    from sumo_ayss.analysis.bootstrap import binned_mean_bootstrap

    gen = np.random.default_rng(3)
    used = np.array([True, True, False, True])
    bins = [gen.choice([0, 1, 3], size=n) for n in (40, 7, 23)]
    values = [gen.normal(size=b.size) for b in bins]
    groups = [np.column_stack([b.astype(np.float64), v]) for b, v in zip(bins, values, strict=True)]

    def statistic(rows: np.ndarray) -> float:
        idx = rows[:, 0].astype(np.int64)
        counts = np.bincount(idx, minlength=used.size)
        sums = np.bincount(idx, weights=rows[:, 1], minlength=used.size)
        keep = used & (counts > 0)
        return float(np.mean(sums[keep] / counts[keep]))

    generic = hierarchical_bootstrap(groups, statistic, n_boot=300, rng=11)
    fast = binned_mean_bootstrap(bins, values, used, n_boot=300, rng=11)
    np.testing.assert_array_equal(fast, generic)
