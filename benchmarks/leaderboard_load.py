"""A leaderboard under load: K VUTs × seeds × both cases through ``rank``, per-stage cost.

    python benchmarks/leaderboard_load.py [--out runs/load32] [--k 32] [--vuts models] \
        [--budget tiny] [--seeds 1 2 3]
    python benchmarks/leaderboard_load.py --out runs/load12 --k 12 --vuts varied --budget verdict
    python benchmarks/leaderboard_load.py --out runs/load12 --analyse   # tables of a finished run
    python benchmarks/leaderboard_load.py --row-bytes   # heap per cross-play row held in memory

Writes ``<out>/load.yaml`` and runs ``python -m sumo_ayss.rank <out>/load.yaml --no-live`` on
it as a child process.

VUT sets (``--vuts``, the first K of the set):

* ``models``: two variants of every SUMO car-following model in the catalog (SUMO's defaults
  with minGap 2.5 m; minGap 5 m, tau 1.5 s, accel 2.5 m/s², speedDev 0): 32 (session 5).
* ``varied``: 12 realistic VUTs of different kinds: the paper's pi1 and pi2, the ends of the
  committed braking, time-headway and ACC time-gap ladders, the careful human driver with a
  1.5 s reaction, and SUMO's Krauss (its defaults), W99 and ACC models. None has an
  ``actionStepLength`` other than the step: one such vType switches every vehicle of the
  simulation to ballistic integration (docs/ranking.md, "step method").

Budgets (``--budget``): ``tiny`` (3,000 transitions, a candidate every 1,500, 20 outcome
scenarios, 2,000 AYSS draws, ``--seeds``: session 5's 32-VUT run) or ``verdict`` (the named
budget as ``rank`` applies it by default: 20,000 transitions, 4 seeds per VUT and adaptive
seeding up to 6, the shipped experiment configs with their follower).

While the child runs, every 0.5 s, its whole process tree is read from /proc: resident memory
(sum of RSS) and CPU-seconds (utime + stime + cutime + cstime of every live process of the
tree: a reaped child's time moves into its parent's cutime/cstime, so the sum only grows).
Each stderr line of the child is stamped with its time. Samples go to ``<out>/samples.csv``,
stamped log lines to ``<out>/events.tsv``; both are then cut into stages by the log lines
(:func:`segments`): ``setup`` until the first job, ``grid`` (jobs: train, evaluate),
``cross-play``, ``adaptive look``, ``discriminability``, ``report``, ``ranking`` (after the
report, rank's tables and leaderboard). Adaptive seeding's extra jobs and cross-play come as
further ``grid`` and ``cross-play`` segments. Per segment and per stage: wall, CPU-seconds,
peak memory and plateau memory (the median of the stage's samples), jobs, cross-play cells;
written to ``<out>/stages.csv``, ``<out>/segments.csv`` and ``<out>/load.json`` and printed.
The total CPU-seconds are also measured with ``RUSAGE_CHILDREN`` when the child exits.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import re
import resource
import statistics
import subprocess
import sys
import threading
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import yaml

from sumo_ayss.vuts.vtype_params import MODEL_PARAMS

STAGES = (
    "setup",
    "grid",
    "cross-play",
    "adaptive look",
    "discriminability",
    "report",
    "ranking",
)
LADDERS = Path(__file__).resolve().parents[1] / "configs" / "ladders"
#: ``varied``: (ladder file or None for a built-in / catalog VUT, VUT name).
VARIED = (
    (None, "pi1"),
    (None, "pi2"),
    ("braking.yaml", "d45"),
    ("braking.yaml", "d9"),
    ("time_headway.yaml", "tau05"),
    ("time_headway.yaml", "tau20"),
    ("acc_time_gap.yaml", "tg06"),
    ("acc_time_gap.yaml", "tg20"),
    ("careful_human.yaml", "human150"),
    (None, "krauss_a"),
    (None, "w99_b"),
    (None, "acc_b"),
)


def model_vuts() -> dict[str, dict]:
    """Two variants of every SUMO car-following model of the catalog."""
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
    return vuts


def varied_vuts() -> dict[str, dict | None]:
    """The ``varied`` set; None: a built-in VUT (``pi1``, ``pi2``)."""
    models = model_vuts()
    vuts: dict[str, dict | None] = {}
    for ladder, name in VARIED:
        if ladder is not None:
            vuts[name] = yaml.safe_load((LADDERS / ladder).read_text())["vuts"][name]
        else:
            vuts[name] = models.get(name)
    for name, spec in vuts.items():
        assert spec is None or "actionStepLength" not in spec.get("params", {}), name
    return vuts


def write_config(
    out: Path, k: int, seeds: list[int], budget: str = "tiny", kind: str = "models"
) -> Path:
    vuts = model_vuts() if kind == "models" else varied_vuts()
    names = list(vuts)[:k]
    cfg: dict = {"grid": {"cases": ["car_following", "cut_in"], "vuts": names}, "out": "out"}
    if budget == "tiny":
        cfg["grid"]["seeds"] = seeds
        cfg |= {"total_timesteps": 3000, "eval_every": 1500}
        cfg["evaluate"] = {"n_outcome": 20, "n_ayss": 2000}
    else:  # the named budget chooses seeds (adaptive), transitions and draws, as rank does
        cfg["budget"] = budget
    cfg["vuts"] = {n: vuts[n] for n in names if vuts[n] is not None}
    out.mkdir(parents=True, exist_ok=True)
    path = out / "load.yaml"
    path.write_text(yaml.safe_dump(cfg, sort_keys=False, allow_unicode=True))
    return path


@dataclass(frozen=True)
class Sample:
    t_s: float  # since the child started
    rss_mib: float  # resident memory of the process tree
    cpu_s: float  # utime + stime + cutime + cstime over the live tree
    n_procs: int


def read_tree(root: int, proc: Path = Path("/proc")) -> tuple[float, float, int]:
    """(RSS [MiB], CPU [s], processes) of ``root`` and its descendants, from ``proc``.

    CPU: utime + stime + cutime + cstime of every live process of the tree (fields 14–17 of
    ``/proc/<pid>/stat``, clock ticks); RSS: field 24 (pages).
    """
    tick = os.sysconf("SC_CLK_TCK")
    page = os.sysconf("SC_PAGE_SIZE")
    children: dict[int, list[int]] = {}
    info: dict[int, tuple[int, int]] = {}
    for entry in os.listdir(proc):
        if not entry.isdigit():
            continue
        try:
            stat = (proc / entry / "stat").read_text()
        except OSError:
            continue
        fields = stat.rpartition(")")[2].split()  # fields[0] is field 3 (state)
        ppid = int(fields[1])
        cpu = sum(int(x) for x in fields[11:15])
        children.setdefault(ppid, []).append(int(entry))
        info[int(entry)] = (cpu, int(fields[21]))
    cpu_ticks = rss_pages = n = 0
    todo = [root]
    while todo:
        pid = todo.pop()
        if pid in info:
            cpu_ticks += info[pid][0]
            rss_pages += info[pid][1]
            n += 1
        todo += children.get(pid, [])
    return rss_pages * page / 2**20, cpu_ticks / tick, n


#: (stage, pattern of a log line that starts it); the first match wins.
MARKERS = (
    ("grid", re.compile(r"\d+ jobs on \d+ worker processes")),
    ("cross-play", re.compile(r"cross-play (car_following|cut_in|\w+):")),
    ("adaptive look", re.compile(r"adaptive seeding, \w+: (settled|not settled) at")),
    ("discriminability", re.compile(r"discriminability of \w+:")),
    ("report", re.compile(r"report: analysing")),
    ("ranking", re.compile(r"report written to")),
)
JOBS = re.compile(r"(\d+) jobs on \d+ worker processes")
ADDED = re.compile(r"adaptive seeding, (\w+): adding seed (\d+)")
LOOK = re.compile(r"adaptive seeding, (\w+): (settled|not settled) at (\d+) seeds")
CELL = " vs SPCP "


@dataclass
class Segment:
    stage: str
    start_s: float
    stop_s: float
    cpu_s: float = 0.0
    peak_mib: float = 0.0
    plateau_mib: float = 0.0
    n_samples: int = 0
    jobs: int = 0
    cells: int = 0

    @property
    def wall_s(self) -> float:
        return self.stop_s - self.start_s


def segments(
    events: list[tuple[float, str]],
    samples: list[Sample],
    end_s: float,
    total_cpu_s: float | None = None,
) -> list[Segment]:
    """Cut the run into stage segments at the log lines of :data:`MARKERS`.

    A segment runs from its marker line to the next line that starts another stage (or to
    ``end_s``). Its CPU is the growth of the tree's CPU counter from the last sample at or
    before its start to the last sample at or before its stop (the last segment: to
    ``total_cpu_s`` when given, the child's ``RUSAGE_CHILDREN``); its memory: the peak and
    the median (plateau) of the samples inside it.
    """
    segs = [Segment("setup", 0.0, end_s)]
    for t, line in events:
        stage = next((s for s, pat in MARKERS if pat.search(line)), None)
        if stage is not None and stage != segs[-1].stage:
            segs[-1].stop_s = t
            segs.append(Segment(stage, t, end_s))
        m = JOBS.search(line)
        if m:
            segs[-1].jobs += int(m.group(1))
        if CELL in line and "cross-play" in line:
            segs[-1].cells += 1

    def cpu_at(t: float) -> float:
        before = [s.cpu_s for s in samples if s.t_s <= t]
        return max(before) if before else 0.0

    for i, seg in enumerate(segs):
        inside = [s.rss_mib for s in samples if seg.start_s <= s.t_s < seg.stop_s]
        seg.n_samples = len(inside)
        seg.peak_mib = max(inside, default=0.0)
        seg.plateau_mib = statistics.median(inside) if inside else 0.0
        last = i == len(segs) - 1
        stop_cpu = total_cpu_s if last and total_cpu_s is not None else cpu_at(seg.stop_s)
        seg.cpu_s = max(stop_cpu - cpu_at(seg.start_s), 0.0)
    return segs


def by_stage(segs: list[Segment], samples: list[Sample]) -> list[dict]:
    """One row per stage: the sums of its segments; peak and plateau over all its samples."""
    rows = []
    for stage in STAGES:
        mine = [s for s in segs if s.stage == stage]
        if not mine:
            continue
        inside = [x.rss_mib for x in samples if any(s.start_s <= x.t_s < s.stop_s for s in mine)]
        rows.append(
            {
                "stage": stage,
                "segments": len(mine),
                "wall_s": round(sum(s.wall_s for s in mine), 1),
                "cpu_s": round(sum(s.cpu_s for s in mine), 1),
                "peak_mib": round(max(inside, default=0.0)),
                "plateau_mib": round(statistics.median(inside)) if inside else 0,
                "jobs": sum(s.jobs for s in mine),
                "cells": sum(s.cells for s in mine),
            }
        )
    return rows


def adaptive_lines(events: list[tuple[float, str]]) -> dict[str, list]:
    """Per case: the looks (seeds, verdict) and the seeds the adaptive rule added."""
    out: dict[str, list] = {}
    for _, line in events:
        if m := LOOK.search(line):
            out.setdefault(m.group(1), []).append(f"{m.group(2)} at {m.group(3)}")
        elif m := ADDED.search(line):
            out.setdefault(m.group(1), []).append(f"added seed {m.group(2)}")
    return out


#: The child's command as recorded (no machine paths in committed results).
COMMAND = "python -m sumo_ayss.rank load.yaml --no-live"


def read_run(out: Path) -> tuple[list[tuple[float, str]], list[Sample], dict]:
    events = []
    with (out / "events.tsv").open() as f:
        for row in f:
            t, _, line = row.rstrip("\n").partition("\t")
            events.append((float(t), line))
    with (out / "samples.csv").open() as f:
        samples = [Sample(*(float(v) for v in r[:3]), int(r[3])) for r in list(csv.reader(f))[1:]]
    if (out / "run.json").is_file():
        meta = json.loads((out / "run.json").read_text())
        if meta.get("command") != COMMAND:  # an older run's record named the interpreter's path
            meta["command"] = COMMAND
            (out / "run.json").write_text(json.dumps(meta, indent=1) + "\n")
    else:  # still running (or killed): the stages so far, the last one cut at the last sample
        cfg = yaml.safe_load((out / "load.yaml").read_text())
        budget = cfg.get("budget", "tiny")
        meta = {"k": len(cfg["grid"]["vuts"]), "vuts": "?", "budget": budget, "returncode": None}
    return events, samples, meta


def analyse(out: Path) -> dict:
    """Stage tables of a finished (or interrupted) run in ``out``: written and printed."""
    events, samples, meta = read_run(out)
    end_s = meta.get("wall_s") or (samples[-1].t_s if samples else 0.0)
    segs = segments(events, samples, end_s, meta.get("cpu_s"))
    stages = by_stage(segs, samples)
    result = {
        **meta,
        "peak_mib": round(max((s.rss_mib for s in samples), default=0.0)),
        "stages": stages,
        "segments": [asdict(s) | {"wall_s": round(s.wall_s, 1)} for s in segs],
        "adaptive": adaptive_lines(events),
    }
    (out / "load.json").write_text(json.dumps(result, indent=1) + "\n")
    for name, rows in (("stages.csv", stages), ("segments.csv", result["segments"])):
        with (out / name).open("w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
    print(
        f"{meta['k']} VUTs ({meta['vuts']}), budget {meta['budget']}, 2 cases; rank exit status "
        f"{meta.get('returncode')}; wall {end_s:.0f} s, CPU {meta.get('cpu_s')} s"
    )
    print("| stage | segments | wall [s] | CPU [s] | peak [MiB] | plateau [MiB] | jobs | cells |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for r in stages:
        print(
            f"| {r['stage']} | {r['segments']} | {r['wall_s']:.0f} | {r['cpu_s']:.0f} | "
            f"{r['peak_mib']} | {r['plateau_mib']} | {r['jobs']} | {r['cells']} |"
        )
    for case, looks in result["adaptive"].items():
        print(f"adaptive seeding, {case}: {'; '.join(looks)}")
    return result


def row_bytes(n: int = 20_000) -> dict[str, float]:
    """Python heap per cross-play row [bytes], measured with tracemalloc on ``n`` rows shaped
    as :func:`sumo_ayss.scenarios.crossplay.run_crossplay` holds them (a dict per episode,
    every column of the schema) and then as the table built from them."""
    import random
    import tracemalloc

    from sumo_ayss.records.table import table_from_rows
    from sumo_ayss.run_folder import CROSSPLAY_SCHEMA

    names = [c.name for c in CROSSPLAY_SCHEMA.columns]
    tracemalloc.start()
    rows = []
    for i in range(n):
        row: dict[str, object] = {c: random.random() for c in names}
        row |= {"vut": "pi1", "opponent_vut": "pi2", "opponent_seed": 3, "scenario": i % 200}
        row |= {"collided": i % 7 == 0, "n_steps": 25}
        rows.append(row)
    held = tracemalloc.get_traced_memory()[0]
    table_from_rows(CROSSPLAY_SCHEMA, rows)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return {"rows_b_per_row": round(held / n), "peak_b_per_row": round(peak / n)}


def run(out: Path, config: Path, meta: dict, period_s: float = 0.5) -> None:
    """Run ``rank`` on ``config``, sampling its process tree; write the raw records."""
    cmd = [sys.executable, "-m", "sumo_ayss.rank", str(config), "--no-live"]
    log = (out / "rank.log").open("a")
    events_f = (out / "events.tsv").open("w")
    samples_f = (out / "samples.csv").open("w")
    samples_f.write("t_s,rss_mib,cpu_s,n_procs\n")
    t0 = time.monotonic()
    child = subprocess.Popen(cmd, stdout=log, stderr=subprocess.PIPE, text=True)

    def read_log() -> None:
        assert child.stderr is not None
        for line in child.stderr:
            log.write(line)
            log.flush()
            events_f.write(f"{time.monotonic() - t0:.2f}\t{line.rstrip()}\n")
            events_f.flush()

    reader = threading.Thread(target=read_log, daemon=True)
    reader.start()
    while child.poll() is None:
        rss, cpu, n = read_tree(child.pid)
        samples_f.write(f"{time.monotonic() - t0:.2f},{rss:.1f},{cpu:.2f},{n}\n")
        samples_f.flush()
        time.sleep(period_s)
    wall = time.monotonic() - t0
    reader.join(timeout=5)
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    for f in (log, events_f, samples_f):
        f.close()
    meta |= {
        "returncode": child.returncode,
        "wall_s": round(wall, 1),
        "cpu_s": round(usage.ru_utime + usage.ru_stime, 1),
        "command": COMMAND,
    }
    (out / "run.json").write_text(json.dumps(meta, indent=1) + "\n")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, default=Path("runs/load32"))
    p.add_argument("--k", type=int, default=32)
    p.add_argument("--vuts", choices=["models", "varied"], default="models")
    p.add_argument("--budget", choices=["tiny", "verdict"], default="tiny")
    p.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3], help="tiny budget only")
    p.add_argument("--analyse", action="store_true", help="only the tables of a run in --out")
    p.add_argument("--row-bytes", action="store_true", help="only the heap per cross-play row")
    args = p.parse_args()
    if args.row_bytes:
        print(row_bytes())
        return
    if not args.analyse:
        config = write_config(args.out, args.k, args.seeds, args.budget, args.vuts)
        meta = {
            "k": args.k,
            "vuts": args.vuts,
            "budget": args.budget,
            "started": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
            "cpus": os.cpu_count(),
            "loadavg_at_start": os.getloadavg(),
        }
        run(args.out, config, meta)
    analyse(args.out)


if __name__ == "__main__":
    main()
