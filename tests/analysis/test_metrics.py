"""Tests of sumo_ayss.analysis.metrics: TTC and Δv̄ (golden cases and properties)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sumo_ayss.analysis.metrics import (
    delta_v_bar,
    delta_v_bar_between,
    time_to_collision,
    ttc_longitudinal,
)
from sumo_ayss.util.errors import ConfigError

coord = st.floats(-200.0, 200.0, allow_nan=False, allow_infinity=False)
speed = st.floats(-50.0, 50.0, allow_nan=False, allow_infinity=False)
positive_speed = st.floats(1e-3, 50.0, allow_nan=False, allow_infinity=False)
angle = st.floats(0.0, 2.0 * math.pi, allow_nan=False, allow_infinity=False)


# --------------------------------------------------------------------------- TTC


@pytest.mark.parametrize(
    ("gap", "closing", "expected"),
    [
        (10.0, 2.0, 5.0),  # closing in: gap / closing speed
        (1.0, 5.0, 0.2),
        (10.0, 0.0, math.inf),  # constant gap
        (10.0, -3.0, math.inf),  # opening gap
        (0.0, 5.0, 0.0),  # touching
        (0.0, -5.0, 0.0),  # touching even when separating
        (-1.0, 2.0, 0.0),  # overlapping
    ],
)
def test_ttc_golden(gap: float, closing: float, expected: float) -> None:
    result = time_to_collision(gap, closing)
    assert isinstance(result, float)
    assert result == pytest.approx(expected)


def test_ttc_vectorised_and_broadcast() -> None:
    gaps = np.array([[10.0, 0.0, 4.0], [6.0, -2.0, 3.0]])
    result = time_to_collision(gaps, np.array([2.0, 1.0, -1.0]))
    expected = np.array([[5.0, 0.0, np.inf], [3.0, 0.0, np.inf]])
    assert isinstance(result, np.ndarray)
    np.testing.assert_array_equal(result, expected)


def test_ttc_nan_propagates() -> None:
    result = time_to_collision([np.nan, 5.0], [1.0, np.nan])
    assert np.all(np.isnan(result))


def test_ttc_longitudinal_uses_follower_minus_leader() -> None:
    assert ttc_longitudinal(10.0, v_leader_mps=20.0, v_follower_mps=25.0) == pytest.approx(2.0)
    assert ttc_longitudinal(10.0, v_leader_mps=25.0, v_follower_mps=20.0) == math.inf
    assert ttc_longitudinal(0.0, v_leader_mps=25.0, v_follower_mps=20.0) == 0.0


def test_ttc_rejects_bad_input() -> None:
    with pytest.raises(ConfigError, match="gap_m and closing_speed_mps"):
        time_to_collision(np.ones(3), np.ones(2))
    with pytest.raises(ConfigError, match="gap_m"):
        time_to_collision("ten", 1.0)  # type: ignore[arg-type]


@given(g1=st.floats(-10.0, 200.0), g2=st.floats(-10.0, 200.0), closing=positive_speed)
def test_ttc_monotone_in_gap(g1: float, g2: float, closing: float) -> None:
    lo, hi = sorted((g1, g2))
    assert time_to_collision(lo, closing) <= time_to_collision(hi, closing)


@given(gap=st.floats(1e-3, 200.0), c1=speed, c2=speed)
def test_ttc_non_increasing_in_closing_speed(gap: float, c1: float, c2: float) -> None:
    lo, hi = sorted((c1, c2))
    assert time_to_collision(gap, hi) <= time_to_collision(gap, lo)


@given(gap=st.floats(-50.0, 200.0), closing=speed)
def test_ttc_is_non_negative(gap: float, closing: float) -> None:
    assert time_to_collision(gap, closing) >= 0.0


# --------------------------------------------------------------------------- Δv̄


def test_delta_v_bar_golden() -> None:
    # Δp = (3, 4), |Δp| = 5, Δv = (0, -5): (3·0 + 4·(-5)) / 5 = -4.
    result = delta_v_bar([3.0, 4.0], [0.0, -5.0])
    assert isinstance(result, float)
    assert result == pytest.approx(-4.0)
    assert delta_v_bar([3.0, 4.0], [6.0, 8.0]) == pytest.approx(10.0)


def test_delta_v_bar_batch_shape_and_zero_distance() -> None:
    rel_pos = np.array([[[10.0, 0.0], [0.0, 0.0]], [[0.0, 2.0], [-4.0, 0.0]]])
    rel_vel = np.array([-3.0, 1.0])
    result = delta_v_bar(rel_pos, rel_vel)
    assert result.shape == (2, 2)
    np.testing.assert_allclose(result[0, 0], -3.0)
    assert np.isnan(result[0, 1])  # coincident positions: direction undefined
    np.testing.assert_allclose(result[1], [1.0, 3.0])


def test_delta_v_bar_rejects_bad_shapes() -> None:
    with pytest.raises(ConfigError, match="rel_pos"):
        delta_v_bar([1.0, 2.0, 3.0], [1.0, 2.0, 3.0])
    with pytest.raises(ConfigError, match="rel_vel"):
        delta_v_bar([1.0, 2.0], 3.0)
    with pytest.raises(ConfigError, match="do not broadcast"):
        delta_v_bar(np.ones((3, 2)), np.ones((2, 2)))


def _unit_and_perp(x: float, y: float) -> tuple[np.ndarray, np.ndarray]:
    norm = math.hypot(x, y)
    unit = np.array([x, y]) / norm
    return unit, np.array([-unit[1], unit[0]])


nonzero_vec = st.tuples(coord, coord).filter(lambda v: math.hypot(*v) > 0.1)


@given(dp=nonzero_vec, c=positive_speed, tangential=speed)
def test_delta_v_bar_negative_when_approaching(
    dp: tuple[float, float], c: float, tangential: float
) -> None:
    unit, perp = _unit_and_perp(*dp)
    dv = -c * unit + tangential * perp  # closing at c, plus any rotation about each other
    result = delta_v_bar(np.array(dp), dv)
    assert result < 0.0
    assert result == pytest.approx(-c, rel=1e-9, abs=1e-9)


@given(dp=nonzero_vec, c=positive_speed, tangential=speed)
def test_delta_v_bar_positive_when_separating(
    dp: tuple[float, float], c: float, tangential: float
) -> None:
    unit, perp = _unit_and_perp(*dp)
    result = delta_v_bar(np.array(dp), c * unit + tangential * perp)
    assert result > 0.0
    assert result == pytest.approx(c, rel=1e-9, abs=1e-9)


@given(dp=nonzero_vec, dv=st.tuples(speed, speed), theta=angle)
def test_delta_v_bar_rotation_invariant(
    dp: tuple[float, float], dv: tuple[float, float], theta: float
) -> None:
    rot = np.array([[math.cos(theta), -math.sin(theta)], [math.sin(theta), math.cos(theta)]])
    before = delta_v_bar(np.array(dp), np.array(dv))
    after = delta_v_bar(rot @ np.array(dp), rot @ np.array(dv))
    assert after == pytest.approx(before, rel=1e-9, abs=1e-9)


@given(
    x_follower=coord,
    gap=st.floats(0.1, 100.0),
    y=coord,
    v_follower=speed,
    v_leader=speed,
)
def test_delta_v_bar_equals_minus_1d_closing_speed(
    x_follower: float, gap: float, y: float, v_follower: float, v_leader: float
) -> None:
    pos_follower, pos_leader = np.array([x_follower, y]), np.array([x_follower + gap, y])
    result = delta_v_bar_between(
        pos_follower, np.array([v_follower, 0.0]), pos_leader, np.array([v_leader, 0.0])
    )
    assert result == pytest.approx(-(v_follower - v_leader), rel=1e-9, abs=1e-9)


@given(dp=nonzero_vec, dv=st.tuples(speed, speed))
def test_delta_v_bar_is_rate_of_change_of_distance(
    dp: tuple[float, float], dv: tuple[float, float]
) -> None:
    p, v = np.array(dp), np.array(dv)
    eps = 1e-7
    numeric = (np.linalg.norm(p + eps * v) - np.linalg.norm(p - eps * v)) / (2 * eps)
    assert delta_v_bar(p, v) == pytest.approx(numeric, rel=1e-5, abs=1e-5)


@settings(max_examples=50)
@given(
    pi=st.tuples(coord, coord),
    vi=st.tuples(speed, speed),
    pj=st.tuples(coord, coord),
    vj=st.tuples(speed, speed),
)
def test_delta_v_bar_between_symmetric_in_pair(
    pi: tuple[float, float],
    vi: tuple[float, float],
    pj: tuple[float, float],
    vj: tuple[float, float],
) -> None:
    ij = delta_v_bar_between(pi, vi, pj, vj)
    ji = delta_v_bar_between(pj, vj, pi, vi)
    if math.isnan(ij):
        assert math.isnan(ji)
    else:
        assert ij == pytest.approx(ji, rel=1e-9, abs=1e-9)
