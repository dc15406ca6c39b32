"""highway-env's laws without SUMO: hand-computed cases and the configuration's guards."""

from __future__ import annotations

import math

import pytest

from sumo_ayss.config import ActuatorConfig, EnvConfig, SimConfig
from sumo_ayss.laws.hwenv import HighwayEnvIDM, HighwayEnvPov, idm_acceleration
from sumo_ayss.sim.actuator import pov_acceleration
from sumo_ayss.util.errors import ConfigError
from sumo_ayss.vuts.hwenv_kinematics import KinematicState, bicycle_step, collision_check


def test_idm_example_from_the_research_note() -> None:
    """v_pov 30, v_vut 10, h 1 m (d = 6 m), v0 30: +2.91 (10 m) / -4.06 (20 m) m/s².

    By hand: d* = s0 + 15 - 10·20/(2·sqrt(15)) = s0 - 10.82 (negative for s0 = 10: no
    clamp at zero); a = 3·(1 - (1/3)^4) - 3·(d*/6)^2.
    """
    for s0, expected in ((10.0, 2.907), (20.0, -4.06)):
        a = idm_acceleration(10.0, 30.0, 6.0, -20.0, distance_wanted_m=s0)
        d_star = s0 + 15.0 - 200.0 / (2 * math.sqrt(15.0))
        assert a == pytest.approx(3 * (1 - (1 / 3) ** 4) - 3 * (d_star / 6) ** 2)
        assert a == pytest.approx(expected, abs=0.01)


def test_idm_clip_and_free_road() -> None:
    assert idm_acceleration(20.0, 20.0, 1.0, 10.0) == -6.0  # ACC_MAX clip
    assert idm_acceleration(0.0, 20.0, None, 0.0) == 3.0  # free road from standstill
    assert idm_acceleration(20.0, 20.0, None, 0.0) == 0.0  # at v0


def test_target_speed_is_the_start_speed_clipped_to_the_lane_limit() -> None:
    idm = HighwayEnvIDM()
    idm.start(35.0)
    assert idm.v0_mps == 30.0
    idm.start(12.0)
    assert idm.v0_mps == 12.0
    fixed = HighwayEnvIDM(target_speed_mps=25.0)
    fixed.start(12.0)
    assert fixed.v0_mps == 25.0


def test_leader_is_centre_to_centre_within_lane_margin() -> None:
    idm = HighwayEnvIDM()
    own = KinematicState(0.0, 0.0, 0.0, 20.0)
    d, dv = idm.leader_terms(own, 0.0, 3.2, KinematicState(8.0, 2.6, 0.0, 15.0))
    assert (d, dv) == (8.0, 5.0)  # centre 2.6 m off = half width 1.6 + margin 1
    assert idm.leader_terms(own, 0.0, 3.2, KinematicState(8.0, 2.61, 0.0, 15.0))[0] is None
    assert idm.leader_terms(own, 0.0, 3.2, KinematicState(-0.1, 0.0, 0.0, 15.0))[0] is None


def test_explicit_euler_moves_with_the_old_speed() -> None:
    s = bicycle_step(KinematicState(0.0, 0.0, 0.0, 10.0), 3.0, 0.0, 0.1)
    assert (s.x_m, s.speed_mps) == (1.0, pytest.approx(10.3))
    assert bicycle_step(KinematicState(0, 0, 0, 0.1), -6.0, 0.0, 0.1).speed_mps == 0.0  # floor
    assert bicycle_step(KinematicState(0, 0, 0, 45.0), 10.0, 0.0, 0.1).speed_mps == 44.5  # cap


def test_pov_law_is_unclipped_and_the_lane_change_is_smooth() -> None:
    cfg = ActuatorConfig(mode="highway_env")
    assert pov_acceleration(25.0, 20.0, cfg) == pytest.approx(-8.333, abs=1e-3)
    assert pov_acceleration(25.0, 20.0, ActuatorConfig()) == -6.0
    pov = HighwayEnvPov()
    pov.start(KinematicState(0.0, 3.2, 0.0, 20.0), 3.2)
    pov.target_lane_y_m = 0.0
    lateral = []
    for _ in range(15):
        states = pov.advance(3, 1 / 15)
        lateral.append(states[-1].vy_mps)
    assert min(lateral) < -2.0  # moves right
    assert abs(pov.state.y_m) < 0.2 and abs(lateral[-1]) < 0.5  # nearly settled after 3 s


def test_collision_check_rotated_bodies() -> None:
    a = KinematicState(0.0, 0.0, 0.0, 10.0)
    assert collision_check(a, KinematicState(4.9, 0.0, 0.0, 10.0), 1 / 15) == (True, True)
    assert collision_check(a, KinematicState(5.1, 0.0, 0.0, 10.0), 1 / 15)[0] is False
    # 2.1 m apart laterally: clear when parallel, hit when the other is rotated
    assert collision_check(a, KinematicState(0.0, 2.1, 0.0, 10.0), 1 / 15)[0] is False
    assert collision_check(a, KinematicState(0.0, 2.1, 0.3, 10.0), 1 / 15)[0] is True


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"actuator": ActuatorConfig(mode="highway_env"), "case": "cut_in"}, "lateral_resolution"),
        (
            {"actuator": ActuatorConfig(mode="highway_env"), "sim": SimConfig(step_length_s=0.1)},
            "decision_period_s must equal",
        ),
    ],
)
def test_config_guards(kwargs: dict, match: str) -> None:
    with pytest.raises(ConfigError, match=match):
        EnvConfig(**kwargs)


def test_actuator_mode_errors_name_the_field() -> None:
    with pytest.raises(ConfigError, match=r"env\.actuator\.mode must be one of"):
        ActuatorConfig(mode="hwenv")  # type: ignore[arg-type]
    with pytest.raises(ConfigError, match=r"not used in mode highway_env"):
        ActuatorConfig(mode="highway_env", accel_min_mps2=-9.0)


def test_paper_fidelity_pipeline_plans_the_grid() -> None:
    """configs/paper_fidelity.yaml: both cases x hwenv pair x 3 seeds, highway-env laws."""
    from sumo_ayss.config import PROJECT_ROOT
    from sumo_ayss.pipeline import load_pipeline, plan_jobs

    jobs = plan_jobs(load_pipeline(PROJECT_ROOT / "configs" / "paper_fidelity.yaml"))
    assert sorted((j.case, j.vut, j.seed) for j in jobs) == sorted(
        (c, v, s)
        for c in ("car_following", "cut_in")
        for v in ("hwenv_pi1", "hwenv_pi2")
        for s in (0, 1, 2)
    )
    for job in jobs:
        env = job.experiment.env
        assert env.actuator.mode == "highway_env"
        assert env.odd.vut_speed_mps == (0.0, 40.0)
        controller = env.vuts[job.vut].controller
        assert controller is not None and controller.target == "highway_env_idm"
