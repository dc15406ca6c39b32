"""Export one scenario of a run (an AYSS sample or an outcome episode) as SUMO files (see
:mod:`sumo_ayss.replay`)."""

from __future__ import annotations

import dataclasses
import json
import math
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sumo_ayss.config import EnvConfig, to_dict
from sumo_ayss.envs import make_env
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.envs.pair_env import PairEnv
from sumo_ayss.replay.playback import (
    GUI_FILE,
    NET_FILE,
    POSITION_TOL_M,
    SCENARIO_FILE,
    SPEED_TOL_MPS,
    SUMOCFG_FILE,
    TRAJECTORY_FILE,
    VTYPES_FILE,
)
from sumo_ayss.replay.source import Kind, initial_condition, load_policy, read_row, select_row
from sumo_ayss.run_folder import (
    RunRecord,
    read_run,
)
from sumo_ayss.scenarios.rollout import Policy
from sumo_ayss.sim import export
from sumo_ayss.sim.network import network_path
from sumo_ayss.util.atomic import atomic_copy, atomic_write_text
from sumo_ayss.util.errors import SimulationError
from sumo_ayss.util.paths import portable_path
from sumo_ayss.vuts.catalog import controller_imports, vtypes_xml

__all__ = ["ExportResult", "export_scenario"]

#: The reset must reproduce a row's state to this tolerance [m/s, m] (float32 rows).
_RESET_TOL = 1e-3


@dataclass(frozen=True)
class ExportResult:
    """What :func:`export_scenario` wrote.

    Attributes:
        out: The scenario folder.
        sumocfg: Its ``scenario.sumocfg``.
        trajectory: Its ``trajectory.fcd.xml``.
        info: The contents of ``scenario.json``.
    """

    out: Path
    sumocfg: Path
    trajectory: Path
    info: dict[str, Any]


# --------------------------------------------------------------------------- export


def _vehicle_name(vtype: str, vehicle: str = "") -> str:
    """The replay's name of a vehicle: ``vut``, ``pov``, ``follower``; a further POV by its
    id's tag (``<prefix>.<tag>.<episode>``, e.g. ``pov2``)."""
    if vtype == "pov":
        parts = vehicle.split(".")
        return parts[1] if len(parts) == 3 and parts[1].startswith("pov") else "pov"
    return vtype if vtype == "follower" else "vut"


def _rename(points: Sequence[export.FcdPoint], time_of: dict[float, float]) -> list[Any]:
    out = []
    for p in points:
        t = time_of.get(round(p.time_s, 9))
        if t is not None:
            name = _vehicle_name(p.vtype, p.vehicle)
            out.append(dataclasses.replace(p, time_s=t, vehicle=name))
    return out


def export_scenario(
    run_dir: str | Path,
    out: str | Path,
    *,
    ayss_row: int | None = None,
    outcome_row: int | None = None,
    decisions: int | None = None,
    policy: Policy | None = None,
    trust_controller: bool = False,
) -> ExportResult:
    """Write one scenario of a run as replayable SUMO files (see the module docstring).

    Args:
        run_dir: A run folder (``config.yaml``, ``spcp.zip``, and the evaluated tables).
        out: The scenario folder to write (created; existing files are replaced).
        ayss_row: Data row (0-based) of ``ayss.csv``; exactly one of the two rows.
        outcome_row: Data row (0-based) of ``outcome.csv``.
        decisions: Policy decisions to record, >= 1; default 1 for an AYSS sample (its
            ``d = 1`` scenario) and the whole episode for an outcome row. The recording
            always stops when the episode ends (collision or its last decision).
        policy: Use this policy instead of ``<run>/spcp.zip`` (e.g. a scripted one).
        trust_controller: Allow importing the run's user-controller VUT (runs its code).

    Returns:
        The written files and the scenario's information.

    Raises:
        ConfigError: If the row selection or ``decisions`` is invalid.
        CheckpointError: If the run folder, a table or the SPCP cannot be read.
        SimulationError: If SUMO fails or does not reproduce the row's initial state.
    """
    kind, index = select_row(ayss_row, outcome_row, decisions)
    out = Path(out)
    with controller_imports(trust_controller):
        return _export(read_run(run_dir), kind, index, out, policy, decisions)


def _export(
    run: RunRecord, kind: Kind, index: int, out: Path, policy: Policy | None, decisions: int | None
) -> ExportResult:
    env_cfg = run.experiment.env  # raises first if the folder is not a run folder
    row = read_row(run.folder, kind, index)
    ic = initial_condition(kind, row, run)
    pol = policy if policy is not None else load_policy(run)
    limit = decisions if decisions is not None else (1 if kind == "ayss" else None)
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="sumo_ayss_rec_") as tmp:
        recorded = Path(tmp) / "recorded.fcd.xml"
        rec = _record(env_cfg, run.config_seed, ic, pol, limit, recorded)
        # The episode's vehicles only: an env may simulate others after its last step (the
        # online preventability replay of lead_and_cut_in after a crash).
        ids = rec["vehicles"]
        sumo_points = [p for p in export.read_fcd(recorded) if p.vehicle in ids]
    dt = env_cfg.sim.step_length_s
    # SUMO labels the state after the step starting at T with T; the initial state was
    # read at reset_time (the start of the first step): tau = T + dt - reset_time.
    times = sorted({round(p.time_s, 9) for p in sumo_points})
    later = [t for t in times if t >= rec["reset_time_s"] - 1e-9]
    time_of = {t: round(t + dt - rec["reset_time_s"] + dt, 9) for t in later}
    initial = [dataclasses.replace(p, time_s=dt) for p in rec["initial"]]
    trajectory = [*rec["insertion"], *initial, *_rename(sumo_points, time_of)]
    end_s = round(max(p.time_s for p in trajectory) + dt, 9)
    net_src = env_cfg.network if env_cfg.network is not None else network_path(env_cfg.case)
    atomic_copy(net_src, out / NET_FILE)
    vt = env_cfg.vut_type
    types = {f"vut_{env_cfg.vut}": vt, "pov": env_cfg.pov}
    if env_cfg.follower.enabled:  # issue 33: the follower behind the VUT
        types["follower"] = env_cfg.follower.sumo_type
    atomic_write_text(out / VTYPES_FILE, vtypes_xml(types))
    comment = (
        f"{kind} row {index} of {run.path}; t = 0 inserts the vehicles, the scenario "
        f"(tau = 0) starts at t = {dt:g} s"
    )
    export.write_fcd(out / TRAJECTORY_FILE, trajectory, comment)
    shown = [p for p in trajectory if p.time_s >= dt - 1e-9]
    xs, ys = [p.x_m for p in shown], [p.y_m for p in shown]
    export.write_gui_settings(
        out / GUI_FILE,
        (0.5 * (min(xs) + max(xs)), 0.5 * (min(ys) + max(ys))),
        max(xs) - min(xs) + 60.0,
        delay_ms=round(1000 * dt),
    )
    export.write_sumocfg(
        out / SUMOCFG_FILE,
        net=NET_FILE,
        additional=VTYPES_FILE,
        fcd_replay=TRAJECTORY_FILE,
        sim=env_cfg.sim,
        end_s=end_s,
        seed=run.config_seed,
        gui_settings=GUI_FILE,
    )
    info = _info(run, kind, index, row, ic, rec, dt, end_s)
    atomic_write_text(out / SCENARIO_FILE, json.dumps(info, indent=2, allow_nan=False) + "\n")
    atomic_write_text(out / "README.md", _readme(info))
    return ExportResult(out, out / SUMOCFG_FILE, out / TRAJECTORY_FILE, info)


def _record(
    env_cfg: EnvConfig,
    sumo_seed: int,
    ic: InitialCondition,
    policy: Policy,
    limit: int | None,
    fcd_path: Path,
) -> dict[str, Any]:
    """Run the scenario in a fresh env whose SUMO writes every step to ``fcd_path``."""
    sim = dataclasses.replace(
        env_cfg.sim, extra_args=(*env_cfg.sim.extra_args, *export.fcd_output_args(fcd_path))
    )
    env = make_env(dataclasses.replace(env_cfg, sim=sim), sumo_seed=sumo_seed)
    base = env.unwrapped
    assert isinstance(base, PairEnv)
    try:
        obs, info0 = base.reset(options={"initial_condition": ic})
        reset_time = export.simulation_time_s()
        snapshot = export.snapshot(reset_time)
        vehicles = {p.vehicle for p in snapshot}
        initial = [
            dataclasses.replace(p, vehicle=_vehicle_name(p.vtype, p.vehicle)) for p in snapshot
        ]
        insertion = export.insertion_points(initial, 0.0)
        if np.max(np.abs(obs[:3] - np.array(ic.as_tuple()))) > _RESET_TOL:
            raise SimulationError(f"reset to {ic} gave observation {obs.tolist()}")
        steps: list[dict[str, Any]] = []
        done = False
        while not done and (limit is None or len(steps) < limit):
            action = int(np.asarray(policy(obs[None, :])).reshape(-1)[0])
            obs, reward, terminated, truncated, info = base.step(action)
            done = bool(terminated or truncated)
            steps.append(
                {
                    "decision": len(steps),
                    "action": action,
                    "reward": float(reward),
                    "headway_m": float(info["headway_m"]),
                    "pov_speed_mps": float(obs[0]),
                    "vut_speed_mps": float(obs[1]),
                    "collision": bool(info["collision"]),
                    "lane_change_started": bool(info.get("lane_change_started", False)),
                    "terminated": bool(terminated),
                    "truncated": bool(truncated),
                }
            )
    finally:
        env.close()
    return {
        "reset_time_s": reset_time,
        "initial": initial,
        "insertion": insertion,
        "vehicles": vehicles,
        "steps": steps,
        "ttc0": info0["ttc_s"],
    }


def _json_value(v: Any) -> Any:
    if isinstance(v, float) and not math.isfinite(v):
        return str(v)
    if isinstance(v, np.generic):
        return _json_value(v.item())
    return v


def _info(
    run: RunRecord,
    kind: Kind,
    index: int,
    row: dict[str, Any],
    ic: InitialCondition,
    rec: dict[str, Any],
    dt: float,
    end_s: float,
) -> dict[str, Any]:
    from sumo_ayss.sim.session import sumo_version

    env_cfg: EnvConfig = run.experiment.env
    steps = rec["steps"]
    ep_return = sum(s["reward"] for s in steps)
    collided = any(s["collision"] for s in steps)
    ended = bool(steps) and (steps[-1]["terminated"] or steps[-1]["truncated"])
    reproduced: dict[str, Any]
    if kind == "ayss":
        reproduced = {"action": bool(steps) and steps[0]["action"] == row["action"]}
    else:
        reproduced = {
            "episode_return": math.isclose(ep_return, row["episode_return"], abs_tol=1e-6),
            "collided": collided == row["collided"],
            "n_steps": len(steps) == row["n_steps"],
        }
    return {
        "source": {
            "run_dir": portable_path(run.path),
            "table": (run.folder.ayss_csv if kind == "ayss" else run.folder.outcome_csv).name,
            "row": index,
            "values": {k: _json_value(v) for k, v in row.items()},
            "spcp_step": run.spcp.step if run.spcp is not None else None,
        },
        "case": env_cfg.case,
        "vut": env_cfg.vut,
        "vut_type": to_dict(env_cfg.vut_type),
        "train_seed": run.config_seed,
        "sumo_seed": run.config_seed,
        "sumo_version": sumo_version(),
        "step_length_s": dt,
        "decision_period_s": env_cfg.decision_period_s,
        "time_offset_s": dt,
        "end_s": end_s,
        "initial_condition": dataclasses.asdict(ic),
        "initial_ttc_s": _json_value(rec["ttc0"]),
        "decisions": steps,
        "episode_return": ep_return,
        "collided": collided,
        "episode_ended": ended,
        "reproduces_row": reproduced,
        "files": {
            "network": NET_FILE,
            "vehicle_types": VTYPES_FILE,
            "trajectory": TRAJECTORY_FILE,
            "sumocfg": SUMOCFG_FILE,
            "gui_settings": GUI_FILE,
        },
        "tolerance": {"position_m": POSITION_TOL_M, "speed_mps": SPEED_TOL_MPS},
    }


def _readme(info: dict[str, Any]) -> str:
    src = info["source"]
    ic = info["initial_condition"]
    return (
        f"# Scenario: {src['table']} row {src['row']} of `{src['run_dir']}`\n\n"
        f"Case `{info['case']}`, VUT `{info['vut']}`; initial condition: POV "
        f"{ic['pov_speed_mps']:.3f} m/s, VUT {ic['vut_speed_mps']:.3f} m/s, gap "
        f"{ic['gap_m']:.3f} m; {len(info['decisions'])} decision(s) of the SPCP, "
        f"collision: {info['collided']}.\n\n"
        "Watch it (a display is needed):\n\n"
        "    python -m sumo_ayss.replay .        # or: sumo-gui -c scenario.sumocfg\n\n"
        "Replay it without a window and check it against the recording:\n\n"
        "    python -m sumo_ayss.replay . --headless\n\n"
        f"SUMO's fcd-replay device moves both vehicles along `{TRAJECTORY_FILE}`. t = 0 only "
        f"inserts them upstream; the scenario starts at t = {info['time_offset_s']:g} s "
        "(scenario time tau = t - that offset). Details: `scenario.json`.\n"
    )
