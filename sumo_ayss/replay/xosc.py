"""Export one scenario of a run as ASAM OpenSCENARIO 1.x with its OpenDRIVE road (issue 27).

``python -m sumo_ayss.replay export RUN_DIR --outcome-row K --format xosc --out DIR``
reruns the row's episode exactly as the SUMO export does (a fresh env of the run's config,
SUMO seed = the run's seed, the row's initial condition, the run's SPCP or a given policy)
and writes, with the maintained ``scenariogeneration`` library:

* ``road.xodr`` — OpenDRIVE 1.x: the run's straight road (length, lane count and width
  read from its SUMO network), all lanes to the right of the reference line, which lies on
  the road's left edge; SUMO lane ``i`` (0 = rightmost) is OpenDRIVE lane ``-(n - i)``;
* ``scenario.xosc`` — OpenSCENARIO 1.2: the VUT (``ego``) and the POV with their bodies
  (length, width from the vehicle types), their initial position and speed, and each
  vehicle's recorded trajectory as a ``FollowTrajectoryAction`` along a timed polyline
  (one vertex per decision, absolute times, following mode ``position``): a player that
  follows it reproduces the episode's motion whatever its own driver model;
* ``xosc.json`` — where it came from and whether the rerun reproduced the row.

Coordinates: world x along the road from its start, y to the left, both shifted so that
the OpenDRIVE reference line is y = 0 (on the built-in roads this is SUMO's own frame).
A vehicle's OpenSCENARIO reference point is the centre of its rear axle; SUMO has no
axles, so both axles are placed :data:`OVERHANG_M` inside the body's ends (an assumption
that moves no body: the bounding box is placed relative to that point).

The SUMO export (:mod:`sumo_ayss.replay.record`) stays as it is.
"""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sumo_ayss.config import EnvConfig
from sumo_ayss.envs import make_env
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.envs.pair_env import PairEnv
from sumo_ayss.replay.source import initial_condition, load_policy, read_row, select_row
from sumo_ayss.run_folder import read_run
from sumo_ayss.scenarios.rollout import Policy
from sumo_ayss.scenarios.trajectory import (
    SecondPovTrack,
    body_width_m,
    follower_of,
    second_pov_of,
    trajectory_from_infos,
)
from sumo_ayss.sim.network import network_path
from sumo_ayss.util.atomic import atomic_write_text, atomic_write_with
from sumo_ayss.util.errors import ConfigError, SimulationError
from sumo_ayss.util.paths import portable_path
from sumo_ayss.vuts.catalog import controller_imports

__all__ = ["OVERHANG_M", "XODR_FILE", "XOSC_FILE", "XoscResult", "export_xosc"]

XOSC_FILE = "scenario.xosc"
XODR_FILE = "road.xodr"
INFO_FILE = "xosc.json"
#: OpenSCENARIO minor version written (1.2: widely supported, its XSD ships with ASAM's
#: checker).
OSC_MINOR_VERSION = 2
#: Axle inset from each end of the body [m] (SUMO models no axles; an assumption).
OVERHANG_M = 1.0
#: Vehicle height [m] for the bounding box (SUMO's passenger-car default 1.5 m).
HEIGHT_M = 1.5


@dataclass(frozen=True)
class XoscResult:
    """What :func:`export_xosc` wrote: the folder, its two files, and ``xosc.json``'s content."""

    out: Path
    xosc: Path
    xodr: Path
    info: dict[str, Any]


@dataclass(frozen=True)
class _Road:
    length_m: float
    lane_width_m: float
    n_lanes: int
    y_ref_m: float  # world y of the road's left edge (the OpenDRIVE reference line)
    centres_y_m: tuple[float, ...]  # world y of each SUMO lane's centre, index 0 = rightmost


def _read_road(net: Path) -> _Road:
    """The straight road of a SUMO network file (one edge, lanes along +x)."""
    try:
        lanes = [
            ln
            for ln in ET.parse(net).getroot().iter("lane")
            if not ln.get("id", "").startswith(":")
        ]
    except (OSError, ET.ParseError) as e:
        raise ConfigError(f"{net}: not a readable SUMO network ({e})") from e
    lanes.sort(key=lambda ln: int(ln.get("index", "0")))
    shapes = [
        [tuple(map(float, p.split(","))) for p in ln.get("shape", "").split()] for ln in lanes
    ]
    widths = {float(ln.get("width", "3.2")) for ln in lanes}
    straight = all(len(s) == 2 and s[0][1] == s[1][1] for s in shapes)
    if not lanes or len(widths) != 1 or not straight:
        raise ConfigError(f"{net}: the OpenSCENARIO export needs one straight road of equal lanes")
    width = widths.pop()
    centres = tuple(s[0][1] for s in shapes)
    return _Road(
        float(lanes[0].get("length", "0")),
        width,
        len(lanes),
        max(centres) + 0.5 * width,
        centres,
    )


def _record(
    env_cfg: EnvConfig, seed: int, ic: InitialCondition, policy: Policy, limit: int | None
) -> tuple[dict[str, Any], list[dict[str, Any]], list[int], list[float]]:
    env = make_env(env_cfg, sumo_seed=seed)
    base = env.unwrapped
    assert isinstance(base, PairEnv)
    try:
        obs, reset_info = base.reset(options={"initial_condition": ic})
        infos: list[dict[str, Any]] = []
        actions: list[int] = []
        rewards: list[float] = []
        done = False
        while not done and (limit is None or len(infos) < limit):
            action = int(np.asarray(policy(obs[None, :])).reshape(-1)[0])
            obs, reward, terminated, truncated, info = base.step(action)
            actions.append(action)
            rewards.append(float(reward))
            infos.append(info)
            done = bool(terminated or truncated)
    finally:
        env.close()
    return reset_info, infos, actions, rewards


def _xodr(road: _Road, path: Path) -> None:
    from scenariogeneration import xodr

    r = xodr.create_road(
        xodr.Line(road.length_m),
        id=0,
        left_lanes=0,
        right_lanes=road.n_lanes,
        lane_width=road.lane_width_m,
    )
    odr = xodr.OpenDrive("sumo_ayss_straight_road")
    odr.add_road(r)
    odr.adjust_roads_and_lanes()
    atomic_write_with(path, lambda tmp: odr.write_xml(str(tmp)))


def _vehicle(name: str, length_m: float, width_m: float, max_speed_mps: float) -> Any:
    from scenariogeneration import xosc

    # Reference point: the rear axle's centre, OVERHANG_M in front of the rear bumper.
    bb = xosc.BoundingBox(
        width_m, length_m, HEIGHT_M, 0.5 * length_m - OVERHANG_M, 0, 0.5 * HEIGHT_M
    )
    front = xosc.Axle(0.0, 0.6, width_m - 0.2, length_m - 2 * OVERHANG_M, 0.3)
    rear = xosc.Axle(0.0, 0.6, width_m - 0.2, 0.0, 0.3)
    # Performance: bounds that never clip the recorded motion (|acceleration| <= 9 m/s² here).
    return xosc.Vehicle(name, xosc.VehicleCategory.car, bb, front, rear, max_speed_mps, 15.0, 15.0)


def _xosc(
    tr: Any,
    road: _Road,
    y_vut: np.ndarray,
    y_pov: np.ndarray,
    path: Path,
    description: str,
    follower: tuple[np.ndarray, np.ndarray, float, float] | None = None,
    pov2: SecondPovTrack | None = None,
) -> None:
    from scenariogeneration import xosc

    entities = xosc.Entities()
    init = xosc.Init()
    act = xosc.Act(
        "episode",
        xosc.ValueTrigger(
            "episode_start",
            0,
            xosc.ConditionEdge.none,
            xosc.SimulationTimeCondition(0, xosc.Rule.greaterThan),
        ),
    )
    bodies = {
        "ego": (tr.vut_x_m, y_vut, tr.vut_speed_mps, tr.vut_length_m, tr.vut_width_m),
        "pov": (tr.pov_x_m, y_pov, tr.pov_speed_mps, tr.pov_length_m, tr.pov_width_m),
    }
    if follower is not None:  # issue 33: in the VUT's lane; its samples until a rear-end
        fx, fv, f_len, f_wid = follower
        alive = int(np.isfinite(fx).sum())
        bodies["follower"] = (fx[:alive], y_vut[:alive], fv[:alive], f_len, f_wid)
    if pov2 is not None:  # issue 39: the supporting POV, in the POV's body
        bodies["pov2"] = (pov2.x_m, pov2.y_m, pov2.speed_mps, tr.pov_length_m, tr.pov_width_m)
    all_times = [float(t) for t in tr.time_s]
    for name, (x_front, y, speed, length, width) in bodies.items():
        times = all_times[: len(x_front)]
        entities.add_scenario_object(name, _vehicle(name, length, width, 50.0))
        # the rear axle: OVERHANG_M in front of the rear bumper; coordinates from the road
        xs = np.asarray(x_front) - length + OVERHANG_M  # lane positions: x from the road start
        ys = np.asarray(y) - road.y_ref_m
        positions = [
            xosc.WorldPosition(float(xv), float(yv), 0, 0) for xv, yv in zip(xs, ys, strict=True)
        ]
        init.add_init_action(name, xosc.TeleportAction(positions[0]))
        init.add_init_action(
            name,
            xosc.AbsoluteSpeedAction(
                float(speed[0]),
                xosc.TransitionDynamics(xosc.DynamicsShapes.step, xosc.DynamicsDimension.time, 0),
            ),
        )
        if len(times) < 2:
            continue
        trajectory = xosc.Trajectory(f"{name}_recorded", False)
        trajectory.add_shape(xosc.Polyline(times, positions))
        follow = xosc.FollowTrajectoryAction(
            trajectory, xosc.FollowingMode.position, xosc.ReferenceContext.absolute, 1, 0
        )
        event = xosc.Event(f"{name}_follows_recording", xosc.Priority.override)
        event.add_action(f"{name}_trajectory", follow)
        event.add_trigger(
            xosc.ValueTrigger(
                f"{name}_start",
                0,
                xosc.ConditionEdge.none,
                xosc.SimulationTimeCondition(0, xosc.Rule.greaterThan),
            )
        )
        maneuver = xosc.Maneuver(f"{name}_maneuver")
        maneuver.add_event(event)
        group = xosc.ManeuverGroup(f"{name}_group")
        group.add_actor(name)
        group.add_maneuver(maneuver)
        act.add_maneuver_group(group)
    story = xosc.Story("recorded_episode")
    story.add_act(act)
    stop = xosc.ValueTrigger(
        "episode_end",
        0,
        xosc.ConditionEdge.rising,
        xosc.SimulationTimeCondition(times[-1], xosc.Rule.greaterThan),
        "stop",
    )
    board = xosc.StoryBoard(init, stop)
    board.add_story(story)
    scenario = xosc.Scenario(
        description,
        "sumo_ayss",
        xosc.ParameterDeclarations(),
        entities,
        board,
        xosc.RoadNetwork(roadfile=XODR_FILE),
        xosc.Catalog(),
        osc_minor_version=OSC_MINOR_VERSION,
    )
    atomic_write_with(path, lambda tmp: scenario.write_xml(str(tmp)))


def export_xosc(
    run_dir: str | Path,
    out: str | Path,
    *,
    ayss_row: int | None = None,
    outcome_row: int | None = None,
    decisions: int | None = None,
    policy: Policy | None = None,
    trust_controller: bool = False,
) -> XoscResult:
    """Write one scenario of a run as OpenSCENARIO + OpenDRIVE (see the module docstring).

    Arguments as :func:`sumo_ayss.replay.record.export_scenario`.

    Raises:
        ConfigError: If the row selection, ``decisions`` or the road is not supported.
        CheckpointError: If the run folder, a table or the SPCP cannot be read.
        SimulationError: If SUMO fails.
    """
    kind, index = select_row(ayss_row, outcome_row, decisions)
    out = Path(out)
    with controller_imports(trust_controller):
        run = read_run(run_dir)
        env_cfg: EnvConfig = run.experiment.env  # raises first if not a run folder
        row = read_row(run.folder, kind, index)
        ic = initial_condition(kind, row, run)
        pol = policy if policy is not None else load_policy(run)
        limit = decisions if decisions is not None else (1 if kind == "ayss" else None)
        reset_info, infos, actions, rewards = _record(env_cfg, run.config_seed, ic, pol, limit)
    if not infos:
        raise SimulationError("the episode recorded no decision")
    net = env_cfg.network if env_cfg.network is not None else network_path(env_cfg.case)
    road = _read_road(Path(net))
    tr = trajectory_from_infos(env_cfg, reset_info, infos)
    lane0 = np.full(tr.n, road.centres_y_m[0])
    y_vut = tr.vut_y_m if "vut_y_m" in reset_info else lane0
    y_pov = tr.pov_y_m if "pov_y_m" in reset_info else lane0
    out.mkdir(parents=True, exist_ok=True)
    _xodr(road, out / XODR_FILE)
    description = f"{kind} row {index} of {portable_path(run.path)} ({env_cfg.case}, {env_cfg.vut})"
    track = follower_of(reset_info, infos)
    fol = None
    if track is not None:
        f_type = env_cfg.follower.sumo_type
        f_len = float(f_type.params.get("length", 5.0))
        fol = (track.x_m, track.speed_mps, f_len, body_width_m(f_type))
    pov2 = second_pov_of(reset_info, infos)
    _xosc(tr, road, y_vut, y_pov, out / XOSC_FILE, description, fol, pov2)
    collided = bool(infos[-1]["collision"])
    reproduced: dict[str, bool]
    if kind == "ayss":
        reproduced = {"action": actions[0] == row["action"]}
    else:
        reproduced = {
            "episode_return": bool(np.isclose(sum(rewards), row["episode_return"], atol=1e-6)),
            "collided": collided == bool(row["collided"]),
            "n_steps": len(infos) == row["n_steps"],
        }
    info = {
        "source": {"run_dir": portable_path(run.path), "kind": kind, "row": index},
        "case": env_cfg.case,
        "vut": env_cfg.vut,
        "sumo_seed": run.config_seed,
        "decisions": len(infos),
        "decision_period_s": env_cfg.decision_period_s,
        "collided": collided,
        "reproduces_row": reproduced,
        "openscenario": f"1.{OSC_MINOR_VERSION}",
        "bodies_m": {
            "ego": [tr.vut_length_m, body_width_m(env_cfg.vut_type)],
            "pov": [tr.pov_length_m, body_width_m(env_cfg.pov)],
            **({"pov2": [tr.pov_length_m, body_width_m(env_cfg.pov)]} if pov2 else {}),
        },
        "axle_overhang_m": OVERHANG_M,
        "files": {"scenario": XOSC_FILE, "road": XODR_FILE},
    }
    atomic_write_text(out / INFO_FILE, json.dumps(info, indent=2) + "\n")
    return XoscResult(out, out / XOSC_FILE, out / XODR_FILE, info)
