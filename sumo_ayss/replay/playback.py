"""Replay a scenario folder: in ``sumo-gui``, or headless with ``sumo`` and checked against
the recording (see :mod:`sumo_ayss.replay`)."""

from __future__ import annotations

import json
import math
import os
import subprocess
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sumo_ayss.sim import export
from sumo_ayss.util.errors import ConfigError, SimulationError

__all__ = [
    "GUI_FILE",
    "NET_FILE",
    "POSITION_TOL_M",
    "REPLAYED_FILE",
    "SCENARIO_FILE",
    "SPEED_TOL_MPS",
    "SUMOCFG_FILE",
    "TRAJECTORY_FILE",
    "VTYPES_FILE",
    "ReplayCheck",
    "compare_trajectories",
    "has_display",
    "replay_headless",
    "replay_in_gui",
]

#: A replayed position may differ from the recorded one by this much [m] (Euclidean).
POSITION_TOL_M = 1e-3
#: A replayed speed may differ from the recorded one by this much [m/s].
SPEED_TOL_MPS = 1e-3
#: The reset must reproduce a row's state to this tolerance [m/s, m] (float32 rows).

# The files of a scenario folder.
NET_FILE, VTYPES_FILE, TRAJECTORY_FILE = "network.net.xml", "vtypes.add.xml", "trajectory.fcd.xml"
SUMOCFG_FILE, SCENARIO_FILE, REPLAYED_FILE = "scenario.sumocfg", "scenario.json", "replayed.fcd.xml"
GUI_FILE = "gui.settings.xml"


@dataclass(frozen=True)
class ReplayCheck:
    """Replayed vs. recorded trajectory.

    Attributes:
        n_points: Vehicle records compared (every vehicle at every ``τ >= 0``).
        max_position_error_m: Largest Euclidean distance between replayed and recorded
            front-bumper positions [m].
        max_speed_error_mps: Largest absolute speed difference [m/s].
        missing: Recorded (time, vehicle) pairs absent from the replay.
    """

    n_points: int
    max_position_error_m: float
    max_speed_error_mps: float
    missing: tuple[tuple[float, str], ...]

    @property
    def ok(self) -> bool:
        """Within :data:`POSITION_TOL_M` and :data:`SPEED_TOL_MPS`, nothing missing."""
        return (
            not self.missing
            and self.n_points > 0
            and self.max_position_error_m <= POSITION_TOL_M
            and self.max_speed_error_mps <= SPEED_TOL_MPS
        )


def compare_trajectories(
    recorded: Sequence[export.FcdPoint], replayed: Sequence[export.FcdPoint], start_s: float
) -> ReplayCheck:
    """Replayed vs. recorded records at every time ``>= start_s`` (the scenario's τ = 0)."""
    got = {(round(p.time_s, 6), p.vehicle): p for p in replayed}
    n, pos_err, speed_err, missing = 0, 0.0, 0.0, []
    for p in recorded:
        if p.time_s < start_s - 1e-9:
            continue
        q = got.get((round(p.time_s, 6), p.vehicle))
        if q is None:
            missing.append((p.time_s, p.vehicle))
            continue
        n += 1
        pos_err = max(pos_err, math.hypot(q.x_m - p.x_m, q.y_m - p.y_m))
        speed_err = max(speed_err, abs(q.speed_mps - p.speed_mps))
    return ReplayCheck(n, pos_err, speed_err, tuple(missing))


def _scenario(scenario_dir: Path) -> tuple[Path, dict[str, Any]]:
    cfg = scenario_dir / SUMOCFG_FILE
    info_path = scenario_dir / SCENARIO_FILE
    if not cfg.is_file() or not info_path.is_file():
        raise ConfigError(
            f"{scenario_dir}: not a scenario folder (no {SUMOCFG_FILE} / {SCENARIO_FILE}); "
            "write one with `python -m sumo_ayss.replay export RUN_DIR --ayss-row K --out DIR`"
        )
    try:
        info = json.loads(info_path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as e:  # ValueError: not JSON or not UTF-8
        raise ConfigError(f"{info_path}: unreadable scenario record ({e})") from None
    if not isinstance(info, dict):
        raise ConfigError(f"{info_path}: expected a JSON object, got {type(info).__name__}")
    return cfg, info


def replay_headless(scenario_dir: str | Path, output: str | Path | None = None) -> ReplayCheck:
    """Replay with the ``sumo`` binary, write the replayed FCD, compare with the recording.

    Args:
        scenario_dir: A folder written by :func:`export_scenario`.
        output: Replayed FCD file; default ``<scenario_dir>/replayed.fcd.xml``.
    """
    scenario_dir = Path(scenario_dir)
    cfg, info = _scenario(scenario_dir)
    out = Path(output) if output is not None else scenario_dir / REPLAYED_FILE
    export.run_headless(cfg.resolve(), out.resolve())
    recorded = export.read_fcd(scenario_dir / TRAJECTORY_FILE)
    return compare_trajectories(recorded, export.read_fcd(out), float(info["time_offset_s"]))


def has_display() -> bool:
    """Whether a GUI window can open here (X11 ``$DISPLAY`` or Wayland)."""
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def replay_in_gui(scenario_dir: str | Path, delay_ms: int = 200) -> int:
    """Open the scenario in ``sumo-gui`` (blocks until the window is closed).

    Returns:
        sumo-gui's exit status.

    Raises:
        SimulationError: If there is no display.
    """
    scenario_dir = Path(scenario_dir)
    cfg, _ = _scenario(scenario_dir)
    if not has_display():
        raise SimulationError(
            "no display: $DISPLAY (and $WAYLAND_DISPLAY) is not set, so sumo-gui cannot open a "
            f"window here. Replay without a window: python -m sumo_ayss.replay {scenario_dir} "
            "--headless (runs sumo, writes replayed.fcd.xml, checks it against the recording); "
            f"or copy {scenario_dir} to a machine with a display and run "
            f"`sumo-gui -c {SUMOCFG_FILE}` in it."
        )
    cmd = export.gui_command(cfg.resolve(), delay_ms)
    return subprocess.run(cmd, check=False, env=export.sumo_env()).returncode
