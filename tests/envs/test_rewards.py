"""Reward shapes: anchor points, bounds, monotonicity; collisions get the minimum."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from sumo_ayss.config import RewardConfig, RewardShape
from sumo_ayss.envs.rewards import adversarial_reward, total_reward

KINDS = ["linear", "quadratic", "exponential"]
headways = st.floats(0.0, 100.0)


@pytest.mark.parametrize("kind", KINDS)
def test_anchor_points(kind: str) -> None:
    shape = RewardShape(kind=kind, peak_m=0.25, zero_m=20.0, value_at_contact=0.5)
    assert adversarial_reward(0.25, shape) == pytest.approx(1.0)
    assert adversarial_reward(20.0, shape) == 0.0
    assert adversarial_reward(35.0, shape) == 0.0
    assert adversarial_reward(0.0, shape) == pytest.approx(0.5)
    assert adversarial_reward(0.125, shape) == pytest.approx(0.75)


@pytest.mark.parametrize("kind", KINDS)
@given(h1=headways, h2=headways)
def test_bounded_and_decreasing_beyond_peak(kind: str, h1: float, h2: float) -> None:
    shape = RewardShape(kind=kind)
    r1, r2 = adversarial_reward(h1, shape), adversarial_reward(h2, shape)
    assert 0.0 <= r1 <= 1.0
    if shape.peak_m <= h1 <= h2:
        assert r1 >= r2


@given(h=headways)
def test_collision_is_the_minimum(h: float) -> None:
    cfg = RewardConfig()
    r = adversarial_reward(h, cfg.same_lane)
    assert total_reward(r, True, cfg) == cfg.min_reward < total_reward(r, False, cfg)
    assert total_reward(r, False, cfg) <= cfg.max_reward
