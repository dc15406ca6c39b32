"""Adaptive seeding's error rates and cost, measured (issue 26).

    python scripts/adaptive_seeds.py [--reps 4000] [--out results/adaptive_seeds]

1. **Synthetic nulls** (no true difference between the VUTs; a seed-block effect shared by
   all VUTs): how often the whole sequence of looks (4, 5, 6 seeds) ends in a "settled"
   claim, for the product's rule (:func:`sumo_ayss.analysis.sequential.settle_check`), for
   the naive rule (stop when the current ends' paired t is below 0.05) and for one look at
   4 seeds with no gate. Three error shapes: normal; seed blocks of very different scale
   (log-normal, sd 0.7: opponents that learned little shrink every score); heavy tails (t, 3
   degrees of freedom).
2. **Synthetic ladders** (VUT i's true score ``i * delta``, noise sd 1): how often the rule
   settles, at how many seeds, and how often it settles with the ends the wrong way round.
3. **First looks**: every fresh-seed validation ladder-case of session 6 (seeds 401-404,
   ``runs/verdict``) at its first look: would the rule stop at 4 seeds, with what order.
4. **Real ladders**: the per-seed cross-play blocks at the verdict budget (20,000
   transitions, 200 outcome scenarios) of the ladders with 6 seeds: braking and ACC
   time-gap (from the verdict curve's cells, ``runs/verdict_curve``) and minGap
   car-following on fresh seeds 401-406 (``runs/verdict/min_gap``). Every order of the 6
   seeds is one replay of adaptive seeding (start with the first 4, add the 5th, the 6th):
   where it stops, Kendall's τ and the ends at the stop, and the mean seeds per VUT.

Prints the tables and writes them as CSV with a README into ``--out``.
"""

from __future__ import annotations

import argparse
import csv
import itertools
import json
import math
import sys
from pathlib import Path

import numpy as np

from sumo_ayss.analysis.seeds import SeedScores, compare_seeds, kendall_tau
from sumo_ayss.analysis.sequential import looks_of, settle_check
from sumo_ayss.util.paths import PROJECT_ROOT

LOOKS = looks_of(4, 6)
PARTS = ("real", "first", "synthetic")


def _scores(x: np.ndarray, names: list[str] | None = None) -> list[SeedScores]:
    names = names or [f"v{i}" for i in range(x.shape[0])]
    return [SeedScores(n, dict(enumerate(row.tolist()))) for n, row in zip(names, x, strict=True)]


def _ends_p(x: np.ndarray) -> float:
    s = _scores(x)
    m = x.mean(axis=1)
    return compare_seeds(s[int(m.argmin())], s[int(m.argmax())]).p


def replay(x: np.ndarray, names: list[str] | None = None) -> tuple[int | None, object]:
    """(seeds at the settled look or None, the last look's check) of one grid."""
    check = None
    for n in LOOKS:
        check = settle_check(_scores(x[:, :n], names), LOOKS)
        if check.settled:
            return n, check
    return None, check


def synthetic_nulls(reps: int, rng: np.random.Generator) -> list[dict]:
    rows = []
    shapes = {
        "normal": lambda k, n: rng.normal(size=(k, n)),
        "block scale sd 0.7": lambda k, n: (
            rng.normal(size=(k, n)) * np.exp(rng.normal(0.0, 0.7, n))
        ),
        "t, 3 df": lambda k, n: rng.standard_t(3, size=(k, n)),
    }
    for shape, draw in shapes.items():
        for k in (2, 3, 4, 6):
            rule = naive = one = 0
            for _ in range(reps):
                x = draw(k, LOOKS[-1]) + 3.0 * rng.normal(size=LOOKS[-1])
                rule += replay(x)[0] is not None
                naive += any(_ends_p(x[:, :n]) < 0.05 for n in LOOKS)
                one += _ends_p(x[:, :4]) < 0.05
            se = math.sqrt(0.05 * 0.95 / reps)
            rows.append(
                {
                    "errors": shape,
                    "vuts": k,
                    "reps": reps,
                    "adaptive_rule": round(rule / reps, 4),
                    "naive_rule": round(naive / reps, 4),
                    "one_look_4_seeds_no_gate": round(one / reps, 4),
                    "mc_se_at_0.05": round(se, 4),
                }
            )
            print(rows[-1], flush=True)
    return rows


def synthetic_ladders(reps: int, rng: np.random.Generator) -> list[dict]:
    rows = []
    for k in (3, 4):
        for delta in (0.25, 0.5, 1.0, 2.0):
            truth = [f"v{i}" for i in range(k)]
            stops, wrong, tau1 = [], 0, 0
            for _ in range(reps):
                x = (
                    delta * np.arange(k)[:, None]
                    + rng.normal(size=(k, LOOKS[-1]))
                    + 3.0 * rng.normal(size=LOOKS[-1])
                )
                n, check = replay(x, truth)
                stops.append(n)
                if n is not None:
                    wrong += check.safest == truth[-1] or check.least_safe == truth[0]
                    order = [truth[i] for i in np.argsort(x[:, :n].mean(axis=1), kind="stable")]
                    tau1 += kendall_tau(order, truth) == 1.0
            settled = [n for n in stops if n is not None]
            rows.append(
                {
                    "vuts": k,
                    "delta_per_step_in_noise_sd": delta,
                    "reps": reps,
                    "settled": round(len(settled) / reps, 4),
                    "settled_at_4": round(sum(n == 4 for n in settled) / reps, 4),
                    "mean_seeds": round(float(np.mean([n or LOOKS[-1] for n in stops])), 3),
                    "settled_ends_wrong_way": round(wrong / reps, 4),
                    "settled_tau_1": round(tau1 / reps, 4),
                }
            )
            print(rows[-1], flush=True)
    return rows


def _cells_blocks() -> dict[str, tuple[list[str], np.ndarray]]:
    sys.path.insert(0, str(PROJECT_ROOT / "scripts"))
    import verdict_curve as vc  # the verdict curve's own cell reader

    out = {}
    for study in ("braking", "acc_time_gap"):
        for case in ("car_following", "cut_in"):
            folder = PROJECT_ROOT / "runs" / "verdict_curve" / study / case
            if not (folder / "cells.csv").is_file():
                continue
            data, meta, _ = vc._load_cells(folder)
            runs = meta["runs"]
            vuts = vc._expected(meta)
            seeds = sorted({int(k.split("/")[1]) for k in runs})
            x = np.zeros((len(vuts), len(seeds)))
            for j, s in enumerate(seeds):
                for i, v in enumerate(vuts):
                    steps = [runs[f"{o}/{s}"]["spcp_by_budget"]["20000"] for o in vuts]
                    x[i, j] = np.mean(
                        [
                            data[(v, o, s, st)][0][:200].mean()
                            for o, st in zip(vuts, steps, strict=True)
                        ]
                    )
            out[f"{study} {case} (seeds {seeds[0]}-{seeds[-1]}, cells at 20k)"] = (vuts, x)
    return out


def _run_blocks(study: str, case: str) -> tuple[list[str], np.ndarray, list[int]] | None:
    """A fresh-seed validation run's per-seed cross-play blocks (``runs/verdict``), VUTs in
    the known order; None where the run folders are not here."""
    from sumo_ayss.run_folder import find_run_dirs, read_case_matrix, read_run

    folder = PROJECT_ROOT / "runs" / "verdict" / study
    if not (folder / case / "crossplay.csv").is_file():
        return None
    order = json.loads((folder / "order_check.json").read_text())["expected"]
    m = read_case_matrix([read_run(d) for d in find_run_dirs([folder / case])])
    by = {s.name: s for s in m.scores("seed")}
    return order, np.array([by[v].array for v in order]), list(by[order[0]].seeds)


def _folder_blocks() -> dict[str, tuple[list[str], np.ndarray]]:
    found = _run_blocks("min_gap", "car_following")
    if found is None:
        return {}
    order, x, seeds = found
    return {f"min_gap car_following (seeds {seeds[0]}-{seeds[-1]}, runs)": (order, x)}


def first_looks() -> list[dict]:
    """The first look (4 seeds) at every fresh-seed validation ladder-case of session 6
    (seeds 401-404, verdict budget): would adaptive seeding stop there, and with what order?"""
    rows = []
    for study in ("braking", "acc_time_gap", "reaction", "min_gap"):
        for case in ("car_following", "cut_in"):
            found = _run_blocks(study, case)
            if found is None:
                continue
            order, x, _ = found
            check = settle_check(_scores(x[:, :4], order), LOOKS)
            ranked = [order[i] for i in np.argsort(x[:, :4].mean(axis=1), kind="stable")]
            rows.append(
                {
                    "ladder": study,
                    "case": case,
                    "ranking": " > ".join(ranked),
                    "kendall_tau": kendall_tau(ranked, order),
                    "f_gate_p": float(f"{check.omnibus_p:.3g}"),
                    "gate_level": round(check.gate_level, 4),
                    "ends_p": float(f"{check.ends_p:.3g}"),
                    "settled_at_4": check.settled,
                }
            )
            print(rows[-1], flush=True)
    return rows


def real_ladders() -> list[dict]:
    rows = []
    for name, (vuts, x) in {**_cells_blocks(), **_folder_blocks()}.items():
        stops, tau1, ends_ok = [], 0, 0
        perms = list(itertools.permutations(range(x.shape[1])))
        for perm in perms:
            xp = x[:, list(perm)]
            n, check = replay(xp, vuts)
            stops.append(n)
            if n is not None:
                order = [vuts[i] for i in np.argsort(xp[:, :n].mean(axis=1), kind="stable")]
                tau1 += kendall_tau(order, vuts) == 1.0
                ends_ok += check.safest == vuts[0] and check.least_safe == vuts[-1]
        settled = [n for n in stops if n is not None]
        mean_seeds = float(np.mean([n or LOOKS[-1] for n in stops]))
        rows.append(
            {
                "ladder": name,
                "vuts": len(vuts),
                "replays": len(perms),
                "settled": round(len(settled) / len(perms), 4),
                "at_4": round(sum(n == 4 for n in settled) / len(perms), 4),
                "at_5": round(sum(n == 5 for n in settled) / len(perms), 4),
                "at_6": round(sum(n == 6 for n in settled) / len(perms), 4),
                "settled_tau_1": round(tau1 / len(perms), 4),
                "settled_ends_right": round(ends_ok / len(perms), 4),
                "mean_seeds": round(mean_seeds, 3),
            }
        )
        print(rows[-1], flush=True)
    return rows


def _write(path: Path, rows: list[dict]) -> None:
    with path.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--reps", type=int, default=4000)
    p.add_argument("--out", type=Path, default=PROJECT_ROOT / "results" / "adaptive_seeds")
    p.add_argument(
        "--parts",
        nargs="+",
        choices=PARTS,
        default=list(PARTS),
        help="which tables to write (default: all)",
    )
    a = p.parse_args()
    a.out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(2026)
    if "real" in a.parts:
        _write(a.out / "real_ladders.csv", real_ladders())
    if "first" in a.parts:
        _write(a.out / "first_looks.csv", first_looks())
    if "synthetic" in a.parts:  # the nulls, then the ladders, from one random stream
        _write(a.out / "synthetic_nulls.csv", synthetic_nulls(a.reps, rng))
        _write(a.out / "synthetic_ladders.csv", synthetic_ladders(a.reps, rng))
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
