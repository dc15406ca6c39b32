"""Command line of the report stage.

    python -m sumo_ayss.report RUNS_ROOT_OR_RUN_FOLDER... [--out DIR] [--title TEXT] [--strict]

Writes ``report.html`` (self-contained), ``summary.md`` and the PNG figures into ``--out``
(default ``<first path>/report``) and prints the path of ``report.html``. Each missing,
unreadable or empty input file the report lists under "Missing or incomplete data" is also
printed to stderr as a ``WARNING:`` line naming the file; with ``--strict`` (for CI) any such
problem makes the exit status non-zero (the report is still written).
"""

from __future__ import annotations

import argparse
import logging
import sys
from collections.abc import Sequence
from pathlib import Path

from sumo_ayss.cli import STRICT_HELP, prog
from sumo_ayss.config import check_out_dir
from sumo_ayss.modes import analyse_cases, input_problems
from sumo_ayss.report.document import DEFAULT_TITLE, ReportOptions, write_report_for
from sumo_ayss.run_folder import case_runs, load_runs
from sumo_ayss.util.errors import AyssError

#: ``--strict``'s help, also quoted by ``rank --strict``.


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    """Parses the command line."""
    defaults = ReportOptions()
    parser = argparse.ArgumentParser(
        prog=prog("python -m sumo_ayss.report"),
        description="Write the AYSS safety report (HTML + Markdown + PNGs) from run folders.",
    )
    parser.add_argument(
        "paths", nargs="+", type=Path, help="run folders <out>/<case>/<vut>/seed_<k> or roots"
    )
    parser.add_argument(
        "--out", type=Path, default=None, help="output folder (default: <first path>/report)"
    )
    parser.add_argument("--title", default=DEFAULT_TITLE, help="report title")
    parser.add_argument(
        "--h-max", type=float, default=defaults.h_max_m, help="AYSS headway limit [m]"
    )
    parser.add_argument(
        "--bin-width", type=float, default=defaults.bin_width_m, help="figure bin width [m]"
    )
    parser.add_argument(
        "--index-bins", type=int, default=defaults.index_bins, help="safety-index headway bins"
    )
    parser.add_argument(
        "--n-boot", type=int, default=defaults.n_boot, help="bootstrap replicates per VUT"
    )
    parser.add_argument("--seed", type=int, default=defaults.rng_seed, help="bootstrap seed")
    parser.add_argument("--strict", action="store_true", help=STRICT_HELP)
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress")
    return parser.parse_args(argv)


def main(argv: Sequence[str] | None = None) -> None:
    """Entry point: writes the report and prints the path of ``report.html``."""
    args = parse_args(argv)
    logging.basicConfig(
        level=logging.INFO if args.verbose else logging.WARNING,
        format="%(levelname)s %(name)s: %(message)s",
    )
    try:
        options = ReportOptions(
            h_max_m=args.h_max,
            bin_width_m=args.bin_width,
            index_bins=args.index_bins,
            n_boot=args.n_boot,
            rng_seed=args.seed,
        )
        if args.out is not None:
            check_out_dir(args.out, "--out")
        runs = load_runs(args.paths)
        analyses = analyse_cases(case_runs(runs), options)
        out = args.out if args.out is not None else args.paths[0] / "report"
        path = write_report_for(runs, out, analyses=analyses, title=args.title, options=options)
    except AyssError as exc:
        sys.exit(f"error: {exc}")
    except OSError as exc:  # e.g. a folder that cannot be written
        sys.exit(f"error: cannot write the report: {exc}")
    problems = input_problems(analyses)
    for line in problems:
        print(f"WARNING: {line}", file=sys.stderr)
    print(path)
    if args.strict and problems:
        sys.exit(
            f"error: --strict: {len(problems)} problem(s) in the input files (the WARNING "
            f"lines above); the report was written to {path}"
        )


if __name__ == "__main__":
    main()
