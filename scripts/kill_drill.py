"""Kill drill (issue 38): SIGKILL a whole ``rank`` pipeline at random instants of a tiny study;
after each kill the rerun must finish and equal the undisturbed run.

    .venv/bin/python scripts/kill_drill.py [--kills 20] [--seed 0] [--work DIR] [--n-outcome 30]

The study: car-following, VUTs pi1 and pi2, training seeds 0 and 1, the tiny learner (600
transitions per run), ``n_outcome`` outcome and cross-play scenarios. First one undisturbed
``python -m sumo_ayss.rank`` run (its wall time T). Then, per kill, a fresh output folder: the
same command in its own process group, SIGKILL to the whole group (the pipeline and every
worker, as a power cut would) at an instant drawn uniformly from (0, T), then the same command
again to the end. Compared byte for byte with the undisturbed run: ``ranking.csv``, every
case's ``crossplay.csv`` and every run's ``outcome.csv``. One line per kill (the instant, what
the killed run had finished: jobs evaluated, cross-play cells kept, whether the rerun equals
the undisturbed run), and a JSON summary in ``<work>/kill_drill.json``.

Exit status 0 when every rerun finished and equalled the undisturbed run.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parent.parent
TINY_AGENT = {
    "feature_net_arch": [32],
    "value_net_arch": [32],
    "advantage_net_arch": [32],
    "learning_starts": 100,
    "buffer_size": 5000,
    "learning_rate": 1e-3,
}


def write_study(folder: Path, n_outcome: int) -> Path:
    """The tiny study's experiment and pipeline YAML in ``folder``; returns the pipeline's."""
    folder.mkdir(parents=True, exist_ok=True)
    exp = yaml.safe_load((ROOT / "configs" / "car_following.yaml").read_text())
    exp["agent"] = TINY_AGENT
    exp["train"].update(n_eval_scenarios=5)
    (folder / "cf.yaml").write_text(yaml.safe_dump(exp))
    pipe = {
        "grid": {"cases": ["car_following"], "vuts": ["pi1", "pi2"], "seeds": [0, 1]},
        "experiments": {"car_following": "cf.yaml"},
        "out": "runs",
        "total_timesteps": 600,
        "eval_every": 300,
        "evaluate": {"n_outcome": n_outcome, "n_ayss": 2000},
        "workers": 2,
    }
    path = folder / "pipe.yaml"
    path.write_text(yaml.safe_dump(pipe))
    return path


def command(pipe: Path) -> list[str]:
    return [sys.executable, "-m", "sumo_ayss.rank", str(pipe), "--no-live"]


def outputs(out: Path) -> dict[str, bytes]:
    """The files compared: ranking.csv, each crossplay.csv, each outcome.csv (by path)."""
    files = [out / "ranking.csv", *out.glob("*/crossplay.csv"), *out.glob("*/*/seed_*/outcome.csv")]
    return {str(p.relative_to(out)): p.read_bytes() for p in sorted(files) if p.is_file()}


def state(out: Path) -> str:
    """What a killed run had finished."""
    evaluated = len(list(out.glob("*/*/seed_*/evaluate.done.json")))
    cells = len(list(out.glob("*/crossplay.partial/cell_*.csv")))
    tables = len(list(out.glob("*/crossplay.csv")))
    return f"{evaluated} jobs evaluated, {cells} cross-play cells kept, {tables} tables"


def run(pipe: Path, log: Path) -> tuple[int, float]:
    t0 = time.perf_counter()
    with log.open("ab") as f:
        code = subprocess.run(command(pipe), cwd=ROOT, stdout=f, stderr=f, timeout=1800).returncode
    return code, time.perf_counter() - t0


def kill_at(pipe: Path, instant_s: float, log: Path) -> bool:
    """Start the command in its own process group and SIGKILL the group after
    ``instant_s``; False when it ended before that."""
    with log.open("ab") as f:
        proc = subprocess.Popen(command(pipe), cwd=ROOT, stdout=f, stderr=f, start_new_session=True)
        try:
            proc.wait(timeout=instant_s)
            return False
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
            return True


def kill_after_cells(pipe: Path, cells: int, log: Path) -> bool:
    """Start the command in its own process group and SIGKILL the group as soon as the
    cross-play stage has kept ``cells`` finished cells; False when it ended before."""
    partial = pipe.parent / "runs" / "car_following" / "crossplay.partial"
    with log.open("ab") as f:
        proc = subprocess.Popen(command(pipe), cwd=ROOT, stdout=f, stderr=f, start_new_session=True)
        while proc.poll() is None:
            if len(list(partial.glob("cell_*.csv"))) >= cells:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()
                return True
            time.sleep(0.02)
        return False


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--kills", type=int, default=20)
    p.add_argument("--seed", type=int, default=0, help="seed of the kill instants")
    p.add_argument("--work", type=Path, default=Path("/tmp/kill_drill"))
    p.add_argument("--n-outcome", type=int, default=30)
    p.add_argument(
        "--cell-kills",
        type=int,
        default=0,
        help="more kills, each once cross-play has kept a random number (1..7) of its 8 cells",
    )
    args = p.parse_args(argv)
    if args.work.exists():
        shutil.rmtree(args.work)
    ref_pipe = write_study(args.work / "undisturbed", args.n_outcome)
    code, wall = run(ref_pipe, args.work / "undisturbed" / "log.txt")
    if code != 0:
        print(f"undisturbed run failed (exit {code}); see {args.work}/undisturbed/log.txt")
        return 1
    expected = outputs(ref_pipe.parent / "runs")
    print(f"undisturbed: {wall:.1f} s, {len(expected)} files compared", flush=True)
    rng = random.Random(args.seed)
    results = []
    for k in range(args.kills + args.cell_kills):
        folder = args.work / f"kill_{k:02d}"
        pipe = write_study(folder, args.n_outcome)
        log = folder / "log.txt"
        if k < args.kills:
            instant = rng.uniform(0.0, wall)
            killed = kill_at(pipe, instant, log)
        else:  # a kill in the middle of a cross-play case
            instant = float(rng.randint(1, 7))
            killed = kill_after_cells(pipe, int(instant), log)
        at_kill = state(folder / "runs")
        rerun_log = folder / "rerun.txt"
        code, rerun_s = run(pipe, rerun_log)
        kept = rerun_log.read_text(errors="replace").count("kept from an earlier run")
        got = outputs(folder / "runs")
        differ = sorted(n for n in expected.keys() | got.keys() if expected.get(n) != got.get(n))
        ok = code == 0 and not differ
        results.append(
            {
                "kill": k,
                "instant_s": round(instant, 2) if k < args.kills else None,
                "after_cells": int(instant) if k >= args.kills else None,
                "killed": killed,
                "at_kill": at_kill,
                "rerun_exit": code,
                "rerun_s": round(rerun_s, 1),
                "rerun_kept_cells": kept,
                "differ": differ,
                "ok": ok,
            }
        )
        when = f"at {instant:6.1f} s" if k < args.kills else f"after {int(instant)} cells"
        verdict = "equal" if not differ else "DIFFERS: " + ", ".join(differ)
        print(
            f"kill {k:2d} {when} ({at_kill}): rerun exit {code} in "
            f"{rerun_s:.1f} s ({kept} cells kept), {verdict}",
            flush=True,
        )
        if ok:
            shutil.rmtree(folder)  # keep only the failures for inspection
    summary = {"undisturbed_s": round(wall, 1), "files": sorted(expected), "kills": results}
    (args.work / "kill_drill.json").write_text(json.dumps(summary, indent=2) + "\n")
    n_ok = sum(r["ok"] for r in results)
    print(f"{n_ok} of {len(results)} kills: rerun equal to the undisturbed run")
    return 0 if n_ok == len(results) else 1


if __name__ == "__main__":
    sys.exit(main())
