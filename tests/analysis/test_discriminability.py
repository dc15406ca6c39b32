"""Discriminability arithmetic on hand-made response arrays (no SUMO)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sumo_ayss.analysis.discriminability import (
    BoxGrid,
    BoxStates,
    bin_shares,
    compare_responses,
    differ_mask,
    lowest_differing_headway,
)
from sumo_ayss.util.errors import ConfigError


def test_differ_mask_is_strictly_above_threshold() -> None:
    a = np.array([0.0, 0.0, 0.0, 1.0, np.nan])
    b = np.array([0.1, 0.1000001, -0.3, 1.0, 0.0])
    assert differ_mask(a, b, 0.1).tolist() == [False, True, True, False, False]
    with pytest.raises(ConfigError, match="same shape"):
        differ_mask(a, b[:2], 0.1)


def test_bin_shares_hand_case() -> None:
    flags = [True, False, True, True, False]
    x = [0.1, 0.4, 0.6, 1.0, 7.0]  # 1.0 falls in the last (closed) bin; 7.0 is outside
    counts, shares = bin_shares(flags, x, [0.0, 0.5, 1.0])
    assert counts.tolist() == [2, 2]
    assert shares.tolist() == [0.5, 1.0]
    counts, shares = bin_shares([True], [0.2], [0.0, 0.5, 1.0])
    assert counts.tolist() == [1, 0] and shares[0] == 1.0 and math.isnan(shares[1])
    with pytest.raises(ConfigError, match="increasing"):
        bin_shares(flags, x, [1.0, 0.0])


def test_lowest_differing_headway() -> None:
    assert lowest_differing_headway([False, True, True], [1.0, 3.0, 2.5]) == 2.5
    assert lowest_differing_headway([False, False], [1.0, 3.0]) is None


def test_grid_keeps_the_ayss_filter() -> None:
    g = BoxGrid(speed_step_mps=5.0, headway_step_m=1.0)
    s = g.states()
    assert len(s) > 0
    assert s.h_m.min() > 0 and s.h_m.max() <= 5.0
    closing = s.v_vut_mps - s.v_pov_mps
    ttc = np.where(closing > 0, s.h_m / np.where(closing > 0, closing, 1.0), np.inf)
    assert ttc.min() >= 0.2
    # A state that the TTC filter drops: v_pov 0, v_vut 30, h 1 (TTC 1/30 s).
    dropped = (s.v_pov_mps == 0) & (s.v_vut_mps == 30) & (s.h_m == 1)
    assert not dropped.any()
    kept = (s.v_pov_mps == 0) & (s.v_vut_mps == 5) & (s.h_m == 1)  # TTC 0.2 s: kept
    assert kept.sum() == 1
    # The documented default grid.
    assert len(BoxGrid().states()) == 38_496
    with pytest.raises(ConfigError, match="speed_step_mps must be > 0"):
        BoxGrid(speed_step_mps=0)
    with pytest.raises(ConfigError, match="v_vut_mps"):
        BoxGrid(v_vut_mps=(10.0, 5.0))


def _states() -> BoxStates:
    h = np.array([0.5, 1.5, 2.5, 3.5, 4.5, 4.5])
    v = np.array([5.0, 5.0, 15.0, 15.0, 25.0, 25.0])
    return BoxStates(v_pov_mps=v.copy(), v_vut_mps=v, h_m=h)


def test_compare_responses_golden() -> None:
    s = _states()
    a = np.array([-6.0, -6.0, -6.0, -5.0, -4.0, -4.0])
    b = np.array([-6.0, -6.0, -6.0, -6.0, -6.0, -4.05])
    res = compare_responses(
        {"a": a, "b": b, "a2": a.copy()},
        s,
        threshold_mps2=0.1,
        h_edges_m=[0, 1, 2, 3, 4, 5],
        v_edges_mps=[0, 10, 20, 30],
    )
    assert [(p.a, p.b) for p in res.pairs] == [("a", "b"), ("a", "a2"), ("b", "a2")]
    ab, aa, _ = res.pairs
    assert ab.share == pytest.approx(2 / 6)
    assert ab.lowest_h_m == 3.5
    assert ab.share_by_h.tolist() == [0.0, 0.0, 0.0, 1.0, 0.5]
    assert ab.share_by_v_vut.tolist() == [0.0, 0.5, 0.5]
    assert ab.max_abs_diff_mps2 == pytest.approx(2.0)
    assert ab.mean_abs_diff_mps2 == pytest.approx((1 + 2 + 0.05) / 6)
    assert aa.share == 0.0 and aa.lowest_h_m is None and aa.max_abs_diff_mps2 == 0.0
    assert res.mean_response_mps2["a"] == pytest.approx(a.mean())
    d = res.to_dict()
    assert d["pairs"][0]["share_by_h"] == [0.0, 0.0, 0.0, 1.0, 0.5]
    with pytest.raises(ConfigError, match=r"responses\['b'\] must have shape"):
        compare_responses({"a": a, "b": b[:3]}, s)
