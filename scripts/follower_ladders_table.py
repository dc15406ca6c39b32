"""Issue 33: the committed default-budget ladders re-run with the follower, beside the same
ladders without it, as one Markdown table (cross-play mode, the default).

    python scripts/follower_ladders_table.py results/follower_ladders results/verdict_budget

For every ``<with>/<ladder>/`` holding ``order_check.json`` and ``ranking.csv`` (written by
``rank`` with the follower on), one row per case: Kendall's τ, the ends' p, significant
adjacent pairs, rear-ends (and those the VUT caused), each VUT's unjustified-braking rate in
the known order, OVER-BRAKING flags; then the same ladder's τ, ends' p and adjacent pairs
from ``<without>/<ladder>/order_check.json`` (the committed run, no follower).
"""

from __future__ import annotations

import sys
from pathlib import Path

from sumo_ayss.run_folder.study import StudyFolder, read_order_check, read_ranking_csv

MODE = "crossplay"


def _check_cells(study: Path, case: str) -> tuple[str, str, str, tuple[str, ...]]:
    checks = read_order_check(StudyFolder(study).order_check_json)
    for c in checks.cases:
        if c.case == case and c.mode == MODE:
            sig = "yes" if c.ends_significant else "no"
            return (
                f"{c.tau:.2f}",
                f"{c.ends_p:.3g} ({sig})",
                f"{c.significant_adjacent} of {c.adjacent}",
                checks.expected,
            )
    return "—", "—", "—", ()


def rows(with_root: Path, without_root: Path) -> list[str]:
    out = [
        "| ladder | case | τ | ends p | adjacent significant | rear-ends (caused) | "
        "unjustified braking, known order | flags | without follower: τ, ends p, adjacent |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for study in sorted(p for p in with_root.iterdir() if (p / "order_check.json").exists()):
        ranking = [r for r in read_ranking_csv(StudyFolder(study).ranking_csv) if r["mode"] == MODE]
        for case in dict.fromkeys(r["case"] for r in ranking):
            tau, ends, adj, expected = _check_cells(study, case)
            mine = {r["vut"]: r for r in ranking if r["case"] == case}
            order = [v for v in expected if v in mine] or list(mine)
            rear = sum(float(mine[v]["rear_end_rate"] or "nan") for v in order)
            caused = sum(float(mine[v]["rear_end_caused_rate"] or "nan") for v in order)
            ub = ", ".join(
                f"{v} {100 * float(mine[v]['unjustified_braking_rate']):.0f} %"
                if mine[v]["unjustified_braking_rate"]
                else f"{v} —"
                for v in order
            )
            flags = ", ".join(v for v in order if mine[v]["overbraking"] == "True") or "none"
            ref = without_root / study.name
            old = _check_cells(ref, case) if (ref / "order_check.json").exists() else ("—",) * 3
            out.append(
                f"| {study.name} | {case} | {tau} | {ends} | {adj} | "
                f"{100 * rear / len(order):.2f} % ({100 * caused / len(order):.2f} %) | {ub} | "
                f"{flags} | {old[0]}, {old[1]}, {old[2]} |"
            )
    return out


if __name__ == "__main__":
    print("\n".join(rows(Path(sys.argv[1]), Path(sys.argv[2]))))
