"""The verdict's learning curve: how the cross-play ranking of a ladder depends on the budget.

    python scripts/verdict_curve.py cells OUT STUDY [STUDY ...] [--budget-step 10000]
    python scripts/verdict_curve.py curve OUT                      # rank per budget
    python scripts/verdict_curve.py frontier OUT                   # cheapest protocols
    python scripts/verdict_curve.py early-stop OUT [--rules 2:1 ...]  # stopped runs' verdict

``cells``: for every run of the studies (one ladder; several studies of it are pooled, e.g.
run A and run B with other seeds) and every budget B = 10k, 20k, ... (``--budget-step``) up
to the run's last candidate, the SPCP the run would have selected with a training budget of
B transitions is the best of its candidates up to B (the run's selection criterion on its
``eval.csv``). Every distinct such candidate is driven against every VUT of the case exactly
as the cross-play stage drives an opponent
(:func:`sumo_ayss.scenarios.crossplay.run_crossplay`: a fresh single env, SUMO seed = the
opponent's seed, the outcome stage's ``n`` scenarios of its seed). One row per episode goes
to ``OUT/<case>/cells.csv`` (appended cell by cell, so a killed run continues where it
stopped), with the CPU-seconds of each cell. At each run's final SPCP the episodes of its
own VUT are checked against the run's ``outcome.csv`` (the cross-play diagonal check): this
script drives the vehicle the product drives.

``curve``: for each budget B, each number of training seeds per VUT S (every subset of S of
the pooled seeds) and each number of scenarios n (the first n), the cross-play ranking
(:func:`sumo_ayss.analysis.crossplay.rank_crossplay`, the product's default: harm, paired
t-test over seed blocks) against the known order: Kendall's τ, whether the ends differ
significantly in the right direction (the product's rule: Holm over the adjacent pairs, the
ends claimed through the chain between them; ``curve.csv`` keeps the raw ends p beside the
adjusted one), significant adjacent pairs. Subsets: all of them, or ``--max-subsets`` drawn
at random (seeded) where there are more. Writes
``OUT/<case>/curve.csv`` (one row per (B, S, n, seed subset)) and ``OUT/summary.csv`` (per
(case, B, S, n): share of subsets with τ = 1, with significant ends, with both; mean τ; the
CPU-seconds of that protocol for the ladder).

CPU-seconds of a protocol (V VUTs, S seeds, budget B, n scenarios): V·S jobs trained to B
(seconds per 10k transitions with candidate evaluation: the median gap between consecutive
candidates in the runs' ``job.log``, where each job had one core), their outcome stages
(V·S·n episodes) and cross-play (V·V·S·n episodes), episodes at the CPU-seconds per episode
measured here. The AYSS stage (not needed by the cross-play verdict) is left out.

``frontier``: from ``summary.csv`` (``n`` = 200 scenarios), every (budget, seeds per VUT)
point with its share in each case and the CPU-seconds of both cases, as a share of the paper
protocol's (3 seeds × 100k, the same model); the cheapest points reaching 100 % and 95 % in
every case. Writes ``OUT/frontier.csv``.

``early-stop``: the verdict when every run stops where the early-stopping rule
(:mod:`sumo_ayss.analysis.early_stop`, on the run's ``eval.csv``) stops it, for each
``patience:margin_se`` of ``--rules``, beside every run trained to its last candidate
(``patience`` "off"). Writes ``OUT/early_stop.csv``.

Pass ``--expected`` to override the study's known order (``order_check.json``).
"""

from __future__ import annotations

import argparse
import csv
import gzip
import itertools
import json
import math
import re
import statistics
import sys
import time
from collections import defaultdict
from collections.abc import Sequence
from datetime import datetime
from pathlib import Path
from typing import IO

import numpy as np

from sumo_ayss.analysis.crossplay import crossplay_matrix, rank_crossplay
from sumo_ayss.analysis.harm import episode_harm, harm_scale_of
from sumo_ayss.analysis.seeds import kendall_tau
from sumo_ayss.run_folder import RunFolder, RunRecord, StudyFolder, read_eval_table, read_run
from sumo_ayss.run_folder.study import read_order_check
from sumo_ayss.util.atomic import atomic_write_text
from sumo_ayss.util.paths import PROJECT_ROOT, portable_path

CELL_COLUMNS = (
    "vut",
    "opponent_vut",
    "opponent_seed",
    "opponent_step",
    "scenario",
    "collided",
    "near_miss_pay",
    "episode_return",
    "n_steps",
    "final_headway_m",
    "vut_mean_speed_mps",
    "cell_cpu_s",
)
BUDGET_STEP = 10_000


# ----------------------------------------------------------------------------- cells


def spcp_steps(run: RunRecord, budget_step: int = BUDGET_STEP) -> dict[int, int]:
    """Budget B -> step of the candidate the run selects among those at steps <= B."""
    from sumo_ayss.training.selection import select_spcp

    criterion = run.experiment.train.selection
    rows = read_eval_table(run.folder.eval_table)
    last = int(max(r["step"] for r in rows))
    out = {}
    for budget in range(budget_step, last + 1, budget_step):
        prefix = [r for r in rows if r["step"] <= budget]
        out[budget] = select_spcp(prefix, criterion).step
    return out


def _run_dirs(studies: Sequence[Path], case: str) -> list[Path]:
    return sorted(d for s in studies for d in (s / case).glob("*/seed_*") if d.is_dir())


def _done_cells(path: Path) -> set[tuple[str, str, int, int]]:
    if not path.is_file():
        return set()
    with path.open() as f:
        return {
            (r["vut"], r["opponent_vut"], int(r["opponent_seed"]), int(r["opponent_step"]))
            for r in csv.DictReader(f)
        }


def cells(out: Path, studies: Sequence[Path], budget_step: int = BUDGET_STEP) -> None:
    """Roll out every (VUT, candidate SPCP) cell not yet in ``OUT/<case>/cells.csv``
    (budgets every ``budget_step`` transitions)."""
    from sumo_ayss.agents.weights import load_greedy_policy
    from sumo_ayss.envs import make_env
    from sumo_ayss.envs.odd import scenario_set
    from sumo_ayss.scenarios.rollout import run_episodes

    cases = sorted({p.name for s in studies for p in s.iterdir() if list(p.glob("*/seed_*"))})
    for case in cases:
        runs = [read_run(d) for d in _run_dirs(studies, case)]
        outcome = runs[0].outcome_record
        if outcome is None:
            sys.exit(f"{runs[0].folder.outcome_json}: missing or unreadable")
        n, seed = int(outcome.settings["n"]), int(outcome.settings["seed"])
        envs = {}
        for r in runs:
            envs.setdefault(r.experiment.env.vut, r.experiment.env)
        folder = out / case
        folder.mkdir(parents=True, exist_ok=True)
        path = folder / "cells.csv"
        done = _done_cells(path)
        meta = {
            "studies": [portable_path(s) for s in studies],
            "n": n,
            "seed": seed,
            "runs": {},
        }
        scale = harm_scale_of(runs[0])
        if scale is not None:  # so that the cells read back without their run folders
            meta["max_episode_pay"] = scale.max_episode_pay
        todo = []
        for r in runs:
            steps = spcp_steps(r, budget_step)
            meta["runs"][f"{r.experiment.env.vut}/{r.config_seed}"] = {
                "run_dir": portable_path(r.path),
                "spcp_by_budget": {str(b): s for b, s in steps.items()},
                "sec_per_10k": _sec_per_10k(r.folder),
            }
            for step in sorted(set(steps.values())):
                todo += [
                    (v, r, step)
                    for v in envs
                    if (v, r.experiment.env.vut, r.config_seed, step) not in done
                ]
        # the smallest budgets first: an interrupted run leaves whole budgets behind it
        todo.sort(key=lambda t: (t[2], t[1].experiment.env.vut, t[1].config_seed, t[0]))
        atomic_write_text(folder / "cells.json", json.dumps(meta, indent=2) + "\n")
        print(f"{case}: {len(done)} cells done, {len(todo)} to run", flush=True)
        new = not path.is_file()
        policies: dict[tuple[str, int, int], object] = {}
        with path.open("a", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=CELL_COLUMNS, lineterminator="\n")
            if new:
                writer.writeheader()
            for k, (vut, run, step) in enumerate(todo):
                c0, t0 = time.process_time(), time.perf_counter()
                env = make_env(envs[vut], sumo_seed=run.config_seed)
                try:
                    key = (run.experiment.env.vut, run.config_seed, step)
                    if key not in policies:
                        ckpt = run.folder.candidate_model(step)
                        policies = {
                            key: load_greedy_policy(
                                ckpt,
                                run.experiment.agent,
                                env.observation_space,  # type: ignore[arg-type]
                                env.action_space,  # type: ignore[arg-type]
                            )
                        }
                    scenarios = scenario_set(envs[vut], n, seed)
                    episodes = run_episodes(env, policies[key], scenarios)  # type: ignore[arg-type]
                finally:
                    env.close()
                cpu = time.process_time() - c0
                for j, e in enumerate(episodes):
                    writer.writerow(
                        {
                            "vut": vut,
                            "opponent_vut": run.experiment.env.vut,
                            "opponent_seed": run.config_seed,
                            "opponent_step": step,
                            "scenario": j,
                            "collided": int(e.collided),
                            "near_miss_pay": repr(e.near_miss_pay),
                            "episode_return": repr(e.episode_return),
                            "n_steps": e.n_steps,
                            "final_headway_m": repr(e.final_headway_m),
                            "vut_mean_speed_mps": repr(e.vut_mean_speed_mps),
                            "cell_cpu_s": f"{cpu:.4f}",
                        }
                    )
                f.flush()
                spcp_step = run.spcp.step if run.spcp is not None else None
                if vut == run.experiment.env.vut and step == spcp_step:
                    _check_diagonal(run, episodes)
                    print(f"{run.path}: own SPCP reproduces outcome.csv", flush=True)
                print(
                    f"{case} [{k + 1}/{len(todo)}] {vut} vs {run.experiment.env.vut}/"
                    f"{run.config_seed}"
                    f"@{step}: {sum(e.collided for e in episodes)}/{n} crashes "
                    f"({time.perf_counter() - t0:.2f} s)",
                    flush=True,
                )


def _check_diagonal(run: RunRecord, episodes: Sequence[object]) -> None:
    """The run's own SPCP against its own VUT must reproduce ``outcome.csv`` exactly."""
    table = run.outcome_table
    if table is None:
        sys.exit(f"{run.folder.outcome_csv}: missing or unreadable")
    rows = zip(table["episode_return"].tolist(), table["collided"].tolist(), strict=True)
    for (episode_return, collided), e in zip(rows, episodes, strict=True):
        same = episode_return == e.episode_return and bool(collided) == bool(e.collided)  # type: ignore[attr-defined]
        if not same:
            sys.exit(f"{run.path}: a rollout differs from outcome.csv: not the product's vehicle")


_STAMP = re.compile(r"^(\S+ \S+) \S+ INFO: candidate (\d+):")


def _sec_per_10k(folder: RunFolder) -> float:
    """Median seconds between consecutive candidates in ``job.log`` (per 10k transitions)."""
    stamps = []
    for line in folder.job_log.read_text().splitlines():
        m = _STAMP.match(line)
        if m:
            t = datetime.strptime(m.group(1), "%Y-%m-%d %H:%M:%S,%f").timestamp()
            stamps.append((int(m.group(2)), t))
    gaps = [
        (t1 - t0) * BUDGET_STEP / (s1 - s0)
        for (s0, t0), (s1, t1) in itertools.pairwise(stamps)
        if s1 > s0 and t1 > t0
    ]
    return statistics.median(gaps) if gaps else math.nan


# ----------------------------------------------------------------------------- curve


RATE_FROM: Path | None = None
"""``--rate-from``: a curve folder whose ``<case>/cells.json`` gives the seconds per 10k
transitions of the CPU model instead of this study's ``job.log`` (whose wall-clock gaps
measure the machine's load as much as the job when other work shares the cores)."""


def _has_cells(folder: Path) -> bool:
    return (folder / "cells.csv").is_file() or (folder / "cells.csv.gz").is_file()


def _open_cells(folder: Path) -> IO[str]:
    """``cells.csv``, or the committed ``cells.csv.gz`` when it is absent (``gunzip -k`` it
    before ``cells`` appends to it)."""
    if (folder / "cells.csv").is_file():
        return (folder / "cells.csv").open()
    return gzip.open(folder / "cells.csv.gz", "rt")


def _read_meta(folder: Path) -> dict:
    meta = json.loads((folder / "cells.json").read_text())
    if RATE_FROM is not None:
        ref = json.loads((RATE_FROM / folder.name / "cells.json").read_text())["runs"]
        rate = float(np.nanmedian([r["sec_per_10k"] for r in ref.values()]))
        for r in meta["runs"].values():
            r["sec_per_10k"] = rate
    return meta


def _load_cells(folder: Path) -> tuple[dict, dict, float]:
    """(vut, opp_vut, opp_seed, step) -> (harm, collided) arrays; meta; CPU-s per episode."""
    meta = _read_meta(folder)
    max_pay = meta.get("max_episode_pay")
    if max_pay is None:  # cells written before the scale was stored: ask a run folder
        first = read_run(PROJECT_ROOT / next(iter(meta["runs"].values()))["run_dir"])
        scale = harm_scale_of(first)
        if scale is None:
            sys.exit(f"{first.path}: no harm scale ({'; '.join(first.problems)})")
        max_pay = scale.max_episode_pay
    data: dict = defaultdict(list)
    cpu: dict = {}
    with _open_cells(folder) as f:
        for r in csv.DictReader(f):
            key = (r["vut"], r["opponent_vut"], int(r["opponent_seed"]), int(r["opponent_step"]))
            data[key].append((int(r["scenario"]), float(r["near_miss_pay"]), int(r["collided"])))
            cpu[key] = float(r["cell_cpu_s"])
    cells_out = {}
    for key, rows in data.items():
        rows.sort()
        pay = np.array([p for _, p, _ in rows])
        crash = np.array([c for _, _, c in rows], dtype=bool)
        cells_out[key] = (episode_harm(pay, crash, float(max_pay)), crash)
    n = meta["n"]
    per_episode = float(np.median([c / n for c in cpu.values()]))
    return cells_out, meta, per_episode


def curve(
    out: Path, expected: Sequence[str] | None, max_subsets: int, max_budget: int | None = None
) -> None:
    summary = []
    for folder in sorted(p for p in out.iterdir() if _has_cells(p)):
        case = folder.name
        data, meta, cpu_episode = _load_cells(folder)
        runs = meta["runs"]
        vuts = sorted({k.split("/")[0] for k in runs})
        order = list(expected) if expected else _expected(meta)
        seeds_of = {
            v: sorted(int(k.split("/")[1]) for k in runs if k.split("/")[0] == v) for v in vuts
        }
        seeds = seeds_of[vuts[0]]
        budgets = sorted({int(b) for r in runs.values() for b in r["spcp_by_budget"]})
        budgets = [b for b in budgets if max_budget is None or b <= max_budget]
        sec10k = float(np.nanmedian([r["sec_per_10k"] for r in runs.values()]))
        n_max = meta["n"]
        ns = [x for x in (50, 100, 200) if x <= n_max] or [n_max]
        rows = []
        for budget in budgets:
            for s_count in range(2, len(seeds) + 1):
                subsets = _subsets(seeds, s_count, max_subsets)
                for n in ns:
                    cpu = _protocol_cpu(len(vuts), s_count, budget, n, sec10k, cpu_episode)
                    results = []
                    for subset in subsets:
                        res = _rank(data, runs, vuts, subset, budget, n, order)
                        results.append(res)
                        rows.append(
                            {
                                "budget": budget,
                                "seeds_per_vut": s_count,
                                "n": n,
                                "subset": " ".join(map(str, subset)),
                                **res,
                                "cpu_s": round(cpu),
                            }
                        )
                    ok = [r["tau"] == 1.0 for r in results]
                    ends = [r["ends_significant"] for r in results]
                    summary.append(
                        {
                            "case": case,
                            "budget": budget,
                            "seeds_per_vut": s_count,
                            "n": n,
                            "subsets": len(results),
                            "share_tau1": round(float(np.mean(ok)), 3),
                            "share_ends": round(float(np.mean(ends)), 3),
                            "share_both": round(
                                float(np.mean([a and b for a, b in zip(ok, ends, strict=True)])), 3
                            ),
                            "mean_tau": round(float(np.mean([r["tau"] for r in results])), 3),
                            "median_ends_p": float(np.median([r["ends_p"] for r in results])),
                            "median_ends_p_holm": float(
                                np.median([r["ends_p_holm"] for r in results])
                            ),
                            "mean_sig_adjacent": round(
                                float(np.mean([r["significant_adjacent"] for r in results])), 2
                            ),
                            "cpu_s": round(cpu),
                        }
                    )
        _write_csv(folder / "curve.csv", rows)
        print(
            f"{case}: {len(rows)} rankings; {cpu_episode * 1000:.2f} ms CPU per episode, "
            f"{sec10k:.1f} s per 10k transitions"
        )
    _write_csv(out / "summary.csv", summary)
    print(f"wrote {out / 'summary.csv'}")


def _subsets(seeds: Sequence[int], size: int, most: int) -> list[tuple[int, ...]]:
    """Every ``size``-subset of ``seeds``, or ``most`` of them drawn at random (seeded, the
    same every run) when there are more: a fair sample, not the lexicographically first."""
    every = list(itertools.combinations(seeds, size))
    if len(every) <= most:
        return every
    rng = np.random.default_rng(size)
    return [every[i] for i in sorted(rng.choice(len(every), most, replace=False))]


def _expected(meta: dict) -> list[str]:
    study = StudyFolder(PROJECT_ROOT / meta["studies"][0])
    return list(read_order_check(study.order_check_json).expected)


EPISODE_S: float | None = None
"""``--episode-ms`` / 1000: the CPU model's seconds per episode instead of the cells' own
(whose CPU time grows with the machine's load)."""


def _protocol_cpu(v: int, s: int, budget: int, n: int, sec10k: float, cpu_episode: float) -> float:
    cpu_episode = cpu_episode if EPISODE_S is None else EPISODE_S
    train = v * s * sec10k * budget / BUDGET_STEP
    episodes = v * s * n + v * v * s * n
    return train + episodes * cpu_episode


def _rank(data, runs, vuts, subset, budget, n, order) -> dict:
    """The cross-play ranking of ``subset``'s opponents at ``budget`` (one budget for every
    run, or a mapping ``"vut/seed"`` -> budget: each run's own, e.g. where it stopped)."""
    cols: dict[str, list] = {k: [] for k in ("vut", "ov", "os", "harm", "crash")}
    for opp in vuts:
        for s in subset:
            b = budget[f"{opp}/{s}"] if isinstance(budget, dict) else budget
            step = runs[f"{opp}/{s}"]["spcp_by_budget"].get(str(b))
            if step is None:
                step = max(runs[f"{opp}/{s}"]["spcp_by_budget"].values())
            for v in vuts:
                harm, crash = data[(v, opp, s, step)]
                cols["vut"] += [v] * n
                cols["ov"] += [opp] * n
                cols["os"] += [s] * n
                cols["harm"] += harm[:n].tolist()
                cols["crash"] += crash[:n].tolist()
    m = crossplay_matrix(cols["vut"], cols["ov"], cols["os"], cols["harm"], cols["crash"])
    ranked, pairs = rank_crossplay(m)
    got = [r.name for r in ranked]
    ends = next(c for c in pairs if {c.name_a, c.name_b} == {order[0], order[-1]})
    return {
        "order": " > ".join(got),
        "tau": kendall_tau(got, order),
        # ``significant``: the family-adjusted p (Holm over the adjacent pairs, the ends
        # claimed through the chain between them), as the product decides it
        "ends_significant": bool(ends.significant and ends.name_a == order[0]),
        "ends_p": ends.p,
        "ends_p_holm": ends.p_decision,
        "significant_adjacent": sum(bool(r.significant_vs_next) for r in ranked[:-1]),
    }


def _write_csv(path: Path, rows: list[dict]) -> None:
    import io

    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=list(rows[0]), lineterminator="\n")
    w.writeheader()
    w.writerows(rows)
    atomic_write_text(path, buf.getvalue())


# ----------------------------------------------------------------------------- frontier


def frontier(out: Path, n: int) -> None:
    """The cheapest protocols (budget, seeds per VUT) whose share of seed subsets with τ = 1
    and Holm-significant ends reaches 100 % and 95 %, per case and for both cases of the
    ladder at once (one protocol for both; points with at least 8 seed subsets), from
    ``OUT/summary.csv`` at ``n`` scenarios;
    CPU-seconds also as a share of the paper protocol's (3 seeds × 100k, same model)."""
    with (out / "summary.csv").open() as f:
        rows = [r for r in csv.DictReader(f) if int(r["n"]) == n]
    meta = {p.name: _load_meta(p) for p in out.iterdir() if (p / "cells.json").is_file()}
    paper = {case: _paper_cpu(m, n) for case, m in meta.items()}
    points: dict[tuple[int, int], dict[str, dict]] = defaultdict(dict)
    for r in rows:
        points[(int(r["budget"]), int(r["seeds_per_vut"]))][r["case"]] = r
    cases = sorted({r["case"] for r in rows})
    table = []
    for (budget, seeds), by_case in sorted(points.items()):
        if set(by_case) != set(cases):
            continue
        cpu = sum(float(by_case[c]["cpu_s"]) for c in cases)
        table.append(
            {
                "budget": budget,
                "seeds_per_vut": seeds,
                **{f"share_{c}": float(by_case[c]["share_both"]) for c in cases},
                **{f"subsets_{c}": int(by_case[c]["subsets"]) for c in cases},
                "share_min": min(float(by_case[c]["share_both"]) for c in cases),
                "cpu_s": round(cpu),
                "of_paper": round(cpu / sum(paper.values()), 3),
            }
        )
    _write_csv(out / "frontier.csv", table)
    for level in (1.0, 0.95):
        # a share over a handful of subsets (all 8 of 8 seeds is one) says little
        ok = [
            t
            for t in table
            if t["share_min"] >= level and min(t[f"subsets_{c}"] for c in cases) >= 8
        ]
        best = min(ok, key=lambda t: t["cpu_s"]) if ok else None
        print(f"cheapest point with >= {level:.0%} in every case: {best}")
    print(f"paper protocol (model): { ({c: round(v) for c, v in paper.items()}) } CPU-s")
    print(f"wrote {out / 'frontier.csv'}")


def _load_meta(folder: Path) -> dict:
    meta = _read_meta(folder)
    with _open_cells(folder) as f:
        cpu = {}
        for r in csv.DictReader(f):
            cpu[(r["vut"], r["opponent_vut"], r["opponent_seed"], r["opponent_step"])] = float(
                r["cell_cpu_s"]
            )
    meta["cpu_episode"] = float(np.median([c / meta["n"] for c in cpu.values()]))
    return meta


def _paper_cpu(meta: dict, n: int) -> float:
    runs = meta["runs"]
    vuts = {k.split("/")[0] for k in runs}
    sec10k = float(np.nanmedian([r["sec_per_10k"] for r in runs.values()]))
    return _protocol_cpu(len(vuts), 3, 100_000, n, sec10k, meta["cpu_episode"])


def holm_bound(outs: Sequence[Path], dest: Path, n: int) -> None:
    """From ``curve.csv`` files written before the ranking used Holm (raw ends significance
    and the count of raw-significant adjacent pairs, no adjacent p): per ladder, case,
    budget and seeds per VUT, the share of subsets with τ = 1 and raw-significant ends, and
    an **upper bound** on the share with Holm-significant ends (those need every adjacent
    pair significant on its own too: τ = 1 and all adjacent pairs raw-significant). Writes
    ``dest``."""
    table = []
    for out in outs:
        for path in sorted(out.glob("*/curve.csv")):
            groups: dict[tuple[int, int], list[dict]] = defaultdict(list)
            with path.open() as f:
                for r in csv.DictReader(f):
                    if int(r["n"]) == n:
                        groups[(int(r["budget"]), int(r["seeds_per_vut"]))].append(r)
            for (budget, seeds), rows in sorted(groups.items()):
                k = len(rows[0]["order"].split(" > "))
                raw = [float(r["tau"]) == 1.0 and r["ends_significant"] == "True" for r in rows]
                bound = [
                    float(r["tau"]) == 1.0 and int(r["significant_adjacent"]) == k - 1 for r in rows
                ]
                table.append(
                    {
                        "ladder": out.name,
                        "case": path.parent.name,
                        "budget": budget,
                        "seeds_per_vut": seeds,
                        "subsets": len(rows),
                        "share_both_raw": round(float(np.mean(raw)), 3),
                        "share_both_holm_at_most": round(float(np.mean(bound)), 3),
                        "cpu_s": int(rows[0]["cpu_s"]),
                    }
                )
    _write_csv(dest, table)
    print(f"wrote {dest}")


# ----------------------------------------------------------------------------- early stop


def early_stop(
    out: Path,
    expected: Sequence[str] | None,
    max_subsets: int,
    rules: Sequence[tuple[int, float]],
    n: int,
    max_budget: int | None = None,
) -> None:
    """The verdict with every run stopped by the early-stopping rule
    (:func:`sumo_ayss.analysis.early_stop.stop_index` on the run's ``eval.csv``), each
    ``(patience, margin_se)`` of ``rules``, against every run trained to its last candidate:
    per case and seeds per VUT, the share of seed subsets with τ = 1 and Holm-significant
    ends, the transitions trained and the CPU-seconds (model). ``OUT/early_stop.csv``."""
    from sumo_ayss.analysis.early_stop import evaluation_se, stop_index
    from sumo_ayss.training.selection import CRITERIA

    table = []
    for folder in sorted(p for p in out.iterdir() if _has_cells(p)):
        case = folder.name
        data, meta, cpu_episode = _load_cells(folder)
        runs = meta["runs"]
        vuts = sorted({k.split("/")[0] for k in runs})
        order = list(expected) if expected else _expected(meta)
        seeds = sorted(int(k.split("/")[1]) for k in runs if k.startswith(f"{vuts[0]}/"))
        sec10k = float(np.nanmedian([r["sec_per_10k"] for r in runs.values()]))
        cap = max(int(b) for r in runs.values() for b in r["spcp_by_budget"])
        cap = cap if max_budget is None else min(cap, max_budget)
        curves = {}
        for key, r in runs.items():
            run = read_run(PROJECT_ROOT / r["run_dir"])
            score = CRITERIA[run.experiment.train.selection]
            rows = read_eval_table(run.folder.eval_table)
            curves[key] = (
                [int(x["step"]) for x in rows],
                [score(x) for x in rows],
                [evaluation_se(x) for x in rows],
            )
        for patience, margin in [(0, 0.0), *rules]:
            stop_at = {}
            for key, (steps, scores, ses) in curves.items():
                j = None if patience == 0 else stop_index(scores, ses, patience, margin)
                stop_at[key] = cap if j is None else min(steps[j], cap)
            for s_count in range(2, len(seeds) + 1):
                results, trained = [], []
                for subset in _subsets(seeds, s_count, max_subsets):
                    results.append(_rank(data, runs, vuts, subset, stop_at, n, order))
                    trained.append(
                        float(np.mean([stop_at[f"{v}/{s}"] for v in vuts for s in subset]))
                    )
                mean_budget = float(np.mean(trained))
                table.append(
                    {
                        "case": case,
                        "patience": patience or "off",
                        "margin_se": margin if patience else "",
                        "seeds_per_vut": s_count,
                        "subsets": len(results),
                        "share_tau1": round(float(np.mean([r["tau"] == 1 for r in results])), 3),
                        "share_both": round(
                            float(
                                np.mean([r["tau"] == 1 and r["ends_significant"] for r in results])
                            ),
                            3,
                        ),
                        "median_ends_p_holm": float(np.median([r["ends_p_holm"] for r in results])),
                        "runs_stopped": sum(v < cap for v in stop_at.values()),
                        "runs": len(stop_at),
                        "mean_transitions": round(mean_budget),
                        "cpu_s": round(
                            _protocol_cpu(len(vuts), s_count, mean_budget, n, sec10k, cpu_episode)
                        ),
                    }
                )
        print(f"{case}: early-stop verdicts for {len(rules)} rules")
    _write_csv(out / "early_stop.csv", table)
    print(f"wrote {out / 'early_stop.csv'}")


def figure(outs: Sequence[Path], dest: Path, seeds: Sequence[int], n: int) -> None:
    """One figure per case, against the budget (top axis: the CPU-seconds of a 3-VUT
    ladder's protocol at the first seed count): the share of seed subsets whose ranking has
    τ = 1 and significant ends, and the median ends p; one colour per ladder, one line style
    per number of seeds per VUT, ``n`` scenarios."""
    import matplotlib as mpl

    mpl.use("Agg")
    from matplotlib.figure import Figure

    by_case: dict[str, dict[tuple[str, int], list[dict]]] = defaultdict(dict)
    for out in outs:
        with (out / "summary.csv").open() as f:
            for r in csv.DictReader(f):
                s = int(r["seeds_per_vut"])
                if s in seeds and int(r["n"]) == n:
                    by_case[r["case"]].setdefault((out.name, s), []).append(r)
    styles = ["o-", "s--", "^:"]
    for case, lines in sorted(by_case.items()):
        fig = Figure(figsize=(8.0, 6.6), layout="constrained")
        top, bottom = fig.subplots(2, 1, sharex=True)
        ladders = sorted({ladder for ladder, _ in lines})
        for (ladder, s), rows in sorted(lines.items()):
            colour = f"C{ladders.index(ladder)}"
            style = styles[list(seeds).index(s) % len(styles)]
            b = [int(r["budget"]) / 1000 for r in rows]
            label = f"{ladder}, {s} seeds"
            top.plot(b, [float(r["share_both"]) for r in rows], style, color=colour, label=label)
            p = [max(float(r["median_ends_p"]), 1e-5) for r in rows]
            bottom.plot(b, p, style, color=colour, label=label)
        ref = next(rows for (_, s), rows in sorted(lines.items()) if s == seeds[0])
        xs = np.array([int(r["budget"]) / 1000 for r in ref])
        ys = np.array([float(r["cpu_s"]) for r in ref])
        slope, icpt = np.polyfit(xs, ys, 1)
        axis = top.secondary_xaxis(
            "top",
            functions=(
                lambda x, a=icpt, b=slope: a + b * x,
                lambda y, a=icpt, b=slope: (y - a) / b,
            ),
        )
        axis.set_xlabel(f"CPU-seconds of the whole protocol ({ref[0]['seeds_per_vut']} seeds)")
        top.set_ylabel("share of seed subsets with\nτ = 1 and significant ends")
        top.set_ylim(-0.05, 1.05)
        top.grid(alpha=0.3)
        top.legend(fontsize=7, loc="lower right", ncol=2)
        top.set_title(f"{case}: the cross-play verdict against the training budget ({n} scenarios)")
        bottom.set_yscale("log")
        bottom.axhline(0.05, color="k", lw=0.8, ls=":")
        bottom.set_ylabel("ends p, median over subsets")
        bottom.set_xlabel("training budget per run [thousand transitions]")
        bottom.grid(alpha=0.3)
        path = dest / f"verdict_curve_{case}.png"
        fig.savefig(path, dpi=100)
        print(f"wrote {path}")


def main(argv: Sequence[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="cmd", required=True)
    c = sub.add_parser("cells")
    c.add_argument("out", type=Path)
    c.add_argument("studies", type=Path, nargs="+")
    c.add_argument("--budget-step", type=int, default=BUDGET_STEP)
    k = sub.add_parser("curve")
    k.add_argument("out", type=Path)
    k.add_argument("--expected", nargs="+", default=None)
    k.add_argument("--max-subsets", type=int, default=20)
    fr = sub.add_parser("frontier")
    fr.add_argument("out", type=Path)
    fr.add_argument("--n", type=int, default=200)
    hb = sub.add_parser("holm-bound")
    hb.add_argument("dest", type=Path)
    hb.add_argument("outs", type=Path, nargs="+")
    hb.add_argument("--n", type=int, default=200)
    es = sub.add_parser("early-stop")
    es.add_argument("out", type=Path)
    es.add_argument("--expected", nargs="+", default=None)
    es.add_argument("--max-subsets", type=int, default=20)
    es.add_argument("--n", type=int, default=200)
    es.add_argument(
        "--rules",
        nargs="+",
        default=["1:1", "2:0", "2:1", "2:2", "3:1"],
        help="patience:margin_se pairs",
    )
    g = sub.add_parser("figure")
    g.add_argument("dest", type=Path)
    g.add_argument("outs", type=Path, nargs="+")
    g.add_argument("--seeds", type=int, nargs="+", default=[3, 4])
    g.add_argument("--n", type=int, default=200)
    for sp in (k, es):
        sp.add_argument(
            "--max-budget",
            type=int,
            default=None,
            help="only budgets up to this (cells of larger ones may be missing); early-stop: "
            "the runs' cap",
        )
    for sp in (k, fr, es):
        sp.add_argument(
            "--episode-ms",
            type=float,
            default=None,
            help="CPU milliseconds per episode of the CPU model (default: the cells' own)",
        )
        sp.add_argument(
            "--rate-from",
            type=Path,
            default=None,
            help="a curve folder whose <case>/cells.json gives the seconds per 10k "
            "transitions"
            " of the CPU model (default: this study's job.log)",
        )
    a = p.parse_args(argv)
    global RATE_FROM, EPISODE_S
    RATE_FROM = getattr(a, "rate_from", None)
    ms = getattr(a, "episode_ms", None)
    EPISODE_S = None if ms is None else ms / 1000
    if a.cmd == "figure":
        figure(a.outs, a.dest, a.seeds, a.n)
    elif a.cmd == "cells":
        cells(a.out, a.studies, a.budget_step)
    elif a.cmd == "holm-bound":
        holm_bound(a.outs, a.dest, a.n)
    elif a.cmd == "frontier":
        frontier(a.out, a.n)
    elif a.cmd == "early-stop":
        rules = [(int(r.split(":")[0]), float(r.split(":")[1])) for r in a.rules]
        early_stop(a.out, a.expected, a.max_subsets, rules, a.n, a.max_budget)
    else:
        curve(a.out, a.expected, a.max_subsets, a.max_budget)


if __name__ == "__main__":
    main()
