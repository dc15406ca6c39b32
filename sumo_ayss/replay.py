"""Replayable scenarios: an AYSS sample or an outcome episode of a run, as SUMO files.

    python -m sumo_ayss.replay export runs/cut_in/pi1/seed_0 --ayss-row 12 --out scen/ayss12
    python -m sumo_ayss.replay export runs/cut_in/pi1/seed_0 --outcome-row 3 --out scen/ep3
    python -m sumo_ayss.replay scen/ayss12              # sumo-gui (needs a display)
    python -m sumo_ayss.replay scen/ayss12 --headless   # sumo; writes and checks replayed.fcd.xml

**Export** re-runs the scenario in the run's own env (its ``config.yaml``: case, VUT, ODD,
actuator, SUMO options; SUMO seed = the run's seed, as in evaluation) with the run's SPCP
(``spcp.zip``, greedy), records both vehicles at every SUMO step, and writes into ``--out``:

======================  ====================================================================
``network.net.xml``     copy of the run's road network
``vtypes.add.xml``      vehicle types: the run's VUT (``vut_<name>``) and the POV (``pov``)
``trajectory.fcd.xml``  the recorded trajectory in SUMO's FCD format (vehicles ``vut``,
                        ``pov``); file time ``t = τ + dt`` (see below)
``scenario.sumocfg``    replays the trajectory with SUMO's fcd-replay device
``gui.settings.xml``    sumo-gui's view (centred on the scenario) and real-time delay
``scenario.json``       where it came from (run, table row), the initial condition, the
                        SPCP's actions, rewards and headways per decision, and whether the
                        re-run reproduced the row (action, return, collision)
``README.md``           how to replay
======================  ====================================================================

Which scenario: ``--ayss-row K`` is data row ``K`` (0-based) of the run's ``ayss.csv``: the
sampled observation ``(v_pov_mps, v_vut_mps, h_m)`` is the initial condition and the
scenario is the AYSS's ``d = 1`` decision (``--decisions N`` continues with the SPCP for up
to ``N`` decisions). ``--outcome-row K`` is data row ``K`` of ``outcome.csv``: the initial
condition ``(v_pov0_mps, v_vut0_mps, gap0_m)`` and the whole episode.

**Replay mechanism**: SUMO's native fcd-replay device (:mod:`sumo_ayss.sim.export`), so
the scenario plays in an unmodified ``sumo-gui -c scenario.sumocfg``, with no Python. Its
first record only inserts the vehicles (upstream, standing, as the env does); the
scenario's initial state is at ``t = dt`` and scenario time ``τ`` is file time ``τ + dt``.
In the replay both vehicles follow the recording exactly: positions and speeds match it
within :data:`POSITION_TOL_M` and :data:`SPEED_TOL_MPS` (what ``--headless`` checks).
Neither vehicle's model acts in a replay: it shows what happened, it does not re-simulate.
No routes file is written: the device builds each vehicle's route from the trajectory, and
a routes file defining the same vehicle ids is refused by SUMO ("Another vehicle with the
id 'pov' exists").
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import os
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np

from sumo_ayss.atomic import atomic_copy, atomic_write_text
from sumo_ayss.catalog import controller_imports, vtypes_xml
from sumo_ayss.cli import prog
from sumo_ayss.config import EnvConfig, to_dict
from sumo_ayss.envs import make_env
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.envs.pair_env import PairEnv
from sumo_ayss.errors import AyssError, CheckpointError, ConfigError, SimulationError
from sumo_ayss.paths import portable_path
from sumo_ayss.scenarios.rollout import Policy
from sumo_ayss.scenarios.tables import AYSS_SCHEMA, OUTCOME_SCHEMA, read_table
from sumo_ayss.sim import export
from sumo_ayss.sim.network import network_path

__all__ = [
    "POSITION_TOL_M",
    "SPEED_TOL_MPS",
    "ExportResult",
    "ReplayCheck",
    "compare_trajectories",
    "export_scenario",
    "main",
    "replay_headless",
    "replay_in_gui",
]

#: A replayed position may differ from the recorded one by this much [m] (Euclidean).
POSITION_TOL_M = 1e-3
#: A replayed speed may differ from the recorded one by this much [m/s].
SPEED_TOL_MPS = 1e-3
#: The reset must reproduce a row's state to this tolerance [m/s, m] (float32 rows).
_RESET_TOL = 1e-3

NET_FILE, VTYPES_FILE, TRAJECTORY_FILE = "network.net.xml", "vtypes.add.xml", "trajectory.fcd.xml"
SUMOCFG_FILE, SCENARIO_FILE, REPLAYED_FILE = "scenario.sumocfg", "scenario.json", "replayed.fcd.xml"
GUI_FILE = "gui.settings.xml"

Kind = Literal["ayss", "outcome"]


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


# --------------------------------------------------------------------------- export


def _row(run_dir: Path, kind: Kind, index: int) -> dict[str, Any]:
    name, schema = ("ayss.csv", AYSS_SCHEMA) if kind == "ayss" else ("outcome.csv", OUTCOME_SCHEMA)
    path = run_dir / name
    if not path.is_file():
        raise CheckpointError(f"{run_dir}: no {name} (run `python -m sumo_ayss.evaluate` first)")
    table = read_table(path, schema)
    if isinstance(index, bool) or not isinstance(index, int) or not 0 <= index < len(table):
        raise ConfigError(
            f"--{kind}-row must be an integer in [0, {len(table) - 1}] (data rows of {path}), "
            f"got {index!r}"
        )
    return dict(list(table.rows())[index])


def _initial_condition(kind: Kind, row: dict[str, Any]) -> InitialCondition:
    if kind == "ayss":
        return InitialCondition(row["v_pov_mps"], row["v_vut_mps"], row["h_m"])
    return InitialCondition(row["v_pov0_mps"], row["v_vut0_mps"], row["gap0_m"])


def _load_policy(run: Any) -> Policy:
    """The run's SPCP, weights only (never unpickled: see "Trust model" in the README)."""
    from sumo_ayss.evaluate import load_spcp  # torch: only when a policy is needed

    return load_spcp(run, make_env(run.config.env))


def _vehicle_name(vtype: str) -> str:
    return "pov" if vtype == "pov" else "vut"


def _rename(points: Sequence[export.FcdPoint], time_of: dict[float, float]) -> list[Any]:
    out = []
    for p in points:
        t = time_of.get(round(p.time_s, 9))
        if t is not None:
            out.append(dataclasses.replace(p, time_s=t, vehicle=_vehicle_name(p.vtype)))
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
    from sumo_ayss.evaluate import load_run  # the entry-point layer; imported lazily

    if (ayss_row is None) == (outcome_row is None):
        raise ConfigError(
            "give exactly one of ayss_row (--ayss-row) or outcome_row (--outcome-row)"
        )
    kind: Kind = "ayss" if ayss_row is not None else "outcome"
    index = ayss_row if ayss_row is not None else outcome_row
    assert index is not None
    if decisions is not None and (
        isinstance(decisions, bool) or not isinstance(decisions, int) or decisions < 1
    ):
        raise ConfigError(f"decisions must be an integer >= 1, got {decisions!r}")
    run_dir, out = Path(run_dir), Path(out)
    with controller_imports(trust_controller):
        run = load_run(run_dir)
        return _export(run, kind, index, out, policy, decisions)


def _export(
    run: Any, kind: Kind, index: int, out: Path, policy: Policy | None, decisions: int | None
) -> Any:
    run_dir = run.run_dir
    row = _row(run_dir, kind, index)
    ic = _initial_condition(kind, row)
    pol = policy if policy is not None else _load_policy(run)
    env_cfg = run.config.env
    limit = decisions if decisions is not None else (1 if kind == "ayss" else None)
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="sumo_ayss_rec_") as tmp:
        recorded = Path(tmp) / "recorded.fcd.xml"
        rec = _record(env_cfg, run.seed, ic, pol, limit, recorded)
        sumo_points = export.read_fcd(recorded)
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
    atomic_write_text(out / VTYPES_FILE, vtypes_xml({f"vut_{env_cfg.vut}": vt, "pov": env_cfg.pov}))
    comment = (
        f"{kind} row {index} of {run_dir.resolve()}; t = 0 inserts the vehicles, the scenario "
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
        seed=run.seed,
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
        initial = [
            dataclasses.replace(p, vehicle=_vehicle_name(p.vtype))
            for p in export.snapshot(reset_time)
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
    run: Any,
    kind: Kind,
    index: int,
    row: dict[str, Any],
    ic: InitialCondition,
    rec: dict[str, Any],
    dt: float,
    end_s: float,
) -> dict[str, Any]:
    from sumo_ayss.sim.session import sumo_version

    env_cfg: EnvConfig = run.config.env
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
            "run_dir": portable_path(run.run_dir),
            "table": "ayss.csv" if kind == "ayss" else "outcome.csv",
            "row": index,
            "values": {k: _json_value(v) for k, v in row.items()},
            "spcp_step": run.spcp_step,
        },
        "case": env_cfg.case,
        "vut": env_cfg.vut,
        "vut_type": to_dict(env_cfg.vut_type),
        "train_seed": run.seed,
        "sumo_seed": run.seed,
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


# --------------------------------------------------------------------------- replay


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
    return cfg, json.loads(info_path.read_text())


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


# --------------------------------------------------------------------------- CLI


def _export_main(argv: Sequence[str]) -> int:
    parser = argparse.ArgumentParser(
        prog=prog("python -m sumo_ayss.replay") + " export",
        description="Write an AYSS sample or an outcome episode of a run as SUMO files.",
    )
    parser.add_argument("run_dir", type=Path, help="run folder (config.yaml, spcp.zip, tables)")
    which = parser.add_mutually_exclusive_group(required=True)
    which.add_argument("--ayss-row", type=int, help="data row of ayss.csv (0-based)")
    which.add_argument("--outcome-row", type=int, help="data row of outcome.csv (0-based)")
    parser.add_argument("--out", type=Path, required=True, help="scenario folder to write")
    parser.add_argument(
        "--trust-controller",
        action="store_true",
        help="import the run's user-controller VUT (runs code the run folder names)",
    )
    parser.add_argument(
        "--decisions",
        type=int,
        default=None,
        help="SPCP decisions to record (default: 1 for AYSS, the whole episode for outcome)",
    )
    args = parser.parse_args(argv)
    result = export_scenario(
        args.run_dir,
        args.out,
        ayss_row=args.ayss_row,
        outcome_row=args.outcome_row,
        decisions=args.decisions,
        trust_controller=args.trust_controller,
    )
    info = result.info
    print(
        f"wrote {result.out}: {len(info['decisions'])} decision(s), collision "
        f"{info['collided']}, reproduces the row: {info['reproduces_row']}"
    )
    print(f"replay: python -m sumo_ayss.replay {result.out} [--headless]")
    return 0


def _replay_main(argv: Sequence[str]) -> int:
    parser = argparse.ArgumentParser(
        prog=prog("python -m sumo_ayss.replay"),
        description="Replay a scenario folder in sumo-gui, or headless with sumo. "
        "`python -m sumo_ayss.replay export ...` writes one.",
    )
    parser.add_argument("scenario_dir", type=Path, help="folder written by `... replay export`")
    parser.add_argument(
        "--headless",
        action="store_true",
        help="replay with sumo (no window), write the replayed FCD and check it",
    )
    parser.add_argument(
        "--output", type=Path, default=None, help="replayed FCD file (default: replayed.fcd.xml)"
    )
    parser.add_argument(
        "--delay-ms",
        type=int,
        default=200,
        help="sumo-gui delay per step [ms] (200 = real time at 0.2 s steps)",
    )
    args = parser.parse_args(argv)
    if not args.headless:
        return replay_in_gui(args.scenario_dir, args.delay_ms)
    check = replay_headless(args.scenario_dir, args.output)
    out = args.output or args.scenario_dir / REPLAYED_FILE
    print(
        f"replayed {check.n_points} vehicle records into {out}: max position error "
        f"{check.max_position_error_m:.2e} m (tolerance {POSITION_TOL_M:g}), max speed error "
        f"{check.max_speed_error_mps:.2e} m/s (tolerance {SPEED_TOL_MPS:g}), missing "
        f"{len(check.missing)}: {'OK' if check.ok else 'MISMATCH'}"
    )
    return 0 if check.ok else 1


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point: ``export RUN_DIR ...`` or ``SCENARIO_DIR [--headless]``."""
    args = list(sys.argv[1:] if argv is None else argv)
    try:
        if args and args[0] == "export":
            return _export_main(args[1:])
        return _replay_main(args)
    except AyssError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
