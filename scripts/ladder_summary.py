"""Summarise a ladder study: Kendall's τ and significance per ladder, case and run.

    python scripts/ladder_summary.py results/ladders

Reads every ``<root>/<ladder>_<run>/order_check.json`` and ``ranking.csv`` written by
``python -m sumo_ayss.rank`` (with ``expected_order``), prints a Markdown table (one row per
ladder, case, run and mode: τ, ends significant with p, significant adjacent pairs, the
ranking), writes it to ``<root>/summary.md`` and draws ``<root>/per_seed_exposure.png``: one
panel per ladder and case, the per-seed exposure of every VUT in the known order (safest
left), one line per training seed, both runs side by side. Where ``<study>/<case>/
crossplay.csv`` exists it also draws ``<root>/crossplay_by_opponent.png``: one panel per
ladder and case, per run, each opponent SPCP's mean episode reward across the VUTs in the
known order.
"""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

import matplotlib as mpl

mpl.use("Agg")
from matplotlib.figure import Figure

from sumo_ayss.atomic import atomic_write_text
from sumo_ayss.report.load import read_crossplay_matrix
from sumo_ayss.run_folder import CaseFolder, RunFolder, case_dir_for, read_outcome_json, seed_of_dir


def _per_seed(study: Path, case: str, vut: str) -> dict[int, float]:
    out = {}
    for run in sorted((study / case / vut).glob("seed_*")):
        folder, seed = RunFolder(run), seed_of_dir(run)
        if seed is not None and folder.outcome_json.is_file():
            out[seed] = read_outcome_json(folder.outcome_json).outcome.mean_return.value
    return out


def main(root: Path) -> None:
    studies = sorted(p.parent for p in root.glob("*/order_check.json"))
    if not studies:
        sys.exit(f"no <study>/order_check.json under {root}")
    lines = [
        "| ladder | case | run (seeds) | mode | Kendall τ | ends significant (p) | significant "
        "adjacent pairs | ranking, safest first |",
        "|---|---|---|---|---:|---|---:|---|",
    ]
    panels: dict[tuple[str, str], list[tuple[str, Path, list[str]]]] = {}
    for study in studies:
        check = json.loads((study / "order_check.json").read_text())
        ladder, _, run = study.name.rpartition("_")
        with (study / "ranking.csv").open() as f:
            seeds = {
                r["case"]: r["n_seeds"]
                for r in csv.DictReader(f)
                if r.get("mode", "exposure") == "exposure"
            }
        for c in check["cases"]:
            seed_list = sorted(_per_seed(study, c["case"], check["expected"][0]))
            lines.append(
                f"| {ladder} | {c['case']} | {run} ({', '.join(map(str, seed_list))}; "
                f"{seeds.get(c['case'], '?')} per VUT) | {c.get('mode', 'exposure')} | "
                f"{c['tau']:.2f} | "
                f"{'yes' if c['ends_significant'] else 'no'} ({c['ends_p']:.3g}) | "
                f"{c['significant_adjacent']} of {c['adjacent']} | {' > '.join(c['order'])} |"
            )
            runs = panels.setdefault((ladder, c["case"]), [])
            if all(r[1] != study for r in runs):  # one panel entry per run, whatever the modes
                runs.append((run, study, check["expected"]))
    table = "\n".join(lines) + "\n"
    print(table)
    atomic_write_text(root / "summary.md", table)

    fig = Figure(figsize=(5.2 * len(panels), 4.4), layout="constrained")
    axes = fig.subplots(1, len(panels), squeeze=False)[0]
    for ax, ((ladder, case), runs) in zip(axes, sorted(panels.items()), strict=True):
        for k, (run, study, expected) in enumerate(runs):
            scores = {v: _per_seed(study, case, v) for v in expected}
            seeds = sorted({s for v in expected for s in scores[v]})
            offset = 0.12 * (k - (len(runs) - 1) / 2)
            for seed in seeds:
                xs = [i + offset for i, v in enumerate(expected) if seed in scores[v]]
                ys = [scores[v][seed] for v in expected if seed in scores[v]]
                ax.plot(
                    xs,
                    ys,
                    marker="o",
                    ms=4,
                    lw=1,
                    color=f"C{k}",
                    alpha=0.8,
                    label=f"run {run}" if seed == seeds[0] else None,
                )
        ax.set_xticks(range(len(runs[0][2])), runs[0][2])
        ax.set_title(f"{ladder}, {case}")
        ax.set_xlabel("VUT, known order (safest left)")
        ax.set_ylabel("exposure E per seed (lower = safer)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.savefig(root / "per_seed_exposure.png", dpi=110)
    print(f"wrote {root / 'summary.md'} and {root / 'per_seed_exposure.png'}")
    crossplay_figure(root, panels)


def crossplay_figure(
    root: Path, panels: dict[tuple[str, str], list[tuple[str, Path, list[str]]]]
) -> None:
    """``<root>/crossplay_by_opponent.png``: per ladder and case, per run, each opponent's
    mean episode reward across the VUTs in the known order (when crossplay.csv exists)."""
    cells = [
        (ladder, case, run, expected, read_crossplay_matrix(path))
        for (ladder, case), runs in sorted(panels.items())
        for run, study, expected in runs
        if (path := CaseFolder(case_dir_for(study, case)).crossplay_csv).is_file()
    ]
    if not cells:
        return
    fig = Figure(figsize=(4.6 * len(cells), 4.4), layout="constrained")
    axes = fig.subplots(1, len(cells), squeeze=False)[0]
    for ax, (ladder, case, run, expected, m) in zip(axes, cells, strict=True):
        order = [v for v in expected if v in m.vuts]
        rows = [m.vuts.index(v) for v in order]
        for j, (vut, seed) in enumerate(m.opponents):
            color = f"C{order.index(vut) if vut in order else 9}"
            ax.plot(
                range(len(order)),
                m.returns[rows, j],
                marker="o",
                ms=3,
                lw=1,
                color=color,
                alpha=0.8,
                ls=("-", "--", ":", "-.")[seed % 4],
                label=f"vs {vut}, seed {seed}",
            )
        ax.set_xticks(range(len(order)), order)
        ax.set_title(f"{ladder}, {case}, run {run}")
        ax.set_xlabel("VUT, known order (safest left)")
        ax.set_ylabel("mean episode reward per opponent (reward/episode)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=6, ncol=2)
    fig.savefig(root / "crossplay_by_opponent.png", dpi=110)
    print(f"wrote {root / 'crossplay_by_opponent.png'}")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("results/ladders"))
