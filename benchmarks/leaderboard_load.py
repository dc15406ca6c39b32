"""A leaderboard under load: K VUTs × seeds × both cases through ``rank``, per-stage cost.

    python benchmarks/leaderboard_load.py [--out runs/load32] [--seeds 1 2 3] [--k 32]

Writes ``<out>/load.yaml``: K VUTs, two variants of every SUMO car-following model in the
catalog (SUMO's defaults with minGap 2.5 m; minGap 5 m, tau 1.5 s, accel 2.5 m/s²,
speedDev 0), at a tiny budget (3,000 transitions, a candidate every 1,500, 20 outcome
scenarios, 2,000 AYSS draws). Runs ``python -m sumo_ayss.rank <out>/load.yaml`` as a child
process, samples the resident memory of its whole process tree every 0.5 s from /proc, and
assigns each sample to the stage the child's log is in:

* ``grid``: until "grid finished" (every job: train, evaluate);
* ``cross-play``: while the log reports cross-play cells;
* ``analysis + report``: until "report written" (discriminability, analyses, the report);
* ``ranking``: until the child exits (rank's tables and the printed leaderboard).

Prints per stage its wall time and peak memory (sum of RSS over the tree, MiB), the
cross-play cells and their rate, and the child's exit status.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import threading
import time
from pathlib import Path

import yaml

from sumo_ayss.vuts.vtype_params import MODEL_PARAMS

STAGES = ("grid", "cross-play", "analysis + report", "ranking")


def write_config(out: Path, k: int, seeds: list[int]) -> Path:
    vuts: dict[str, dict] = {}
    for model in sorted(MODEL_PARAMS):
        extra = {"lanesCount": 2} if model == "CC" else {}
        vuts[f"{model.lower()}_a"] = {
            "model": model,
            "params": {"length": 5.0, "minGap": 2.5, **extra},
            "description": f"{model}, SUMO defaults, minGap 2.5 m",
        }
        vuts[f"{model.lower()}_b"] = {
            "model": model,
            "params": {"length": 5.0, "minGap": 5.0, "tau": 1.5, "accel": 2.5, "speedDev": 0.0}
            | extra,
            "description": f"{model}, minGap 5 m, tau 1.5 s, accel 2.5, speedDev 0",
        }
    names = list(vuts)[:k]
    cfg = {
        "grid": {"cases": ["car_following", "cut_in"], "vuts": names, "seeds": seeds},
        "out": "out",
        "total_timesteps": 3000,
        "eval_every": 1500,
        "evaluate": {"n_outcome": 20, "n_ayss": 2000},
        "vuts": {n: vuts[n] for n in names},
    }
    out.mkdir(parents=True, exist_ok=True)
    path = out / "load.yaml"
    path.write_text(yaml.safe_dump(cfg, sort_keys=False))
    return path


def tree_rss_mib(root: int) -> float:
    """Resident memory of ``root`` and all its descendants [MiB], from /proc."""
    children: dict[int, list[int]] = {}
    rss: dict[int, int] = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            stat = Path(f"/proc/{entry}/stat").read_text()
            status = Path(f"/proc/{entry}/status").read_text()
        except OSError:
            continue
        ppid = int(stat.rpartition(")")[2].split()[1])
        children.setdefault(ppid, []).append(int(entry))
        m = re.search(r"VmRSS:\s+(\d+) kB", status)
        rss[int(entry)] = int(m.group(1)) if m else 0
    total, todo = 0, [root]
    while todo:
        pid = todo.pop()
        total += rss.get(pid, 0)
        todo += children.get(pid, [])
    return total / 1024


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, default=Path("runs/load32"))
    p.add_argument("--k", type=int, default=32)
    p.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    args = p.parse_args()
    config = write_config(args.out, args.k, args.seeds)
    cmd = [sys.executable, "-m", "sumo_ayss.rank", str(config), "--no-live"]
    log = (args.out / "rank.log").open("w")
    t0 = time.monotonic()
    child = subprocess.Popen(cmd, stdout=log, stderr=subprocess.PIPE, text=True)
    events: dict[str, float] = {}
    cells = {"n": 0}

    def read_log() -> None:
        assert child.stderr is not None
        for line in child.stderr:
            log.write(line)
            now = time.monotonic()
            if "grid finished" in line:
                events["grid"] = now
            elif "cross-play" in line and " vs SPCP " in line:
                cells["n"] += 1
                events["cross-play"] = now
            elif "report written" in line:
                events["analysis + report"] = now

    reader = threading.Thread(target=read_log, daemon=True)
    reader.start()
    samples: list[tuple[float, float]] = []
    while child.poll() is None:
        samples.append((time.monotonic(), tree_rss_mib(child.pid)))
        time.sleep(0.5)
    reader.join(timeout=5)
    events["ranking"] = time.monotonic()
    log.close()
    bounds, last = {}, t0
    for s in STAGES:  # a stage ends at its last event; one without events takes no time
        stop = events.get(s, last)
        bounds[s] = (last, max(stop, last))
        last = bounds[s][1]
    print(f"{args.k} VUTs x {len(args.seeds)} seeds x 2 cases; rank exit status {child.returncode}")
    print("| stage | wall [s] | peak memory, process tree [MiB] |")
    print("|---|---:|---:|")
    for s in STAGES:
        a, b = bounds[s]
        peak = max((m for t, m in samples if a <= t <= b), default=0.0)
        print(f"| {s} | {b - a:.0f} | {peak:.0f} |")
    a, b = bounds["cross-play"]
    if cells["n"]:
        print(
            f"cross-play cells (VUT x opponent, 20 episodes each): {cells['n']}, "
            f"{cells['n'] / max(b - a, 1e-9):.1f} cells/s"
        )


if __name__ == "__main__":
    main()
