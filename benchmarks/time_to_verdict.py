"""CPU-seconds per correct ranking: a 4-VUT ladder through ``rank`` under two budgets.

    python benchmarks/time_to_verdict.py [--out runs/bench/time_to_verdict] \
        [--ladder configs/ladders/time_headway.yaml] [--budgets paper verdict]

For each named budget (:data:`sumo_ayss.config.budget.BUDGETS`) and each case of the ladder,
writes ``<out>/<budget>/<case>.yaml`` (the ladder with only that case and the budget's
settings written out: training transitions, candidate cadence, outcome scenarios, seeds)
and runs ``python -m sumo_ayss.rank`` on it as a child process, measuring the CPU-seconds of
its whole process tree (``RUSAGE_CHILDREN``: the grid's worker processes, cross-play,
analysis and report) and its wall time. The ranking is correct when Kendall's τ against the
ladder's known order is 1 and the ends differ significantly in the right direction
(``order_check.json``, the product's cross-play verdict).

Prints, per budget and case: τ, the ends' p, significant adjacent pairs, CPU-seconds and
wall seconds; then per budget the CPU-seconds per correct ranking, and their ratio.

A finished (budget, case) keeps its measurement in ``<out>/<budget>/<case>.bench.json`` and
is not run again (delete it, or pass ``--force``, to measure anew); ``rank`` itself resumes
a killed grid, but then the CPU-seconds of that (budget, case) cover only the part run after
the restart, and the line says so.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import yaml

from sumo_ayss.config.budget import BUDGETS
from sumo_ayss.run_folder import OrderCheck, StudyFolder, read_adaptive
from sumo_ayss.run_folder.study import read_order_check
from sumo_ayss.util.atomic import atomic_write_text
from sumo_ayss.util.paths import PROJECT_ROOT


def _children_cpu_s() -> float:
    u = resource.getrusage(resource.RUSAGE_CHILDREN)
    return u.ru_utime + u.ru_stime


def write_config(ladder: Path, budget: str, case: str, out: Path) -> Path:
    """The ladder YAML with one case and the budget named explicitly (its training budget,
    candidate cadence and seeds are the budget's)."""
    cfg = yaml.safe_load(ladder.read_text())
    cfg["grid"]["cases"] = [case]
    cfg["grid"].pop("seeds", None)  # the budget's seeds
    cfg["budget"] = budget
    for key in ("total_timesteps", "eval_every"):
        cfg.pop(key, None)
    cfg.get("evaluate", {}).pop("n_outcome", None)
    experiments = cfg.get("experiments")
    if experiments:  # paths in the ladder resolve against its folder
        cfg["experiments"] = {c: str((ladder.parent / p).resolve()) for c, p in experiments.items()}
    cfg["out"] = str((out / budget / case).resolve())
    path = out / budget / f"{case}.yaml"
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(path, yaml.safe_dump(cfg, sort_keys=False))
    return path


def measure(config: Path, run_out: Path, force: bool) -> dict:
    """Runs ``rank`` on ``config`` unless measured already; returns the measurement."""
    record = config.with_suffix(".bench.json")
    if record.is_file() and not force:
        return json.loads(record.read_text())
    fresh = not run_out.exists()
    cpu0, t0 = _children_cpu_s(), time.perf_counter()
    cmd = [sys.executable, "-m", "sumo_ayss.rank", str(config), "--no-live"]
    proc = subprocess.run(cmd, cwd=PROJECT_ROOT, env=os.environ.copy(), check=False)
    result = {
        "cpu_s": round(_children_cpu_s() - cpu0, 1),
        "wall_s": round(time.perf_counter() - t0, 1),
        "complete": fresh,
        "returncode": proc.returncode,
    }
    if proc.returncode == 0:
        atomic_write_text(record, json.dumps(result, indent=2) + "\n")
    return result


def verdict(run_out: Path, case: str) -> OrderCheck:
    """The case's cross-play order check (``order_check.json``)."""
    checks = read_order_check(StudyFolder(run_out).order_check_json).cases
    return next(x for x in checks if x.case == case and x.mode == "crossplay")


def is_correct(check: OrderCheck) -> bool:
    """The ranking is the known order and its ends differ significantly."""
    return check.tau == 1.0 and check.ends_significant


def seeds_of(run_out: Path, case: str) -> int:
    """Seeds per VUT the case ended with: adaptive seeding's last look, else the grid's."""
    adaptive = StudyFolder(run_out).case(case).adaptive_json
    if adaptive.is_file():
        return read_adaptive(adaptive).looks[-1].n_seeds
    return len(json.loads(StudyFolder(run_out).pipeline_json.read_text())["grid"]["seeds"])


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, default=PROJECT_ROOT / "runs/bench/time_to_verdict")
    p.add_argument(
        "--ladder", type=Path, default=PROJECT_ROOT / "configs/ladders/time_headway.yaml"
    )
    p.add_argument("--budgets", nargs="+", default=["paper", "verdict"], choices=sorted(BUDGETS))
    p.add_argument("--cases", nargs="+", default=None, help="default: the ladder's cases")
    p.add_argument("--force", action="store_true", help="measure again what was measured")
    a = p.parse_args()
    cases = a.cases or yaml.safe_load(a.ladder.read_text())["grid"]["cases"]
    lines = []
    per_budget: dict[str, tuple[float, int, bool]] = {}
    for budget in a.budgets:
        total, n_correct, complete = 0.0, 0, True
        for case in cases:
            config = write_config(a.ladder, budget, case, a.out)
            m = measure(config, a.out / budget / case, a.force)
            if m["returncode"] != 0:
                sys.exit(f"rank failed on {config} (exit {m['returncode']})")
            v = verdict(a.out / budget / case, case)
            total += m["cpu_s"]
            n_correct += is_correct(v)
            complete &= m["complete"]
            seeds = seeds_of(a.out / budget / case, case)
            lines.append(
                f"| {budget} | {case} | {seeds} | {v.tau:.2f} | {v.ends_p:.3g} | "
                f"{v.significant_adjacent} of {v.adjacent} | "
                f"{'yes' if is_correct(v) else 'no'} | {m['cpu_s']:.0f} | {m['wall_s']:.0f} |"
                + ("" if m["complete"] else " resumed: CPU-s partial |")
            )
        per_budget[budget] = (total, n_correct, complete)
    b = BUDGETS
    print(f"ladder {a.ladder.name}, cases {', '.join(cases)}")
    for name in a.budgets:
        print(f"  {name}: {b[name].describe()}")
    print(
        "| budget | case | seeds per VUT | Kendall τ | ends p | significant adjacent | correct | "
        "CPU-s | wall s |"
    )
    print("|---|---|---:|---:|---:|---|---|---:|---:|")
    print("\n".join(lines))
    print()
    print("| budget | correct rankings | CPU-s | CPU-s per correct ranking |")
    print("|---|---:|---:|---:|")
    per_correct = {}
    for name, (total, correct, complete) in per_budget.items():
        per_correct[name] = total / correct if correct else float("inf")
        note = "" if complete else " (partial: resumed)"
        print(
            f"| {name} | {correct} of {len(cases)} | {total:.0f}{note} | {per_correct[name]:.0f} |"
        )
    if len(per_correct) == 2:
        x, y = per_correct
        print(f"\nCPU-s per correct ranking, {y} / {x}: {per_correct[y] / per_correct[x]:.3f}")


if __name__ == "__main__":
    main()
