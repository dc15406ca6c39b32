"""A user controller as the VUT: the protocol without SUMO, then driven through SUMO.

The SUMO tests step a :class:`~sumo_ayss.sim.pair.VehiclePair` by hand (session + pair +
:class:`~sumo_ayss.vuts.controllers.ControlledVut`), the way the env's controller law
(:class:`~sumo_ayss.laws.controller.ControllerVut`) does before each SUMO step, so they do
not depend on :class:`~sumo_ayss.envs.pair_env.PairEnv`.
"""

from __future__ import annotations

import math
import pickle
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

from examples.acc_controller import TimeGapACC
from sumo_ayss.config import PROJECT_ROOT, EnvConfig, SimConfig, env_config_from_mapping
from sumo_ayss.envs import make_env
from sumo_ayss.sim.pair import VutSensing
from sumo_ayss.util.errors import ConfigError
from sumo_ayss.vuts.catalog import POV_TYPE, ControllerSpec, VehicleType
from sumo_ayss.vuts.controllers import (
    ControlledVut,
    Controller,
    ControllerError,
    ControllerInput,
    bound_acceleration,
    commanded_speed,
)

ACC = "examples.acc_controller:TimeGapACC"
ACC_FILE = str(PROJECT_ROOT / "examples" / "acc_controller.py") + ":TimeGapACC"


def acc_spec(time_gap_s: float = 1.5, **kw: Any) -> ControllerSpec:
    return ControllerSpec(ACC, 3.0, 6.0, params={"time_gap_s": time_gap_s}, **kw)


def state(
    speed: float = 20.0, gap: float = math.inf, rel: float = 0.0, lane: int = 0
) -> ControllerInput:
    return ControllerInput(0.0, 0.2, speed, gap, rel, lane)


# --------------------------------------------------------------------------- pure protocol


def test_input_from_sensing_sign_convention() -> None:
    ahead = ControllerInput.from_sensing(VutSensing(1.0, 20.0, 0, 12.0, 15.0), 0.2)
    assert ahead.has_leader and ahead.gap_m == 12.0
    assert ahead.rel_speed_mps == pytest.approx(-5.0)  # leader slower: the gap closes
    free = ControllerInput.from_sensing(VutSensing(1.0, 20.0, 1, math.inf, math.nan), 0.2)
    assert not free.has_leader and free.rel_speed_mps == 0.0 and free.lane_index == 1


def test_bounds_and_speed_integration() -> None:
    assert bound_acceleration(100.0, 3.0, 6.0) == 3.0
    assert bound_acceleration(-100, 3.0, 6.0) == -6.0
    assert bound_acceleration(-2.5, 3.0, 6.0) == -2.5
    for bad in (math.nan, math.inf, "fast", None, True):
        with pytest.raises(ControllerError):
            bound_acceleration(bad, 3.0, 6.0)
    assert commanded_speed(20.0, 2.0, 0.2, 40.0) == pytest.approx((20.4, 2.0))
    assert commanded_speed(0.5, -6.0, 0.2, 40.0) == pytest.approx((0.0, -2.5))  # stops at 0
    assert commanded_speed(39.9, 3.0, 0.2, 40.0) == pytest.approx((40.0, 0.5))  # top speed


def test_time_gap_acc_law() -> None:
    acc = TimeGapACC(time_gap_s=2.0, standstill_gap_m=5.0)
    assert isinstance(acc, Controller)
    assert acc.acceleration(state(20.0, 45.0, 0.0)) == pytest.approx(0.0)  # s0 + T·v
    assert acc.acceleration(state(20.0, 30.0, 0.0)) < 0  # too close: brake
    assert acc.acceleration(state(20.0, 45.0, -3.0)) < 0  # closing in: brake
    assert acc.acceleration(state(20.0)) == pytest.approx(3.0)  # free road: cruise to 30
    assert acc.acceleration(state(30.0)) == pytest.approx(0.0)
    assert acc.acceleration(state(25.0, 1.0, -10.0)) == -6.0  # its own braking limit
    with pytest.raises(ValueError, match="time_gap_s"):
        TimeGapACC(time_gap_s=0.0)


def point_mass_gap(time_gap_s: float, seconds: float = 40.0) -> float:
    """The protocol in a pure point-mass loop (no SUMO): leader at a constant 20 m/s."""
    acc, dt = TimeGapACC(time_gap_s=time_gap_s), 0.2
    v, gap, v_lead = 20.0, 30.0, 20.0
    for k in range(round(seconds / dt)):
        s = ControllerInput(k * dt, dt, v, gap, v_lead - v, 0)
        a = bound_acceleration(acc.acceleration(s), 3.0, 6.0)
        v_next, _ = commanded_speed(v, a, dt, 40.0)
        gap += (v_lead - v_next) * dt  # Euler, as SUMO: the new speed over the whole step
        v = v_next
    return gap


def test_larger_time_gap_keeps_larger_gap_without_sumo() -> None:
    g1, g2 = point_mass_gap(1.0), point_mass_gap(2.0)
    assert g1 == pytest.approx(5.0 + 1.0 * 20.0, abs=0.5)
    assert g2 == pytest.approx(5.0 + 2.0 * 20.0, abs=0.5)


# --------------------------------------------------------------------------- configuration


def test_spec_builds_from_module_and_file() -> None:
    for target in (ACC, ACC_FILE):
        built = ControllerSpec(target, 3.0, 6.0, params={"time_gap_s": 2.0}).build()
        assert built.time_gap_s == 2.0 and callable(built.acceleration)


def test_vehicle_type_mapping_round_trip() -> None:
    data = {
        "description": "ACC, T = 2 s",
        "params": {"length": 4.5},
        "controller": {
            "target": ACC,
            "params": {"time_gap_s": 2.0},
            "max_accel_mps2": 2.5,
            "max_decel_mps2": 7.0,
        },
    }
    vt = VehicleType.from_mapping(data, "env.vuts.acc")
    assert vt.controller is not None and vt.controller.max_decel_mps2 == 7.0
    again = VehicleType.from_mapping(vt.to_dict(), "env.vuts.acc")
    assert again == vt
    # SUMO-model VUTs keep their old plain form (run folders written before stay valid).
    assert "controller" not in VehicleType("IDM", {"tau": 1.0}).to_dict()


@pytest.mark.parametrize(
    ("controller", "match"),
    [
        ({"target": "nocolon", "max_accel_mps2": 3, "max_decel_mps2": 6}, r"target must be"),
        (
            {"target": "examples.nope:X", "max_accel_mps2": 3, "max_decel_mps2": 6},
            r"cannot import 'examples\.nope'",
        ),
        (
            {"target": "examples.acc_controller:Nope", "max_accel_mps2": 3, "max_decel_mps2": 6},
            r"has no attribute 'Nope'",
        ),
        (
            {"target": ACC, "params": {"time_gapp_s": 2}, "max_accel_mps2": 3, "max_decel_mps2": 6},
            r"x\.controller\.params .* rejected .*time_gapp_s",
        ),
        ({"target": ACC, "max_accel_mps2": 3}, r"x\.controller\.max_decel_mps2 is required"),
        (
            {"target": ACC, "max_accel_mps2": 0, "max_decel_mps2": 6},
            r"x\.controller\.max_accel_mps2 must be > 0, got 0",
        ),
        (
            {"target": "math:pi", "max_accel_mps2": 3, "max_decel_mps2": 6},
            r"'math:pi' is a float, not a class",
        ),
        (
            {"target": "builtins:dict", "max_accel_mps2": 3, "max_decel_mps2": 6},
            r"no acceleration\(state\) method",
        ),
        (
            {"target": ACC, "max_accel_mps2": 3, "max_decel_mps2": 6, "gain": 1},
            r"unknown key 'gain'",
        ),
    ],
)
def test_controller_config_errors(controller: dict[str, Any], match: str) -> None:
    """Form errors when the config is read; target and params errors when it is built."""
    with pytest.raises(ConfigError, match=match):
        vt = VehicleType.from_mapping({"controller": controller}, "x")
        assert vt.controller is not None
        vt.controller.build("x.controller")


def test_reading_a_controller_vut_runs_no_user_code(tmp_path: Path) -> None:
    """The target is imported, and its constructor run, when an env is built, not before."""
    marker = tmp_path / "imported"
    module = tmp_path / "marked_controller.py"
    module.write_text(
        f"import pathlib\npathlib.Path({str(marker)!r}).touch()\n"
        "class C:\n    def acceleration(self, state):\n        return 0.0\n"
    )
    spec = {"target": f"{module}:C", "max_accel_mps2": 3.0, "max_decel_mps2": 6.0}
    cfg = env_config_from_mapping({"vut": "m", "vuts": {"m": {"controller": spec}}}, tmp_path)
    assert cfg.vut_type.controller is not None and not marker.exists()
    assert pickle.loads(pickle.dumps(cfg)) == cfg and not marker.exists()
    ControlledVut.from_vehicle_type(cfg.vut_type, 0.2)
    assert marker.exists()


def test_controller_vut_refuses_car_following_parameters() -> None:
    with pytest.raises(ConfigError, match=r"x\.params \['tau'\] would be ignored"):
        VehicleType(params={"tau": 1.0}, controller=acc_spec()).validate("x")


def test_env_config_accepts_a_controller_vut() -> None:
    cfg = EnvConfig(vut="acc", vuts={"acc": VehicleType(controller=acc_spec(2.0))})
    assert cfg.vut_type.controller is not None
    ctl = ControlledVut.from_vehicle_type(cfg.vut_type, cfg.sim.step_length_s)
    assert ctl is not None and ctl.controller.time_gap_s == 2.0
    assert ControlledVut.from_vehicle_type(VehicleType(), 0.2) is None


def test_yaml_controller_vut_needs_the_config_hook(tmp_path: Path) -> None:
    """YAML support goes through ``VehicleType.from_mapping`` once config.py delegates to it."""
    data = {"vut": "acc", "vuts": {"acc": {"controller": acc_spec(2.0).to_dict()}}}
    try:
        cfg = env_config_from_mapping(data, tmp_path)
    except ConfigError as e:
        pytest.skip(f"config.py does not parse controller VUTs yet: {e}")
    assert cfg.vut_type.controller == acc_spec(2.0)


# --------------------------------------------------------------------------- through SUMO


@dataclass
class Constant:
    """A controller that always asks for the same acceleration (to test the bounds)."""

    accel_mps2: float = 100.0

    def acceleration(self, state: ControllerInput) -> float:
        return self.accel_mps2


@contextmanager
def sumo_pair(vut: VehicleType, case: str = "car_following") -> Iterator[Any]:
    """A live session with one pair on the case's built-in road; closed on exit."""
    from sumo_ayss.sim.network import ROAD_EDGE, network_path
    from sumo_ayss.sim.pair import VehiclePair
    from sumo_ayss.sim.session import SumoSession

    session = SumoSession(
        network_path(case),  # type: ignore[arg-type]
        {"vut_x": vut, "pov": POV_TYPE},
        SimConfig(),
        seed=0,
        owner="test_controllers",
    )
    session.start()
    try:
        pair = VehiclePair(session, vut_type="vut_x", pov_type="pov", edge=ROAD_EDGE)
        pair.add()
        session.step()  # insertion
        yield session, pair
    finally:
        session.close()


def follow(time_gap_s: float, seconds: float = 30.0) -> tuple[float, float]:
    """ACC behind a POV at a constant 20 m/s; returns (final gap [m], final VUT speed)."""
    from sumo_ayss.sim.pair import PairPlacement

    vt = VehicleType(params={"length": 5.0}, controller=acc_spec(time_gap_s))
    with sumo_pair(vt) as (session, pair):
        pair.place(PairPlacement(150.0, 20.0, 0, 150.0 + 30.0 + 5.0, 20.0, 0))
        ctl = ControlledVut.from_vehicle_type(vt, 0.2)
        assert ctl is not None
        ctl.start(pair)
        for _ in range(round(seconds / 0.2)):
            pair.command_pov_speed(20.0)
            ctl.before_step(pair)
            session.step()
            assert not pair.collided(session.colliding_ids())
        pov_pos, _, vut_pos, v_vut = pair.longitudinal()
        return pov_pos - 5.0 - vut_pos, v_vut


@pytest.mark.sumo
def test_larger_time_gap_keeps_larger_gap_in_sumo() -> None:
    """After 30 s behind a POV at 20 m/s, each ACC sits near its s0 + T·v."""
    gap1, v1 = follow(1.0)
    gap2, v2 = follow(2.0)
    assert gap1 == pytest.approx(5.0 + 1.0 * 20.0, abs=0.5)
    assert gap2 == pytest.approx(5.0 + 2.0 * 20.0, abs=0.5)
    assert gap2 > gap1 + 15.0
    assert v1 == pytest.approx(20.0, abs=0.1) and v2 == pytest.approx(20.0, abs=0.1)


@pytest.mark.sumo
@pytest.mark.parametrize("request_mps2", [100.0, -100.0, 1.7])
def test_commands_are_bounded_and_act_in_the_next_step(request_mps2: float) -> None:
    from sumo_ayss.sim.pair import PairPlacement

    spec = ControllerSpec("builtins:dict", 2.5, 4.0)  # target unused: the instance is given
    vt = VehicleType(params={"length": 5.0})
    with sumo_pair(vt) as (session, pair):
        pair.place(PairPlacement(150.0, 25.0, 0, 400.0, 25.0, 0))
        ctl = ControlledVut(Constant(request_mps2), spec, 0.2)
        ctl.start(pair)
        expected = min(max(request_mps2, -4.0), 2.5)
        for _ in range(5):
            _, _, x_before, v_before = pair.longitudinal()
            realised = ctl.before_step(pair)
            pair.command_pov_speed(25.0)
            session.step()
            _, _, x_after, v_after = pair.longitudinal()
            # The command computed from the state after step t acts during step t + 1, and
            # SUMO's Euler update moves the VUT by the new speed times the step.
            assert v_after == pytest.approx(v_before + realised * 0.2, abs=1e-9)
            assert x_after - x_before == pytest.approx(v_after * 0.2, abs=1e-9)
            assert realised == pytest.approx(expected)
            assert pair.vut_accel_mps2() == pytest.approx(expected, abs=1e-9)
            assert -4.0 - 1e-9 <= pair.vut_accel_mps2() <= 2.5 + 1e-9
            assert ctl.last_request_mps2 == request_mps2


@pytest.mark.sumo
def test_cut_in_counts_as_leader_once_it_reaches_into_the_lane() -> None:
    """The POV changes from the left lane into the VUT's lane 8 m ahead."""
    from sumo_ayss.sim.pair import PairPlacement

    vt = VehicleType(params={"length": 5.0, "width": 1.8}, controller=acc_spec(1.5))
    with sumo_pair(vt, "cut_in") as (session, pair):
        pair.place(PairPlacement(150.0, 20.0, 0, 150.0 + 8.0 + 5.0, 20.0, 1))
        ctl = ControlledVut.from_vehicle_type(vt, 0.2)
        assert ctl is not None
        ctl.start(pair)
        assert not ctl.observe(pair).has_leader  # POV centred in the next lane
        pair.change_pov_lane(0, 5.0)
        seen = []
        for _ in range(7):
            pair.command_pov_speed(20.0)
            ctl.before_step(pair)
            session.step()
            s = ctl.observe(pair)
            pov_lane, _ = pair.lanes()
            pov_pos, v_pov, vut_pos, v_vut = pair.longitudinal()
            offset = pair.pov_lateral_offset_m()
            # Lane 1 centre is 3.2 m left of lane 0's; POV body edge = centre - 0.9 m.
            body_in_lane = (3.2 * pov_lane + offset) - 0.9 < 1.6
            seen.append((s.has_leader, pov_lane))
            assert s.has_leader == body_in_lane
            if s.has_leader:
                assert s.gap_m == pytest.approx(pov_pos - 5.0 - vut_pos, abs=1e-9)
                assert s.rel_speed_mps == pytest.approx(v_pov - v_vut, abs=1e-9)
        # Seen as leader while its lane index still says lane 1, before it flips.
        assert (True, 1) in seen and (True, 0) in seen


@pytest.mark.sumo
@pytest.mark.parametrize("case", ["car_following", "cut_in"])
def test_controller_vut_in_env(case: str) -> None:
    """One episode with the ACC as VUT: the POV brakes to half its speed (car-following)
    or cuts in 8 m ahead and slows to 15 m/s (cut-in); the ACC brakes, within its limits."""
    from sumo_ayss.envs.odd import InitialCondition

    cfg = EnvConfig(case=case, vut="acc", vuts={"acc": VehicleType(controller=acc_spec(2.0))})  # type: ignore[arg-type]
    env = make_env(cfg, sumo_seed=0)  # its VUT law drives the controller (sumo_ayss.laws)
    gap = 30.0 if case == "car_following" else 8.0
    actions = [1] * 25 if case == "car_following" else [0] + [16] * 24
    try:
        env.reset(options={"initial_condition": InitialCondition(20.0, 20.0, gap)})
        accels = []
        for action in actions:
            obs, _, terminated, truncated, info = env.step(action)
            accels.append(info["vut_accel_mps2"])
            assert math.isfinite(float(obs.sum())) and not info["collision"]
            if terminated or truncated:
                break
        assert min(accels) < -1.0  # the ACC brakes for the braking / cutting-in POV
        assert all(-6.0 - 1e-9 <= a <= 3.0 + 1e-9 for a in accels)
    finally:
        env.close()


def test_file_target_resolves_relative_to_the_yaml_not_the_working_dir(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from sumo_ayss.config import load_experiment

    project = tmp_path / "project"
    (project / "ctl").mkdir(parents=True)
    (project / "ctl" / "hold.py").write_text(
        "class Hold:\n    def acceleration(self, state):\n        return 0.0\n"
    )
    exp = project / "exp.yaml"
    exp.write_text(
        "env:\n  vut: hold\n  vuts:\n    hold:\n      controller:\n"
        "        target: ctl/hold.py:Hold\n        max_accel_mps2: 3.0\n"
        "        max_decel_mps2: 6.0\n"
    )
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)  # "ctl/hold.py" does not exist here
    spec = load_experiment(exp).env.vut_type.controller
    assert spec is not None
    assert spec.target == f"{(project / 'ctl' / 'hold.py').resolve()}:Hold"
    assert type(spec.build("hold")).__name__ == "Hold"
