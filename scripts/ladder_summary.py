"""Summarise ladder studies: Kendall's τ, significance and crash rates per ladder, case, run.

    python scripts/ladder_summary.py results/ladders

Reads every ``<root>/<ladder>_<run>/order_check.json`` and ``ranking.csv`` written by
``python -m sumo_ayss.rank`` (with ``expected_order``), prints a Markdown table (one row per
ladder, case, run and mode: τ, ends significant with p, significant adjacent pairs, the
ranking, each VUT's crash rate in the known order, TIMID flags), writes it to
``<root>/summary.md`` and draws two figures:

* ``<root>/per_seed_harm.png``: one panel per ladder and case, the per-seed harm of each
  VUT's own SPCPs (exposure mode) in the known order (safest left), one line per training
  seed, the runs side by side;
* ``<root>/crossplay_by_opponent.png`` (where ``<study>/<case>/crossplay.csv`` exists): one
  panel per ladder, case and run, each opponent SPCP's mean harm per episode across the
  VUTs in the known order.

Harm: :mod:`sumo_ayss.analysis.harm` (1 for a collision, else near-miss pay over the most an
episode can pay; lower = safer).
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib as mpl

mpl.use("Agg")
from matplotlib.figure import Figure

from sumo_ayss.analysis.crossplay_scoring import crossplay_input
from sumo_ayss.analysis.harm import run_episodes
from sumo_ayss.run_folder import StudyFolder, group_runs, read_run
from sumo_ayss.run_folder.crossplay import load_crossplay
from sumo_ayss.run_folder.study import read_order_check, read_ranking_csv
from sumo_ayss.util.atomic import atomic_write_text


def _runs(study: Path, case: str) -> dict[str, list]:
    """The study's loaded runs of one case, by VUT."""
    dirs = sorted((study / case).glob("*/seed_*"))
    return group_runs([read_run(d) for d in dirs]).get(case, {})


def _crash_cells(study: Path, case: str, mode: str, expected: list[str]) -> tuple[str, str]:
    """``"19.8 / 11.6 / 5.7 %"`` in the known order, and the TIMID VUTs, from ranking.csv."""
    ranking = read_ranking_csv(StudyFolder(study).ranking_csv)
    rows = {r["vut"]: r for r in ranking if r["case"] == case and r["mode"] == mode}
    if not all(rows.get(v, {}).get("crash_rate") for v in expected):
        return "—", "—"
    rates = " / ".join(f"{100 * float(rows[v]['crash_rate']):.1f}" for v in expected) + " %"
    timid = [v for v in expected if rows[v].get("timid") == "True"]
    return rates, ", ".join(timid) or "none"


def main(root: Path) -> None:
    studies = sorted(p.parent for p in root.glob("*/order_check.json"))
    if not studies:
        sys.exit(f"no <study>/order_check.json under {root}")
    lines = [
        "| ladder | case | run (seeds) | mode | Kendall τ | ends significant (p) | significant "
        "adjacent pairs | ranking, safest first | crash rate, known order | TIMID |",
        "|---|---|---|---|---:|---|---:|---|---|---|",
    ]
    panels: dict[tuple[str, str], list[tuple[str, Path, list[str]]]] = {}
    for study in studies:
        check = read_order_check(StudyFolder(study).order_check_json)
        expected = list(check.expected)
        ladder, _, run = study.name.rpartition("_")
        for c in check.cases:
            runs = _runs(study, c.case)
            seeds = sorted({r.seed for rs in runs.values() for r in rs if r.seed is not None})
            per_vut = max((len(rs) for rs in runs.values()), default=0)
            rates, timid = _crash_cells(study, c.case, c.mode, expected)
            lines.append(
                f"| {ladder} | {c.case} | {run} ({', '.join(map(str, seeds))}; "
                f"{per_vut} per VUT) | {c.mode} | {c.tau:.2f} | "
                f"{'yes' if c.ends_significant else 'no'} ({c.ends_p:.3g}) | "
                f"{c.significant_adjacent} of {c.adjacent} | {' > '.join(c.order)} | "
                f"{rates} | {timid} |"
            )
            entries = panels.setdefault((ladder, c.case), [])
            if all(e[1] != study for e in entries):  # one entry per run, whatever the modes
                entries.append((run, study, expected))
    table = "\n".join(lines) + "\n"
    print(table)
    atomic_write_text(root / "summary.md", table)
    per_seed_figure(root, panels)
    crossplay_figure(root, panels)


def per_seed_figure(
    root: Path, panels: dict[tuple[str, str], list[tuple[str, Path, list[str]]]]
) -> None:
    """``<root>/per_seed_harm.png``: each VUT's own SPCPs, harm per seed, known order."""
    fig = Figure(figsize=(4.6 * len(panels), 4.2), layout="constrained")
    axes = fig.subplots(1, len(panels), squeeze=False)[0]
    for ax, ((ladder, case), entries) in zip(axes, sorted(panels.items()), strict=True):
        for k, (run, study, expected) in enumerate(entries):
            runs = _runs(study, case)
            scores = {
                v: {r.seed: e.mean_harm for r in runs.get(v, []) if (e := run_episodes(r))}
                for v in expected
            }
            seeds = sorted({s for v in expected for s in scores[v]})
            offset = 0.12 * (k - (len(entries) - 1) / 2)
            for seed in seeds:
                xs = [i + offset for i, v in enumerate(expected) if seed in scores[v]]
                ys = [scores[v][seed] for v in expected if seed in scores[v]]
                label = f"run {run}" if seed == seeds[0] else None
                ax.plot(xs, ys, marker="o", ms=4, lw=1, color=f"C{k}", alpha=0.8, label=label)
        ax.set_xticks(range(len(entries[0][2])), entries[0][2])
        ax.set_title(f"{ladder}, {case}")
        ax.set_xlabel("VUT, known order (safest left)")
        ax.set_ylabel("harm per episode, own SPCP per seed (lower = safer)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.savefig(root / "per_seed_harm.png", dpi=100)
    print(f"wrote {root / 'summary.md'} and {root / 'per_seed_harm.png'}")


def crossplay_figure(
    root: Path, panels: dict[tuple[str, str], list[tuple[str, Path, list[str]]]]
) -> None:
    """``<root>/crossplay_by_opponent.png``: per ladder, case and run, each opponent's mean
    harm per episode across the VUTs in the known order (where a usable table exists)."""
    cells = []
    for (ladder, case), entries in sorted(panels.items()):
        for run, study, expected in entries:
            by_vut = _runs(study, case)
            found = crossplay_input(load_crossplay(by_vut), by_vut)
            if found.matrix is not None:
                cells.append((ladder, case, run, expected, found.matrix))
    if not cells:
        return
    cols = 4
    n_rows = (len(cells) + cols - 1) // cols
    fig = Figure(figsize=(4.4 * cols, 4.0 * n_rows), layout="constrained")
    axes = fig.subplots(n_rows, cols, squeeze=False).ravel()
    for ax in axes[len(cells) :]:
        ax.set_visible(False)
    for ax, (ladder, case, run, expected, m) in zip(axes, cells, strict=False):
        order = [v for v in expected if v in m.vuts]
        rows = [m.vuts.index(v) for v in order]
        for j, (vut, seed) in enumerate(m.opponents):
            ax.plot(
                range(len(order)),
                m.harm[rows, j],
                marker="o",
                ms=3,
                lw=1,
                color=f"C{order.index(vut) if vut in order else 9}",
                alpha=0.8,
                ls=("-", "--", ":", "-.")[seed % 4],
                label=f"vs {vut}, seed {seed}",
            )
        ax.set_xticks(range(len(order)), order)
        ax.set_title(f"{ladder}, {case}, run {run}", fontsize=10)
        ax.set_xlabel("VUT, known order (safest left)")
        ax.set_ylabel("harm per episode, per opponent")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=5, ncol=2)
    fig.savefig(root / "crossplay_by_opponent.png", dpi=90)
    print(f"wrote {root / 'crossplay_by_opponent.png'}")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("results/ladders"))
