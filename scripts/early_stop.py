"""The early-stopping rule (issue 40, item 2), checked without training anything.

    python scripts/early_stop.py tables [--out results/early_stop]   # committed eval tables
    python scripts/early_stop.py nulls [--grids 2000] [--out results/early_stop]

``tables``: every committed run's ``eval.csv`` under ``results/`` (its candidates' mean
evaluation return and spread on the fixed evaluation scenarios), read through the rule
(:func:`sumo_ayss.analysis.early_stop.stop_index`) for each (patience, margin_se): how many
runs it stops, at what share of their transitions, whether the SPCP selected among the
candidates trained so far is the one the whole run selected, and how much lower its score
is (in standard errors of the whole run's SPCP). ``committed_runs.csv``: one row per rule
and candidate spacing (10,000 or 5,000 transitions).

``nulls``: the ranking's family-wise false-claim rate on synthetic null grids with every
run trained to its last candidate and with every run stopped by the rule
(:func:`sumo_ayss.analysis.early_stop.null_false_claims`), for 3, 4 and 6 VUTs, 4 and 6
seed blocks; and, as the control that the check can fail, a rule that stops one VUT's runs
after their first candidate. ``synthetic_nulls.csv``.
"""

from __future__ import annotations

import argparse
import csv
import io
import statistics
from collections import defaultdict
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from sumo_ayss.analysis.early_stop import evaluation_se, null_false_claims, stop_index
from sumo_ayss.util.atomic import atomic_write_text
from sumo_ayss.util.paths import PROJECT_ROOT

RULES = ((1, 1.0), (2, 0.0), (2, 1.0), (2, 2.0), (3, 1.0))


def _write(path: Path, rows: list[dict]) -> None:
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=list(rows[0]), lineterminator="\n")
    w.writeheader()
    w.writerows(rows)
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(path, buf.getvalue())
    print(f"wrote {path}")


def tables(out: Path) -> None:
    groups: dict[int, list[tuple[list[int], list[float], list[float]]]] = defaultdict(list)
    for path in sorted((PROJECT_ROOT / "results").rglob("eval.csv")):
        with path.open() as f:
            rows = list(csv.DictReader(f))
        if len(rows) < 2:
            continue
        steps = [int(r["step"]) for r in rows]
        scores = [float(r["mean_return"]) for r in rows]
        ses = [evaluation_se(r) for r in rows]
        groups[round((steps[1] - steps[0]) / 1000) * 1000].append((steps, scores, ses))
    table = []
    for spacing, runs in sorted(groups.items()):
        for patience, margin in RULES:
            stopped = same = 0
            shares, losses = [], []
            for steps, scores, ses in runs:
                j = stop_index(scores, ses, patience, margin)
                end = len(scores) - 1 if j is None else j
                full = int(np.argmax(scores))
                prefix = int(np.argmax(scores[: end + 1]))
                stopped += j is not None
                same += prefix == full
                shares.append(steps[end] / steps[-1])
                se = ses[full] or 1.0
                losses.append((scores[full] - scores[prefix]) / se)
            table.append(
                {
                    "candidate_every": spacing,
                    "runs": len(runs),
                    "candidates_per_run": statistics.median(len(r[0]) for r in runs),
                    "patience": patience,
                    "margin_se": margin,
                    "stopped": stopped,
                    "same_spcp": same,
                    "mean_share_of_transitions": round(statistics.mean(shares), 3),
                    "mean_score_loss_se": round(statistics.mean(losses), 2),
                    "max_score_loss_se": round(max(losses), 2),
                }
            )
    _write(out / "committed_runs.csv", table)
    for row in table:
        print(row)


def nulls(out: Path, grids: int) -> None:
    table = []
    rng = np.random.default_rng(40)
    for vuts in (3, 4, 6):
        for seeds in (4, 6):
            for patience, margin in ((1, 1.0), (2, 1.0), (3, 1.0)):
                r = null_false_claims(
                    rng, grids=grids, vuts=vuts, seeds=seeds, patience=patience, margin_se=margin
                )
                table.append(_null_row("rule", vuts, seeds, patience, margin, r))
            r = null_false_claims(
                rng,
                grids=grids,
                vuts=vuts,
                seeds=seeds,
                patience=2,
                margin_se=1.0,
                biased_vut=True,
            )
            table.append(_null_row("one VUT stopped first (control)", vuts, seeds, 2, 1.0, r))
            print(table[-1])
    _write(out / "synthetic_nulls.csv", table)


def _null_row(kind: str, vuts: int, seeds: int, patience: int, margin: float, r) -> dict:
    return {
        "rule": kind,
        "vuts": vuts,
        "seed_blocks": seeds,
        "patience": patience,
        "margin_se": margin,
        "grids": r.grids,
        "false_claims_full_runs": r.rate_full,
        "false_claims_stopped_runs": r.rate_stopped,
        "runs_stopped": round(r.stopped_share, 3),
        "mean_share_of_candidates": round(r.mean_budget, 3),
    }


def main(argv: Sequence[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="cmd", required=True)
    t = sub.add_parser("tables")
    t.add_argument("--out", type=Path, default=PROJECT_ROOT / "results" / "early_stop")
    n = sub.add_parser("nulls")
    n.add_argument("--out", type=Path, default=PROJECT_ROOT / "results" / "early_stop")
    n.add_argument("--grids", type=int, default=2000)
    a = p.parse_args(argv)
    if a.cmd == "tables":
        tables(a.out)
    else:
        nulls(a.out, a.grids)


if __name__ == "__main__":
    main()
