"""CPU-seconds of adding one VUT to a finished study, against running the grown study anew.

    python benchmarks/grow_leaderboard.py [--out runs/bench/grow_leaderboard] \
        [--ladder configs/ladders/time_headway.yaml] [--add tau20] [--budget verdict] \
        [-- RANK_ARGS]     # e.g. -- --total-timesteps 600 --eval-every 300 (a smoke run)

Three ``python -m sumo_ayss.rank`` runs of the ladder (every case, the named budget and its
seeds), each a child process whose whole process tree's CPU-seconds are measured
(``RUSAGE_CHILDREN``: the grid's workers, cross-play, discriminability, the analysis and the
report):

1. ``base``: the ladder without ``--add`` in ``<out>/grown`` (the finished study);
2. ``add``: the whole ladder in the same ``<out>/grown`` (the leaderboard grows in place:
   only the added VUT's runs train, cross-play drives only the new cells);
3. ``scratch``: the whole ladder in ``<out>/scratch`` (the same study from nothing).

Prints each step's CPU-seconds, wall seconds and how many runs it trained, and the ratio
``add / scratch`` (issue 36's target: at most 0.35). A finished step keeps its measurement
in ``<out>/<step>.bench.json`` and is not run again (``--force`` measures anew).
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

from sumo_ayss.util.atomic import atomic_write_text
from sumo_ayss.util.paths import PROJECT_ROOT


def _children_cpu_s() -> float:
    u = resource.getrusage(resource.RUSAGE_CHILDREN)
    return u.ru_utime + u.ru_stime


def write_config(ladder: Path, budget: str, vuts: list[str], out: Path, path: Path) -> Path:
    """The ladder YAML with ``vuts``, the budget named (its seeds and training budget) and
    ``out`` as its output folder."""
    cfg = yaml.safe_load(ladder.read_text())
    cfg["grid"]["vuts"] = vuts
    cfg["grid"].pop("seeds", None)  # the budget's seeds (and adaptive seeding)
    cfg["budget"] = budget
    for key in ("total_timesteps", "eval_every"):
        cfg.pop(key, None)
    cfg.get("evaluate", {}).pop("n_outcome", None)
    cfg["expected_order"] = [v for v in cfg.get("expected_order", []) if v in vuts]
    experiments = cfg.get("experiments")
    if experiments:  # paths in the ladder resolve against its folder
        cfg["experiments"] = {c: str((ladder.parent / p).resolve()) for c, p in experiments.items()}
    cfg["out"] = str(out.resolve())
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(path, yaml.safe_dump(cfg, sort_keys=False))
    return path


def measure(config: Path, force: bool, extra: list[str]) -> dict:
    """Runs ``rank`` on ``config`` (with ``extra`` arguments) unless measured already;
    returns the measurement."""
    record = config.with_suffix(".bench.json")
    if record.is_file() and not force:
        return json.loads(record.read_text())
    cpu0, t0 = _children_cpu_s(), time.perf_counter()
    cmd = [sys.executable, "-m", "sumo_ayss.rank", str(config), "--no-live", *extra]
    proc = subprocess.run(
        cmd, cwd=PROJECT_ROOT, env=os.environ.copy(), check=False, capture_output=True, text=True
    )
    log = proc.stdout + proc.stderr
    config.with_suffix(".log").write_text(log)
    result = {
        "cpu_s": round(_children_cpu_s() - cpu0, 1),
        "wall_s": round(time.perf_counter() - t0, 1),
        "runs_trained": log.count("(train done"),
        "runs_skipped": log.count("(train skipped"),
        "returncode": proc.returncode,
    }
    if proc.returncode == 0:
        atomic_write_text(record, json.dumps(result, indent=2) + "\n")
    return result


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, default=PROJECT_ROOT / "runs/bench/grow_leaderboard")
    p.add_argument(
        "--ladder", type=Path, default=PROJECT_ROOT / "configs/ladders/time_headway.yaml"
    )
    p.add_argument("--add", default=None, help="the VUT added last (default: the ladder's last)")
    p.add_argument("--budget", default="verdict")
    p.add_argument("--force", action="store_true", help="measure again what was measured")
    p.add_argument("rank_args", nargs="*", help="after --: passed to every rank run")
    a = p.parse_args()
    vuts = list(yaml.safe_load(a.ladder.read_text())["grid"]["vuts"])
    added = a.add or vuts[-1]
    base = [v for v in vuts if v != added]
    steps = {
        "base": (base, a.out / "grown"),
        "add": (vuts, a.out / "grown"),
        "scratch": (vuts, a.out / "scratch"),
    }
    rows = {}
    for step, (names, out) in steps.items():
        config = write_config(a.ladder, a.budget, names, out, a.out / f"{step}.yaml")
        m = measure(config, a.force, a.rank_args)
        if m["returncode"] != 0:
            sys.exit(
                f"rank failed on {config} (exit {m['returncode']}; {config.with_suffix('.log')})"
            )
        rows[step] = m
        print(
            f"| {step} | {', '.join(names)} | {m['runs_trained']} | {m['runs_skipped']} | "
            f"{m['cpu_s']:.0f} | {m['wall_s']:.0f} |",
            flush=True,
        )
    ratio = rows["add"]["cpu_s"] / rows["scratch"]["cpu_s"]
    print(
        f"adding {added} to a finished {len(base)}-VUT study / the {len(vuts)}-VUT study from "
        f"scratch: {rows['add']['cpu_s']:.0f} / {rows['scratch']['cpu_s']:.0f} CPU-s = {ratio:.3f}"
    )


if __name__ == "__main__":
    main()
