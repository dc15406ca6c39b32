"""highway-env's laws as the env's POV / VUT laws, without SUMO (a fake pair)."""

from __future__ import annotations

import pytest

from sumo_ayss.config import ActuatorConfig
from sumo_ayss.laws.clipped import ClippedPov
from sumo_ayss.laws.highway_env import HighwayEnvIdmVut, HighwayEnvPovLaw
from sumo_ayss.laws.hwenv import HighwayEnvIDM
from tests.laws.fake_pair import FakePair

HW = ActuatorConfig(mode="highway_env")


def idm_vut(judges: bool) -> HighwayEnvIdmVut:
    return HighwayEnvIdmVut(HighwayEnvIDM(), 0.2, 3, (5.0, 5.0), (2.0, 2.0), judges)


def test_pov_moves_to_its_integrated_state_and_puts_its_speed_back() -> None:
    law = HighwayEnvPovLaw(HW, step_length_s=0.2, length_m=5.0)
    pair = FakePair((180.0, -1.6), (150.0, -4.8))
    law.start(pair, 20.0)  # type: ignore[arg-type]
    law.command(pair, 14.0)  # type: ignore[arg-type]
    states = law.substep_states(pair)  # type: ignore[arg-type]
    assert len(states) == 4 and states[0].x_m == 177.5
    end = states[-1]
    assert pair.log == [("move_pov_xy", end.x_m + 2.5, end.y_m, end.heading_rad)]
    # a = (14 - v)/0.6 unclipped at each 1/15 s sub-step; its mean is reported.
    assert law.accel_mps2(pair) == pytest.approx(-10.0 * (1 + 8 / 9 + 64 / 81) / 3)  # type: ignore[arg-type]
    law.sync(pair)  # type: ignore[arg-type]
    law.sync(pair)  # type: ignore[arg-type]  # once only
    assert pair.log[1:] == [("set_speed_state", end.speed_mps, None)]


def test_pov_lane_change_retargets_its_steering() -> None:
    law = HighwayEnvPovLaw(HW, step_length_s=0.2, length_m=5.0)
    pair = FakePair((180.0, -1.6), (150.0, -4.8))
    law.start(pair, 20.0)  # type: ignore[arg-type]
    assert law.lane_motion(20.0, 0.0, 0.0) == (20.0, 0.0, False)
    law.change_lane(pair, 0, 5.0)  # type: ignore[arg-type]
    assert pair.log == []  # nothing asked of SUMO
    assert law.lane_motion(20.0, 0.0, 0.0)[2]  # 3.2 m off its target centre line
    for _ in range(5):
        law.command(pair, 20.0)  # type: ignore[arg-type]
    vx, vy, changing = law.lane_motion(0.0, 0.0, 0.0)  # SUMO's reading is not used
    assert changing and vy < 0.0 and 0.0 < vx < 20.0


def test_idm_vut_against_a_clipped_pov_commands_its_mean_speed() -> None:
    pov = ClippedPov(ActuatorConfig(), step_length_s=0.2, length_m=5.0)
    vut = idm_vut(judges=False)
    pair = FakePair((185.0, -4.8), (150.0, -4.8))
    pair.pov_lane = 0
    vut.start(pair, 20.0)  # type: ignore[arg-type]
    pov.start(pair, 20.0)  # type: ignore[arg-type]
    pov.command(pair, 20.0)  # type: ignore[arg-type]
    vut.command(pair, pov)  # type: ignore[arg-type]
    assert pair.log[0] == ("take_vut_control",)
    name, mean_speed = pair.log[-1]
    assert name == "command_vut_speed"
    # 30 m centre to centre at 20 m/s each: IDM brakes (d* = 10 + 30 = 40 m > 30 m).
    assert mean_speed < 20.0 and vut.accel_mps2(pair) < 0.0  # type: ignore[arg-type]
    assert vut.collided(False) is False and vut.collided(True) is True
    vut.sync(pair)  # type: ignore[arg-type]
    assert pair.log[-1][:2] == ("set_speed_state", None)


def test_idm_vut_judges_highway_env_collisions_with_a_highway_env_pov() -> None:
    pov = HighwayEnvPovLaw(HW, step_length_s=0.2, length_m=5.0)
    vut = idm_vut(judges=True)
    pair = FakePair((155.5, -4.8), (150.0, -4.8))  # 0.5 m bumper gap, same lane
    pair.pov_lane = 0
    vut.start(pair, 25.0)  # type: ignore[arg-type]
    pov.start(pair, 5.0)  # type: ignore[arg-type]
    assert vut.collided(True) is False  # SUMO's verdict is not used
    pov.command(pair, 0.0)  # type: ignore[arg-type]
    vut.command(pair, pov)  # type: ignore[arg-type]
    assert vut.collided(False) is True
    vut.start(pair, 25.0)  # type: ignore[arg-type]  # a new episode forgets it
    assert vut.collided(True) is False
