"""``python -m sumo_ayss.pipeline`` / ``sumo-ayss pipeline``: the grid, then its report.

The stage is :mod:`sumo_ayss.pipeline` (the grid, cross-play, discriminability, adaptive
seeding, each case analysed once); this command hands it the report writer
(:func:`sumo_ayss.report.document.write_report_for`), prints the leaderboard
(:func:`sumo_ayss.report.leaderboard.leaderboard_text`), the final messages and the input
problems, and sets the exit status.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from sumo_ayss import pipeline as stage
from sumo_ayss.cli import STRICT_HELP, prog
from sumo_ayss.config import PipelineConfig
from sumo_ayss.util.errors import AyssError

__all__ = ["main", "run_pipeline"]


def run_pipeline(cfg: PipelineConfig, **kwargs: Any) -> stage.PipelineResult:
    """:func:`sumo_ayss.pipeline.run_pipeline` with the report written at its end
    (``<out>/report/``, :attr:`~sumo_ayss.pipeline.PipelineResult.report`): config to
    report, what the command runs. ``kwargs``: the stage's (``backend``, ``address``,
    ``live``, ``console``)."""
    from sumo_ayss.report.document import write_report_for

    return stage.run_pipeline(cfg, report=write_report_for, **kwargs)


def main(argv: Sequence[str] | None = None) -> None:
    parser = argparse.ArgumentParser(
        prog=prog("python -m sumo_ayss.pipeline"),
        description=(stage.__doc__ or "").splitlines()[0],
    )
    parser.add_argument(
        "config", type=Path, help="pipeline YAML (configs/paper.yaml runs the paper's grid)"
    )
    stage.add_config_flags(parser)
    parser.add_argument("--backend", choices=["local", "ray"], default="local")
    parser.add_argument("--address", default=None, help="Ray cluster address (ray backend)")
    parser.add_argument(
        "--no-live",
        action="store_true",
        help="no live table: one log line per job event (the default when stdout is not a "
        "terminal)",
    )

    parser.add_argument("--strict", action="store_true", help=STRICT_HELP)
    args = parser.parse_args(argv)
    console = stage.configure_logging(not args.no_live)
    try:
        cfg = stage.config_from_args(args)
        result = run_pipeline(
            cfg,
            backend=args.backend,
            address=args.address,
            live=console is not None,
            console=console,
        )
    except AyssError as e:
        sys.exit(f"error: {e}")
    except KeyboardInterrupt:
        print("interrupted: no job runs any more; rerun the same command to resume", flush=True)
        sys.exit(130)
    if result.analyses:
        from sumo_ayss.report.leaderboard import leaderboard_text

        print(leaderboard_text(result.analyses))
    for line in stage.final_messages(result):
        print(line)
    from sumo_ayss.modes import input_problems

    problems = input_problems(result.analyses)
    for line in problems:
        print(f"WARNING: {line}", file=sys.stderr)
    if any(s.state == "failed" for s in result.statuses):
        sys.exit(1)
    if args.strict and problems:
        sys.exit(
            f"error: --strict: {len(problems)} problem(s) in the input files (the WARNING "
            "lines above); the report was written"
        )
    sys.exit(0)


if __name__ == "__main__":
    main()
