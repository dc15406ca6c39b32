"""``python -m sumo_ayss.replay``: ``export RUN_DIR ...`` or ``SCENARIO_DIR [--headless]``."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

from sumo_ayss.cli import prog
from sumo_ayss.replay.playback import (
    POSITION_TOL_M,
    REPLAYED_FILE,
    SPEED_TOL_MPS,
    replay_headless,
    replay_in_gui,
)
from sumo_ayss.replay.record import export_scenario
from sumo_ayss.util.errors import AyssError

__all__ = ["main"]

# --------------------------------------------------------------------------- CLI


def _export_main(argv: Sequence[str]) -> int:
    parser = argparse.ArgumentParser(
        prog=prog("python -m sumo_ayss.replay") + " export",
        description="Write an AYSS sample or an outcome episode of a run as SUMO files "
        "(or, with --format xosc, as OpenSCENARIO + OpenDRIVE).",
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
    parser.add_argument(
        "--format",
        choices=("sumo", "xosc"),
        default="sumo",
        help="sumo: SUMO files that replay in sumo-gui (default); xosc: ASAM OpenSCENARIO 1.2 "
        "with its OpenDRIVE road",
    )
    args = parser.parse_args(argv)
    row = {
        "ayss_row": args.ayss_row,
        "outcome_row": args.outcome_row,
        "decisions": args.decisions,
        "trust_controller": args.trust_controller,
    }
    if args.format == "xosc":
        from sumo_ayss.replay.xosc import export_xosc

        x = export_xosc(args.run_dir, args.out, **row)
        print(
            f"wrote {x.xosc} and {x.xodr}: {x.info['decisions']} decision(s), collision "
            f"{x.info['collided']}, reproduces the row: {x.info['reproduces_row']}"
        )
        return 0
    result = export_scenario(args.run_dir, args.out, **row)
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
