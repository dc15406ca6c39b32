"""SUMO files of a replayable scenario: trajectories (FCD), the replay config, the binaries.

Replay mechanism: SUMO's own **fcd-replay device** (``--device.fcd-replay.files``, in SUMO
since 1.20, checked on 1.28). Given an FCD file (SUMO's ``--fcd-output`` format), SUMO
creates every vehicle of the file at the time of its first record, at that record's lane
and lane position, and from then on, in every step, moves it to the next record's
``x``/``y`` (``moveToXY``) and sets its speed to the record's ``speed``, one record per step
(the records must therefore be one step length apart). ``sumo`` and ``sumo-gui`` both run
it from a plain ``.sumocfg``; no TraCI and no Python are needed to watch a scenario.

Two properties of the device shape the files written here (both checked on SUMO 1.28):

* A vehicle's first record only inserts it, with SUMO's usual insertion (its speed is not
  applied: SUMO inserted at the lane's speed limit; a vehicle that cannot be inserted
  safely waits, which would shift its trajectory by a step). So every trajectory starts
  with an *insertion record* at ``t = 0`` that parks the vehicles far apart on lane 0 (VUT
  at 10 m, POV at 310 m), and the scenario's initial state follows at ``t = dt``. Scenario
  time ``τ`` (0 = the initial condition) is therefore file time ``t = τ + dt``.
* The replayed positions and speeds equal the records at every later step (to the FCD
  file's printed precision).

Only this module (and the rest of :mod:`sumo_ayss.sim`) talks to SUMO.
"""

from __future__ import annotations

import os
import subprocess
import xml.etree.ElementTree as ET
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from xml.sax.saxutils import quoteattr

import libsumo

from sumo_ayss.config import SimConfig
from sumo_ayss.sim.network import sumo_binary, sumo_home
from sumo_ayss.sim.session import SUMO_ERRORS
from sumo_ayss.util.atomic import atomic_write_text
from sumo_ayss.util.errors import SimulationError

__all__ = [
    "INSERTION_POS_M",
    "FcdPoint",
    "fcd_output_args",
    "gui_command",
    "insertion_points",
    "read_fcd",
    "run_headless",
    "snapshot",
    "sumo_env",
    "write_fcd",
    "write_gui_settings",
    "write_sumocfg",
]

#: Lane positions [m] of the insertion record (lane 0), by vehicle id: far enough apart that
#: SUMO inserts both at once at any speed up to 40 m/s (see :func:`insertion_points`).
INSERTION_POS_M = {"vut": 10.0, "pov": 310.0}
#: Distance [m] between further vehicles of an insertion record.
INSERTION_SPACING_M = 300.0

#: Decimals of positions and speeds in the FCD files written here (1 µm, 1 µm/s).
FCD_PRECISION = 6


@dataclass(frozen=True)
class FcdPoint:
    """One vehicle at one time, as in SUMO's FCD output (front bumper, world frame).

    Attributes:
        time_s: Time of the record [s].
        vehicle: Vehicle id.
        vtype: Vehicle type id (must exist in the replay's additional file).
        x_m: World x of the front bumper's centre [m].
        y_m: World y of the front bumper's centre [m] (+ = left of a road along +x).
        angle_deg: Heading [deg], SUMO's convention (0 = north, 90 = east, clockwise).
        speed_mps: Speed [m/s].
        pos_m: Lane position of the front bumper [m].
        lane: Lane id (``<edge>_<index>``).
    """

    time_s: float
    vehicle: str
    vtype: str
    x_m: float
    y_m: float
    angle_deg: float
    speed_mps: float
    pos_m: float
    lane: str


def snapshot(time_s: float) -> list[FcdPoint]:
    """Every vehicle of the running libsumo simulation now, labelled ``time_s``.

    ``x``/``y`` come from the lane position through the lane's geometry
    (``simulation.convert2D``), not from ``vehicle.getPosition``: right after a
    ``moveTo`` (the env's reset) ``getPosition`` can still report the pre-move position
    (checked on SUMO 1.28). The lateral offset within the lane (0 after the env's reset,
    which puts vehicles on the lane's centre line) is added along the lane's normal for a
    road along +x.
    """
    points = []
    try:
        for vid in libsumo.vehicle.getIDList():
            lane = libsumo.vehicle.getLaneID(vid)
            edge, _, index = lane.rpartition("_")
            pos = libsumo.vehicle.getLanePosition(vid)
            x, y = libsumo.simulation.convert2D(edge, pos, int(index))
            y += libsumo.vehicle.getLateralLanePosition(vid)
            points.append(
                FcdPoint(
                    time_s,
                    vid,
                    libsumo.vehicle.getTypeID(vid),
                    float(x),
                    float(y),
                    float(libsumo.vehicle.getAngle(vid)),
                    float(libsumo.vehicle.getSpeed(vid)),
                    float(pos),
                    lane,
                )
            )
    except SUMO_ERRORS as e:
        raise SimulationError(f"reading the vehicles' state failed: {e}") from e
    return points


def simulation_time_s() -> float:
    """SUMO's current time [s] (the time the next step starts at)."""
    return float(libsumo.simulation.getTime())


def fcd_output_args(path: Path) -> tuple[str, ...]:
    """Extra SUMO options that record every vehicle's state after each step into ``path``.

    SUMO labels the state after the step that starts at time ``T`` with ``T``.
    """
    return ("--fcd-output", str(path), "--precision", str(FCD_PRECISION))


def read_fcd(path: Path) -> list[FcdPoint]:
    """Every vehicle record of an FCD file, in file order."""
    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError) as e:
        raise SimulationError(f"cannot read FCD file {path}: {e}") from e
    points = []
    for step in root.iter("timestep"):
        t = float(step.get("time", "nan"))
        for v in step.iter("vehicle"):
            points.append(
                FcdPoint(
                    t,
                    v.get("id", ""),
                    v.get("type", ""),
                    float(v.get("x", "nan")),
                    float(v.get("y", "nan")),
                    float(v.get("angle", "nan")),
                    float(v.get("speed", "nan")),
                    float(v.get("pos", "nan")),
                    v.get("lane", ""),
                )
            )
    return points


def write_fcd(path: Path, points: Iterable[FcdPoint], comment: str = "") -> Path:
    """Write ``points`` as an FCD file (one ``<timestep>`` per distinct time, in order)."""
    by_time: dict[float, list[FcdPoint]] = {}
    for p in points:
        by_time.setdefault(round(p.time_s, 9), []).append(p)
    d = FCD_PRECISION
    lines = ['<?xml version="1.0" encoding="UTF-8"?>']
    if comment:
        lines.append(f"<!-- {comment.replace('--', '- -')} -->")
    lines.append("<fcd-export>")
    for t in sorted(by_time):
        lines.append(f'    <timestep time="{t:.{d}f}">')
        for p in by_time[t]:
            lines.append(
                f'        <vehicle id={quoteattr(p.vehicle)} x="{p.x_m:.{d}f}" '
                f'y="{p.y_m:.{d}f}" angle="{p.angle_deg:.{d}f}" type={quoteattr(p.vtype)} '
                f'speed="{p.speed_mps:.{d}f}" pos="{p.pos_m:.{d}f}" lane={quoteattr(p.lane)} '
                'slope="0.000000"/>'
            )
        lines.append("    </timestep>")
    lines.append("</fcd-export>")
    atomic_write_text(path, "\n".join(lines) + "\n")
    return path


def insertion_points(initial: Sequence[FcdPoint], time_s: float = 0.0) -> list[FcdPoint]:
    """The insertion record of a replay: each vehicle parked upstream on lane 0, standing.

    Call while the simulation that produced ``initial`` is running (it converts lane
    positions to x/y). The record only has to be insertable at once: the replay moves the
    vehicles to ``initial`` one step later. SUMO inserts the device's vehicles at their
    desired speed with its usual safety checks, and a vehicle it cannot insert waits, which
    would shift its whole trajectory by a step; so the vehicles are parked far apart: the
    VUT at 10 m, the POV at 310 m (:data:`INSERTION_POS_M`), any further vehicle 300 m
    further downstream each, all on lane 0 of the initial lanes' edge.
    """
    out = []
    extra = max(INSERTION_POS_M.values()) + INSERTION_SPACING_M
    try:
        for p in initial:
            pos = INSERTION_POS_M.get(p.vehicle)
            if pos is None:
                pos, extra = extra, extra + INSERTION_SPACING_M
            edge = p.lane.rpartition("_")[0]
            x, y = libsumo.simulation.convert2D(edge, pos, 0)
            out.append(
                replace(
                    p,
                    time_s=time_s,
                    x_m=float(x),
                    y_m=float(y),
                    angle_deg=90.0,
                    speed_mps=0.0,
                    pos_m=pos,
                    lane=f"{edge}_0",
                )
            )
    except SUMO_ERRORS as e:
        raise SimulationError(f"placing the insertion record failed: {e}") from e
    return out


def write_gui_settings(
    path: Path, centre_xy: tuple[float, float], span_m: float, delay_ms: int = 200
) -> Path:
    """sumo-gui view settings: centred on ``centre_xy`` showing about ``span_m`` of road.

    Args:
        path: File to write.
        centre_xy: World ``(x, y)`` [m] the view is centred on.
        span_m: Road length [m] the view should show (on the 1000 m built-in road; sumo-gui's
            zoom is relative to the whole network, 100 = all of it).
        delay_ms: Wall-clock delay per step [ms]; 200 ms = real time at 0.2 s steps.
    """
    zoom = min(max(100.0 * 1000.0 / max(span_m, 1.0), 100.0), 5000.0)
    x, y = centre_xy
    atomic_write_text(
        path,
        "<viewsettings>\n"
        f'    <viewport zoom="{zoom:.1f}" x="{x:.2f}" y="{y:.2f}" angle="0.00"/>\n'
        f'    <delay value="{int(delay_ms)}"/>\n'
        "</viewsettings>\n",
    )
    return path


def write_sumocfg(
    path: Path,
    *,
    net: str,
    additional: str,
    fcd_replay: str,
    sim: SimConfig,
    end_s: float,
    seed: int,
    gui_settings: str | None = None,
) -> Path:
    """A ``.sumocfg`` that replays ``fcd_replay`` on ``net`` with the vehicle types.

    File names are relative to the config's folder. SUMO options match the env's where
    they matter for a replay (step length, collision handling, lane-change duration); the
    emergency-braking warning threshold is raised because the insertion record's vehicles
    jump to the initial state in one step by construction (SUMO still warns once that they
    were "moved by TraCI" at ``t = dt``). ``gui_settings`` (sumo-gui's view and delay) is
    read by sumo-gui and ignored by sumo.
    """
    inputs = {"net-file": net, "additional-files": additional}
    if gui_settings is not None:
        inputs["gui-settings-file"] = gui_settings
    options = {
        "input": inputs,
        "time": {"begin": "0", "end": f"{end_s:.6g}", "step-length": repr(sim.step_length_s)},
        "processing": {
            "collision.action": "warn",
            "collision.mingap-factor": repr(sim.collision_mingap_factor),
            "time-to-teleport": "-1",
            "lanechange.duration": repr(sim.lanechange_duration_s),
            "emergencydecel.warning-threshold": "1000000000",
        },
        "random_number": {"seed": str(int(seed))},
        "report": {"no-step-log": "true", "duration-log.disable": "true"},
        "fcd_replay_device": {"device.fcd-replay.files": fcd_replay},
    }
    lines = ['<?xml version="1.0" encoding="UTF-8"?>', "<configuration>"]
    for section, values in options.items():
        lines.append(f"    <{section}>")
        lines += [f"        <{k} value={quoteattr(v)}/>" for k, v in values.items()]
        lines.append(f"    </{section}>")
    lines.append("</configuration>")
    atomic_write_text(path, "\n".join(lines) + "\n")
    return path


def run_headless(
    sumocfg: Path, fcd_output: Path, timeout_s: float = 300.0
) -> subprocess.CompletedProcess[str]:
    """Run the replay with the ``sumo`` binary, writing the replayed trajectory.

    Raises:
        SimulationError: If SUMO fails (its error output is in the message).
    """
    cmd = [
        str(sumo_binary("sumo")),
        "-c", str(sumocfg),
        *fcd_output_args(fcd_output),
    ]  # fmt: skip
    result = subprocess.run(
        cmd, capture_output=True, text=True, timeout=timeout_s, check=False, env=sumo_env()
    )
    if result.returncode != 0:
        raise SimulationError(
            f"sumo failed on {sumocfg} (exit {result.returncode}): {result.stderr.strip()}"
        )
    return result


def sumo_env() -> dict[str, str]:
    """The environment for SUMO's binaries: ours plus ``SUMO_HOME`` of the pip package.

    Without ``SUMO_HOME`` the binaries warn and skip XML validation of their inputs.
    """
    return {**os.environ, "SUMO_HOME": str(sumo_home())}


def gui_command(sumocfg: Path, delay_ms: int = 200, start: bool = True) -> list[str]:
    """The ``sumo-gui`` command line that replays ``sumocfg``.

    Args:
        sumocfg: The scenario's config.
        delay_ms: Wall-clock delay per step [ms]; 200 ms = real time at 0.2 s steps.
        start: Start playing at once.
    """
    cmd = [str(sumo_binary("sumo-gui")), "-c", str(sumocfg), "--delay", str(int(delay_ms))]
    if start:
        cmd.append("--start")
    return cmd
