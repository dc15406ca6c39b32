"""How many training seeds (cross-play blocks) a ladder needs: power from observed blocks.

    python scripts/power_blocks.py results/ladders/braking_a [results/ladders/braking_b ...]

For each study, case and pair of VUTs adjacent in the known order (and the two ends), takes
the per-seed-block harm differences of the cross-play table (block s = the mean over seed s's
opponents, the default test's unit), their mean d and standard deviation sd, and estimates by
Monte Carlo the power of the default test (paired t over n blocks, two-sided alpha 0.05, the
right direction) for n = 3 .. 10 blocks, assuming block differences ~ Normal(d, sd). Several
studies of one ladder are pooled (their blocks together) before d and sd are taken.
Prints a Markdown table.
"""

from __future__ import annotations

import itertools
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

from sumo_ayss.analysis.crossplay_scoring import crossplay_input
from sumo_ayss.analysis.stats import student_t_sf
from sumo_ayss.run_folder import StudyFolder, group_runs, read_run
from sumo_ayss.run_folder.crossplay import load_crossplay
from sumo_ayss.run_folder.study import read_order_check

NS = (3, 4, 5, 6, 8, 10)
REPS = 4000


def power(d: float, sd: float, n: int, rng: np.random.Generator) -> float:
    """P(paired t over n blocks finds the difference, p < 0.05, right sign)."""
    x = rng.normal(d, max(sd, 1e-12), (REPS, n))
    m, s = x.mean(axis=1), x.std(axis=1, ddof=1)
    t = m / (s / np.sqrt(n))
    p = np.array([2 * student_t_sf(abs(v), n - 1) for v in t])
    return float(np.mean((p < 0.05) & (np.sign(m) == np.sign(d))))


def block_diffs(study: Path) -> dict[tuple[str, str, str], list[float]]:
    """(case, safer VUT, less safe VUT) -> per-block harm differences (less safe - safer)."""
    expected = list(read_order_check(StudyFolder(study).order_check_json).expected)
    out: dict[tuple[str, str, str], list[float]] = {}
    runs = group_runs([read_run(d) for d in sorted(study.glob("*/*/seed_*"))])
    for case, by_vut in runs.items():
        m = crossplay_input(load_crossplay(by_vut), by_vut).matrix
        if m is None:
            continue
        scores = {sc.name: sc.values for sc in m.scores("seed")}
        pairs = [*itertools.pairwise(expected), (expected[0], expected[-1])]
        for a, b in pairs:
            out[(case, a, b)] = [scores[b][s] - scores[a][s] for s in sorted(scores[a])]
    return out


def main(studies: list[Path]) -> None:
    pooled: dict[tuple[str, str, str], list[float]] = defaultdict(list)
    for study in studies:
        for key, diffs in block_diffs(study).items():
            pooled[key] += diffs
    rng = np.random.default_rng(0)
    print(
        "| case | pair (safer vs less safe) | blocks | mean d | sd | "
        + " | ".join(f"power n={n}" for n in NS)
        + " |"
    )
    print("|---|---|---:|---:|---:|" + "---:|" * len(NS))
    for (case, a, b), diffs in sorted(pooled.items()):
        d, sd = float(np.mean(diffs)), float(np.std(diffs, ddof=1))
        cells = " | ".join(f"{power(d, sd, n, rng):.2f}" for n in NS)
        print(f"| {case} | {a} vs {b} | {len(diffs)} | {d:+.4f} | {sd:.4f} | {cells} |")


if __name__ == "__main__":
    main([Path(a) for a in sys.argv[1:]])
