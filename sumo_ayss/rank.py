"""Leaderboard: train SPCPs for K VUTs through the pipeline and rank them by safety index.

    python -m sumo_ayss.rank configs/leaderboard.yaml [--workers N] [--no-live]

The config is a pipeline YAML (:mod:`sumo_ayss.pipeline`) whose ``grid.vuts`` lists the
VUTs to rank (any mix of catalog models defined in the experiments' ``env.vuts``). After
the grid, this writes ``<out>/ranking.csv`` and ``<out>/ranking.md`` (per case: rank, VUT,
safety index with its interval, seeds, and the verdict against the next VUT under the
report's significance rule) and the HTML report, and prints the table.

Safety index: minus the mean aggressiveness indicator over the AYSS headway range (equal-
width headway bins, mean of bin means), so larger = safer; its interval is a hierarchical
bootstrap over seeds, then samples (:func:`sumo_ayss.analysis.ranking.safety_index`).
"""

from __future__ import annotations

import argparse
import csv
import io
import logging
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from sumo_ayss.errors import ConfigError

RANKING_COLUMNS = [
    "case",
    "rank",
    "vut",
    "safety_index",
    "lo",
    "hi",
    "n_seeds",
    "unit",
    "vs_next",
    "significant_vs_next",
]


def ranking_rows(run_dirs: Sequence[Path]) -> list[dict[str, Any]]:
    """Ranking rows for every case among ``run_dirs`` (safest first within a case)."""
    from sumo_ayss.report.document import ReportOptions, analyse_case
    from sumo_ayss.report.load import group_runs, load_run

    options = ReportOptions()
    rows: list[dict[str, Any]] = []
    for case, runs in group_runs([load_run(d) for d in run_dirs]).items():
        analysis = analyse_case(case, runs, options)
        pairs = {(p.verdict.name_a, p.verdict.name_b): p for p in analysis.pairs}
        order = [r.name for r in analysis.ranking]
        for i, r in enumerate(analysis.ranking):
            nxt = order[i + 1] if i + 1 < len(order) else None
            pair = pairs.get((r.name, nxt)) if nxt else None
            rows.append(
                {
                    "case": case,
                    "rank": r.rank,
                    "vut": r.name,
                    "safety_index": r.point,
                    "lo": r.lo,
                    "hi": r.hi,
                    "n_seeds": r.n_seeds,
                    "unit": analysis.info.indicator.unit,
                    "vs_next": pair.sentence if pair else "",
                    "significant_vs_next": pair.significant if pair else "",
                }
            )
    return rows


def write_ranking(rows: Sequence[dict[str, Any]], out: Path) -> tuple[Path, Path]:
    """``ranking.csv`` and ``ranking.md`` in ``out`` (written atomically)."""
    from sumo_ayss.atomic import atomic_write_text

    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=RANKING_COLUMNS, lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    atomic_write_text(out / "ranking.csv", buf.getvalue())
    lines = [
        "| case | rank | VUT | safety index (95 % CI) | seeds | vs next |",
        "|---|---:|---|---|---:|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['case']} | {r['rank']} | {r['vut']} | {r['safety_index']:.2f} "
            f"({r['lo']:.2f} to {r['hi']:.2f}) {r['unit']} | {r['n_seeds']} | {r['vs_next']} |"
        )
    atomic_write_text(out / "ranking.md", "\n".join(lines) + "\n")
    return out / "ranking.csv", out / "ranking.md"


def main(argv: Sequence[str] | None = None) -> None:
    from sumo_ayss.pipeline import load_pipeline, run_pipeline

    parser = argparse.ArgumentParser(
        prog="python -m sumo_ayss.rank", description=__doc__.splitlines()[0]
    )
    parser.add_argument("config", type=Path, help="pipeline YAML listing the VUTs to rank")
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--out", type=Path, default=None, help="replace the config's out")
    parser.add_argument(
        "--seeds", type=int, nargs="+", default=None, help="replace grid.seeds (e.g. 100 101 102)"
    )
    parser.add_argument("--no-live", action="store_true")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(name)s: %(message)s")
    try:
        cfg = load_pipeline(args.config, workers=args.workers, out=args.out, seeds=args.seeds)
        statuses, report = run_pipeline(cfg, live=not args.no_live)
    except ConfigError as e:
        sys.exit(f"error: {e}")
    done = [s.spec.run_dir for s in statuses if s.state == "done"]
    _, md = write_ranking(ranking_rows(done), cfg.out)
    print(md.read_text())
    if report is not None:
        print(f"report: {report}")
    sys.exit(0 if len(done) == len(statuses) else 1)


if __name__ == "__main__":
    main()
