"""Family-wise error of a ranking's "safer than" claims, and the power the control costs
(issue 35).

    python scripts/fwer.py [--reps 2000] [--out results/family_wise]

1. **Synthetic nulls and partial nulls.** Grids of K VUTs x n seed blocks (K = 3, 4, 6, 12,
   32; n = 3 and 4), a seed-block effect shared by every VUT (sd 3) and three error shapes
   (normal; seed blocks of very different scale, log-normal sd 0.7; heavy tails, t with 3
   df). *Complete null*: every VUT equally safe. *Partial null*: VUTs in pairs of equally
   safe twins, the pairs 10 noise sd apart (every pair's twins are adjacent; the
   differences between pairs are real). The family-wise error rate is the share of grids in
   which at least one printed claim ("A is safer than B" for an adjacent pair; a pair
   further apart is only claimed through a chain of true adjacent claims, so it adds no
   error of its own) is false, for three rules: each adjacent pair on its own at 0.05 (the
   product before issue 35), an omnibus F gate at 0.05 before the same tests (Fisher's
   protected LSD) and Holm over the adjacent pairs (the product now,
   :mod:`sumo_ayss.analysis.multiplicity`).
2. **Committed ladders.** Every committed study's cross-play table (``results/**/
   crossplay.csv``, seed blocks as the report reads them) and the verdict-budget ladders'
   ``ranking.csv`` (4 seeds, raw adjacent p): adjacent pairs significant on their own and
   under Holm.

The grids are vectorised; a check at start-up compares the vectorised adjacent p-values and
Holm decisions with :func:`sumo_ayss.analysis.seeds.rank_seeds` on 50 grids.
"""

from __future__ import annotations

import argparse
import csv
import math
from pathlib import Path

import numpy as np
from scipy import stats as sps

from sumo_ayss.analysis.multiplicity import holm
from sumo_ayss.analysis.seeds import SeedScores, rank_seeds
from sumo_ayss.analysis.sequential import omnibus_p
from sumo_ayss.util.paths import PROJECT_ROOT

KS = (3, 4, 6, 12, 32)
SHAPES = ("normal", "block scale log-normal sd 0.7", "t, 3 df")


def _grid(rng: np.random.Generator, means: np.ndarray, n: int, shape: str) -> np.ndarray:
    """One grid ``x[i, j]``: VUT i's score in seed block j."""
    k = means.size
    noise = rng.standard_t(3, (k, n)) if shape == "t, 3 df" else rng.normal(0.0, 1.0, (k, n))
    if shape.startswith("block scale"):
        noise = noise * rng.lognormal(0.0, 0.7, n)[None, :]
    return means[:, None] + rng.normal(0.0, 3.0, n)[None, :] + noise


def _adjacent(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(order, raw paired-t p of each adjacent pair) of one grid, lower = safer (harm)."""
    order = np.argsort(x.mean(axis=1), kind="stable")
    d = x[order[:-1]] - x[order[1:]]
    n = x.shape[1]
    se = d.std(axis=1, ddof=1) / math.sqrt(n)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.abs(d.mean(axis=1)) / se
    return order, np.minimum(1.0, 2.0 * sps.t.sf(t, n - 1))


def _check_against_product(rng: np.random.Generator) -> None:
    """The vectorised p-values and Holm decisions equal :func:`rank_seeds`' own."""
    for _ in range(50):
        x = _grid(rng, np.zeros(5), 4, "normal")
        order, p = _adjacent(x)
        names = [f"v{i:02d}" for i in range(5)]
        rows, _ = rank_seeds(
            [SeedScores(names[i], dict(enumerate(x[i].tolist()))) for i in range(5)],
            higher_is_safer=False,
        )
        assert [r.name for r in rows] == [names[i] for i in order]
        for r, raw, adj in zip(rows[:-1], p, holm(p.tolist()), strict=True):
            assert r.vs_next is not None and math.isclose(r.vs_next.p, raw, rel_tol=1e-9)
            assert r.vs_next.significant == (adj < 0.05)


def _false_claim(order: np.ndarray, sig: np.ndarray, means: np.ndarray) -> bool:
    """Whether some adjacent claim (A ranked above B, significant) is false: A's true
    harm is not below B's."""
    a, b = means[order[:-1]], means[order[1:]]
    return bool(np.any(sig & (a >= b)))


def synthetic(reps: int, rng: np.random.Generator) -> list[dict]:
    rows = []
    for design in ("complete null", "partial null (twins)"):
        for k in KS:
            if design == "complete null":
                means = np.zeros(k)
            else:
                means = np.repeat(10.0 * np.arange((k + 1) // 2), 2)[:k]
            for n in (3, 4):
                for shape in SHAPES:
                    hits = {"raw": 0, "protected LSD": 0, "Holm adjacent": 0}
                    for _ in range(reps):
                        x = _grid(rng, means, n, shape)
                        order, p = _adjacent(x)
                        raw = p < 0.05
                        gate = omnibus_p(x) < 0.05
                        adj = np.array(holm(p.tolist())) < 0.05
                        hits["raw"] += _false_claim(order, raw, means)
                        hits["protected LSD"] += _false_claim(order, raw & gate, means)
                        hits["Holm adjacent"] += _false_claim(order, adj, means)
                    rows.append(
                        {
                            "design": design,
                            "vuts": k,
                            "seeds": n,
                            "errors": shape,
                            "reps": reps,
                            **{f"fwer {key}": round(v / reps, 4) for key, v in hits.items()},
                        }
                    )
                    print(rows[-1], flush=True)
    return rows


def _study_name(path: Path) -> str:
    return str(path.relative_to(PROJECT_ROOT / "results"))


def committed_ladders() -> list[dict]:
    from sumo_ayss.analysis.crossplay import rank_crossplay
    from sumo_ayss.analysis.crossplay_scoring import score_crossplay
    from sumo_ayss.analysis.harm import harm_scale_of
    from sumo_ayss.run_folder.crossplay import read_crossplay_table
    from sumo_ayss.run_folder.record import read_run
    from sumo_ayss.run_folder.study import read_ranking_csv

    rows = []
    for path in sorted((PROJECT_ROOT / "results").rglob("crossplay.csv")):
        run = next(iter(sorted(path.parent.glob("*/seed_*"))), None)
        if run is None:
            continue
        scale = harm_scale_of(read_run(run))
        if scale is None:
            continue
        m = score_crossplay(read_crossplay_table(path).columns, scale)
        ranked, _ = rank_crossplay(m)
        raw = [r.vs_next.p for r in ranked[:-1] if r.vs_next is not None]
        rows.append(
            {
                "study": _study_name(path.parent.parent),
                "case": path.parent.name,
                "seeds": ranked[0].n_seeds,
                "adjacent pairs": len(raw),
                "significant raw": sum(p < 0.05 for p in raw),
                "significant Holm": sum(bool(r.significant_vs_next) for r in ranked[:-1]),
                "raw p": " ".join(f"{p:.3g}" for p in raw),
            }
        )
        print(rows[-1], flush=True)
    for path in sorted((PROJECT_ROOT / "results" / "verdict_budget").glob("*/ranking.csv")):
        table = read_ranking_csv(path)
        for case in sorted({r["case"] for r in table}):
            own = [r for r in table if r["case"] == case and r["mode"] == "crossplay"]
            raw = [float(r["p_vs_next"]) for r in own if r["p_vs_next"] != ""]
            rows.append(
                {
                    "study": _study_name(path.parent),
                    "case": case,
                    "seeds": int(own[0]["n_seeds"]),
                    "adjacent pairs": len(raw),
                    "significant raw": sum(p < 0.05 for p in raw),
                    "significant Holm": sum(q < 0.05 for q in holm(raw)),
                    "raw p": " ".join(f"{p:.3g}" for p in raw),
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
    p.add_argument("--reps", type=int, default=2000)
    p.add_argument("--out", type=Path, default=PROJECT_ROOT / "results" / "family_wise")
    args = p.parse_args()
    rng = np.random.default_rng(20261128)
    _check_against_product(rng)
    args.out.mkdir(parents=True, exist_ok=True)
    _write(args.out / "committed_ladders.csv", committed_ladders())
    _write(args.out / "synthetic.csv", synthetic(args.reps, rng))


if __name__ == "__main__":
    main()
