"""Seed-level intervals: none over two seeds, always inside the quantity's possible range."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sumo_ayss.analysis.harm import HARM_RANGE
from sumo_ayss.analysis.premise import premise_check
from sumo_ayss.analysis.seed_intervals import (
    MIN_SEEDS_FOR_INTERVAL,
    binned_seed_means,
    clip_interval,
    seed_mean_ci,
)
from sumo_ayss.analysis.seeds import SeedScores, rank_seeds
from sumo_ayss.util.errors import ConfigError


def test_two_seeds_give_no_interval_and_say_so() -> None:
    # The case: crash rates 0.0 and 0.57 over two seeds gave "−143 to 200 %".
    mean, lo, hi = seed_mean_ci([0.0, 0.57], bounds=(0.0, 1.0))
    assert mean == pytest.approx(0.285)
    assert math.isnan(lo) and math.isnan(hi)
    assert MIN_SEEDS_FOR_INTERVAL == 3


def test_rate_interval_is_clipped_to_its_possible_range() -> None:
    values = [0.0, 0.02, 0.9]  # a wide spread: the raw t-interval reaches below 0 and above 1
    _, raw_lo, raw_hi = seed_mean_ci(values)
    assert raw_lo < 0.0 and raw_hi > 1.0
    mean, lo, hi = seed_mean_ci(values, bounds=(0.0, 1.0))
    assert 0.0 <= lo <= mean <= hi <= 1.0
    assert (lo, hi) == (0.0, 1.0)


def test_clip_interval_keeps_nan_and_rejects_bad_bounds() -> None:
    assert clip_interval(0.2, 0.4, (0.0, 1.0)) == (0.2, 0.4)
    assert all(math.isnan(v) for v in clip_interval(math.nan, math.nan, (0.0, 1.0)))
    with pytest.raises(ConfigError, match="bounds"):
        clip_interval(0.0, 1.0, (1.0, 0.0))


def test_premise_intervals_lie_within_their_possible_range() -> None:
    rng = np.random.default_rng(0)
    crash = {f"v{i}": list(rng.uniform(0.0, 0.6, 3 + i % 3)) for i in range(6)}
    crash["two"] = [0.0, 0.57]
    premise = premise_check({"crash_rate": crash})
    (metric,) = premise.metrics
    for vut, (mean, lo, hi, n) in metric.per_vut.items():
        if n < MIN_SEEDS_FOR_INTERVAL:
            assert math.isnan(lo) and math.isnan(hi), vut
        else:
            assert 0.0 <= lo <= mean <= hi <= 1.0, vut


def test_harm_ranking_intervals_lie_in_zero_one() -> None:
    rng = np.random.default_rng(1)
    scores = [
        SeedScores(f"v{i}", {s: float(rng.uniform(0.0, 1.0)) for s in range(3)}) for i in range(8)
    ]
    rows, _ = rank_seeds(scores, higher_is_safer=False, bounds=HARM_RANGE)
    assert any(r.lo == 0.0 or r.hi == 1.0 for r in rows)  # some were clipped
    for r in rows:
        assert 0.0 <= r.lo <= r.mean <= r.hi <= 1.0
    rows2, _ = rank_seeds(
        [SeedScores("a", {0: 0.1, 1: 0.9}), SeedScores("b", {0: 0.2, 1: 0.3})],
        higher_is_safer=False,
        bounds=HARM_RANGE,
    )
    assert all(math.isnan(r.lo) and math.isnan(r.hi) for r in rows2)


def test_between_seed_band_holds_every_seed_and_pooled_band_does_not() -> None:
    # Two seeds 7 m/s² apart, many samples each: the pooled t-band is tight and excludes
    # both seed means; the between-seed band (the range of the two) contains both.
    rng = np.random.default_rng(2)
    h = rng.uniform(0.0, 5.0, 4000)
    seeds = [
        (h[:2000], -1.0 + rng.normal(0, 0.5, 2000)),
        (h[2000:], -8.0 + rng.normal(0, 0.5, 2000)),
    ]
    edges = np.linspace(0.0, 5.0, 6)
    bands = binned_seed_means(seeds, edges)
    assert bands.n_seeds.max() == 2
    for b in range(5):
        per_seed = [s.means[b] for s in bands.per_seed]
        assert bands.lo[b] <= min(per_seed) and max(per_seed) <= bands.hi[b]
        assert bands.means[b] == pytest.approx(np.mean(per_seed))
        assert bands.n_seeds[b] == 2
    three = binned_seed_means([*seeds, (h[:100], -4.0 + rng.normal(0, 0.5, 100))], edges)
    assert three.n_seeds.max() == 3
    assert np.all(three.lo <= three.means) and np.all(three.means <= three.hi)
