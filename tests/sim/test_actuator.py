"""The POV actuator: bounded, monotone, and the law the docs state."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from sumo_ayss.config import ActuatorConfig
from sumo_ayss.sim.actuator import next_speed, pov_acceleration

CFG = ActuatorConfig()
speeds = st.floats(0.0, 40.0)
targets = st.floats(-10.0, 500.0)


@given(speeds, targets)
def test_bounded_and_signed(v: float, target: float) -> None:
    a = pov_acceleration(v, target, CFG)
    assert CFG.accel_min_mps2 <= a <= CFG.accel_max_mps2
    clipped = min(max(target, 0.0), CFG.max_speed_mps)
    assert (a > 0) == (clipped > v) or a == 0.0
    v1 = next_speed(v, a, 0.2, CFG)
    assert 0.0 <= v1 <= CFG.max_speed_mps


@given(speeds, targets, targets)
def test_monotone_in_target(v: float, t1: float, t2: float) -> None:
    lo, hi = sorted((t1, t2))
    assert pov_acceleration(v, lo, CFG) <= pov_acceleration(v, hi, CFG)


def test_known_values() -> None:
    assert pov_acceleration(25.0, 20.0, CFG) == -6.0  # unclipped law gives -8.3
    assert pov_acceleration(20.0, 21.2, CFG) == (21.2 - 20.0) / 0.6
    assert pov_acceleration(0.0, 100.0, CFG) == CFG.accel_max_mps2  # target and accel clipped
