"""SUMO's ``actionStepLength``: the testbed's semantics against a standalone SUMO run.

Semantics (issue 21): the VUT decides at the episode's first step and then every
``actionStepLength``, keeping its last acceleration in between. A standalone SUMO run of one
pair, both vehicles departing from a route file at t = 0 at the episode's initial state (no
libsumo placement), the leader driven on a scripted speed profile, is the reference: the
single env and a pair of the vec env must reproduce its VUT speeds and gaps exactly.
"""

from __future__ import annotations

import dataclasses
import itertools
from pathlib import Path

import libsumo
import pytest
import sumo

from sumo_ayss.config import EnvConfig
from sumo_ayss.envs.car_following import CarFollowingEnv
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.envs.vec_env import PairVecEnv
from sumo_ayss.sim.network import network_path
from sumo_ayss.vuts.catalog import VehicleType

pytestmark = pytest.mark.sumo

V0_MPS, GAP_M, START_M = 20.0, 12.0, 150.0
#: The leader brakes at 6 m/s² for 2 s, then holds 8 m/s.
PROFILE = [V0_MPS - 1.2 * min(k + 1, 10) for k in range(25)]
IDM = dict(accel=3, decel=5, emergencyDecel=6, tau=1.5, delta=4, minGap=5, length=5, speedDev=0)


def standalone(tmp_path: Path, asl: float) -> list[tuple[float, float]]:
    """(VUT speed, gap) after each of 25 steps of a plain ``sumo -c`` run."""
    attrs = " ".join(f'{k}="{v}"' for k, v in IDM.items())
    (tmp_path / "pair.rou.xml").write_text(
        f"""<routes>
  <vType id="vut" carFollowModel="IDM" {attrs} maxSpeed="40" actionStepLength="{asl}"/>
  <vType id="lead" length="5" minGap="0" speedDev="0" maxSpeed="50"/>
  <route id="r" edges="road"/>
  <vehicle id="lead" type="lead" route="r" depart="0" departPos="{START_M + GAP_M + 5}"
           departSpeed="{V0_MPS}"/>
  <vehicle id="vut" type="vut" route="r" depart="0" departPos="{START_M}"
           departSpeed="{V0_MPS}" insertionChecks="none"/>
</routes>"""
    )
    (tmp_path / "pair.sumocfg").write_text(
        f"""<configuration>
  <input><net-file value="{network_path("car_following")}"/>
         <route-files value="pair.rou.xml"/></input>
  <time><begin value="0"/><step-length value="0.2"/></time>
</configuration>"""
    )
    binary = str(Path(sumo.SUMO_HOME) / "bin" / "sumo")
    libsumo.start([binary, "-c", str(tmp_path / "pair.sumocfg"), "--no-step-log", "true",
                   "--no-warnings", "true", "--collision.action", "warn"])  # fmt: skip
    try:
        libsumo.simulationStep()  # t = 0: both depart at their initial state
        assert set(libsumo.vehicle.getIDList()) == {"lead", "vut"}
        libsumo.vehicle.setSpeedMode("lead", 0)
        out = []
        for v in PROFILE:
            libsumo.vehicle.setSpeed("lead", v)
            libsumo.simulationStep()
            gap = libsumo.vehicle.getLanePosition("lead") - 5.0
            out.append(
                (libsumo.vehicle.getSpeed("vut"), gap - libsumo.vehicle.getLanePosition("vut"))
            )
        return out
    finally:
        libsumo.close()


def config(asl: float) -> EnvConfig:
    vt = VehicleType.from_mapping(
        {"model": "IDM", "params": {**IDM, "maxSpeed": 40.0, "actionStepLength": asl}}, "vuts.r"
    )
    base = EnvConfig(case="car_following")
    return dataclasses.replace(base, vuts={**base.vuts, "r": vt}, vut="r")


def drive(pair, step) -> list[tuple[float, float]]:
    """The POV on :data:`PROFILE` (commanded speed, as the standalone leader)."""
    out = []
    for v in PROFILE:
        pair.command_pov_speed(v)
        step()
        pov_pos, _, vut_pos, vut_speed = pair.longitudinal()
        out.append((vut_speed, pov_pos - 5.0 - vut_pos))
    return out


@pytest.mark.parametrize("asl", [0.2, 0.6, 1.0])
def test_single_and_vec_env_reproduce_a_standalone_sumo_run(tmp_path: Path, asl: float) -> None:
    reference = standalone(tmp_path, asl)
    ic = InitialCondition(pov_speed_mps=V0_MPS, vut_speed_mps=V0_MPS, gap_m=GAP_M)
    env = CarFollowingEnv(config(asl), sumo_seed=1)
    try:
        env.reset(options={"initial_condition": ic})
        pair = env._pair
        assert pair is not None
        single = drive(pair, pair.session.step)
    finally:
        env.close()
    vec = PairVecEnv(config(asl), n_envs=2, sumo_seed=1)
    try:
        vec.reset()
        member, member_pair = vec.envs[1], vec.envs[1]._pair
        assert member_pair is not None
        member_pair.add()  # a fresh pair placed while waiting for insertion, as a reset does
        member.start_episode(ic)
        pairs = drive(member_pair, libsumo.simulationStep)
    finally:
        vec.close()
    assert single == reference
    assert pairs == reference
    if asl == 1.0:  # decisions at steps 1, 6, 11, 16, 21: constant acceleration between
        speeds = [V0_MPS] + [v for v, _gap in reference]
        dv = [b - a for a, b in itertools.pairwise(speeds)]  # dv[j]: step j + 1
        assert all(d == pytest.approx(dv[10]) for d in dv[10:15])
        assert dv[15] != pytest.approx(dv[10])
