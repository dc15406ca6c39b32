"""``python -m sumo_ayss.rank`` / ``sumo-ayss rank``: the leaderboard, end to end.

The stage is :mod:`sumo_ayss.rank` (the rows of every mode, the known-order check,
``ranking.csv``/``ranking.md``/``order_check.json``); this command runs the pipeline with its
report (:func:`sumo_ayss.commands.pipeline.run_pipeline`) or, with ``--no-run``, reads the run
folders, then hands the analyses to the report's documents: ranking.md's reference-driver
lines (:func:`sumo_ayss.report.sections.reference.reference_markdown`), ``measures.csv``
(:func:`sumo_ayss.report.measures.write_measures`) and the terminal leaderboard
(:func:`sumo_ayss.report.leaderboard.leaderboard_text`).
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from collections.abc import Sequence
from pathlib import Path

from sumo_ayss import rank as stage
from sumo_ayss.cli import STRICT_HELP, prog
from sumo_ayss.commands.pipeline import run_pipeline
from sumo_ayss.modes import input_problems, missing_rows_line, mode_names
from sumo_ayss.pipeline import (
    add_config_flags,
    config_from_args,
    configure_logging,
    final_messages,
    plan_jobs,
)
from sumo_ayss.run_folder import RunFolder, read_run
from sumo_ayss.util.errors import AyssError, ConfigError

__all__ = ["main"]


def main(argv: Sequence[str] | None = None) -> None:
    parser = argparse.ArgumentParser(
        prog=prog("python -m sumo_ayss.rank"),
        description=(stage.__doc__ or "").splitlines()[0]
        + " Default mode: cross-play (every SPCP of a case against every VUT, ranked by the "
        "harm the pooled SPCPs bring about; lower = safer).",
    )
    parser.add_argument("config", type=Path, help="pipeline YAML listing the VUTs to rank")
    add_config_flags(parser)
    parser.add_argument(
        "--mode",
        choices=list(mode_names()),
        default=None,
        help="replace report.mode (default crossplay: every SPCP against every VUT, run "
        "after the grid; rows of every other mode available follow)",
    )
    parser.add_argument(
        "--no-run",
        action="store_true",
        help=f"rank the grid's existing run folders (with {RunFolder.outcome_json.name}) without "
        "running jobs "
        "or cross-play (cross-play rows appear where <out>/<case>/crossplay.csv exists)",
    )
    parser.add_argument("--no-live", action="store_true", help="no live table (log lines)")
    parser.add_argument("--strict", action="store_true", help=STRICT_HELP)
    args = parser.parse_args(argv)
    console = configure_logging(not args.no_live)
    result = None
    try:
        cfg = config_from_args(args)
        if args.mode is not None:
            cfg = dataclasses.replace(cfg, report=dataclasses.replace(cfg.report, mode=args.mode))
        if args.no_run:
            planned = [j.folder for j in plan_jobs(cfg)]
            done = [f.path for f in planned if f.outcome_json.is_file()]
            complete = len(done) == len(planned)
            if not done:
                raise ConfigError(f"--no-run: no finished run folder under {cfg.out}")
            runs = [read_run(d) for d in done]
            analyses = stage.analyse_loaded(runs, cfg.report)
        else:
            result = run_pipeline(cfg, live=console is not None, console=console)
            complete = all(s.state == "done" for s in result.statuses)
            analyses = result.analyses  # the report's: computed once, not again here
    except AyssError as e:
        sys.exit(f"error: {e}")
    except KeyboardInterrupt:
        print("interrupted: no job runs any more; rerun the same command to resume", flush=True)
        sys.exit(130)
    checks = stage.order_checks(analyses, cfg.expected_order)
    # The report's documents, imported once the grid has run (as before: no plotting
    # library is loaded for --help or while the jobs run).
    from sumo_ayss.report.leaderboard import leaderboard_text
    from sumo_ayss.report.measures import write_measures
    from sumo_ayss.report.sections.reference import reference_markdown

    gaps = [line for a in analyses if (line := missing_rows_line(a)) is not None]
    csv_path, md = stage.write_ranking(
        stage.ranking_rows(analyses),
        cfg.out,
        checks,
        cfg.expected_order,
        [*(x for g in gaps for x in ("", g)), *reference_markdown(analyses)],
    )
    write_measures(cfg.out, analyses)  # measures.csv: the safety measures (issue 27)
    print(leaderboard_text(analyses))
    for c in checks:
        print(
            f"{c.case}, {c.mode} mode, against the known order: Kendall tau = "
            f"{c.tau:.2f}; ends differ significantly: "
            f"{'yes' if c.ends_significant else 'no'}"
        )
    print(f"ranking (every mode): {md} and {csv_path.name}")
    if result is None:  # --no-run
        from sumo_ayss.training.trust import fewest_seeds, trust_warnings

        for warning in trust_warnings(
            [(str(d), r.training) for d, r in zip(done, runs, strict=True)],
            fewest_seeds((r.case, r.vut) for r in runs),
        ):
            print(f"WARNING: {warning}")
    else:
        for line in final_messages(result):
            print(line)
    problems = input_problems(analyses)
    for line in problems:
        print(f"WARNING: {line}", file=sys.stderr)
    if complete and args.strict and problems:
        sys.exit(
            f"error: --strict: {len(problems)} problem(s) in the input files (the WARNING "
            "lines above); the ranking was written"
        )
    sys.exit(0 if complete else 1)


if __name__ == "__main__":
    main()
