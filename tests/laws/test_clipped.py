"""Our clipped POV law, without SUMO (a fake pair records the commands)."""

from __future__ import annotations

import pytest

from sumo_ayss.config import ActuatorConfig
from sumo_ayss.laws.clipped import ClippedPov
from tests.laws.fake_pair import FakePair


def test_bounded_acceleration_and_speed_command_each_step() -> None:
    law = ClippedPov(ActuatorConfig(), step_length_s=0.2, length_m=5.0)
    pair = FakePair((180.0, -1.6), (150.0, -4.8))
    law.start(pair, 20.0)  # type: ignore[arg-type]
    law.command(pair, 0.0)  # type: ignore[arg-type]  # a stop: clipped to -6 m/s²
    assert law.accel_mps2(pair) == -6.0  # type: ignore[arg-type]
    assert pair.log == [("command_pov_speed", pytest.approx(18.8))]
    law.command(pair, 18.8)  # type: ignore[arg-type]
    assert law.accel_mps2(pair) == pytest.approx(0.0)  # type: ignore[arg-type]


def test_substep_states_are_constant_speed_from_the_centre() -> None:
    law = ClippedPov(ActuatorConfig(substeps=3), step_length_s=0.3, length_m=5.0)
    pair = FakePair((180.0, -1.6), (150.0, -4.8))
    law.start(pair, 10.0)  # type: ignore[arg-type]
    law.command(pair, 10.0)  # type: ignore[arg-type]
    states = law.substep_states(pair)  # type: ignore[arg-type]
    assert [s.x_m for s in states] == pytest.approx([177.5, 178.5, 179.5, 180.5])
    assert {(s.y_m, s.heading_rad, s.speed_mps) for s in states} == {(-1.6, 0.0, 10.0)}


def test_lane_changes_are_sumos() -> None:
    law = ClippedPov(ActuatorConfig(), step_length_s=0.2, length_m=5.0)
    pair = FakePair((180.0, -1.6), (150.0, -4.8))
    law.change_lane(pair, 0, 5.0)  # type: ignore[arg-type]
    assert pair.log == [("change_pov_lane", 0, 5.0)]
    assert law.lane_motion(20.0, 0.0, 0.0) == (20.0, 0.0, False)
    assert law.lane_motion(20.0, -0.4, -3.2) == (20.0, -3.2, True)
    assert law.lane_motion(20.0, 0.0, -3.2)[2] and law.lane_motion(20.0, 0.1, 0.0)[2]
