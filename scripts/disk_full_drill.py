"""Full-disk drill (issue 38): a tiny study whose output file system fills up at several
points, then resumes once space is freed.

    .venv/bin/python scripts/disk_full_drill.py [--work DIR] [--fractions 0.1,0.3,0.6,0.9]

The file system: a real size-limited tmpfs (``mount -t tmpfs -o size=...``), mounted in a
private mount namespace (``unshare --mount``; as root, or through a user namespace), so that
nothing outside this drill sees it and it vanishes with the drill. The study: ``kill_drill``'s
(car-following, ``--vuts``, ``--seeds``, 600 transitions per run, ``--n-outcome`` outcome and
cross-play scenarios, 2 workers). First an undisturbed run on the ordinary disk: its output's
size B. Then per fraction f: a fresh output folder on the tmpfs, a filler file that leaves
f·B bytes free, the pipeline (it must stop with exit 1 and an ``error:`` line naming a path and
the bytes it needed); every file it left is read back (JSON, CSV, YAML, zip archives; temporary
files counted); the filler removed (space freed); the same command again (exit 0); the study
compared byte for byte with the undisturbed run (``scripts/ray_drill.study_files``: every
``outcome.csv``, ``ayss.csv``, ``crossplay.csv``, ``crossplay_reference.csv``, the
``ranking.csv`` of ``rank --no-run``, each ``spcp.json`` but its wall time).

One line per fraction and ``<work>/disk_full_drill.json``. Exit status 0 when every fraction
passed. Where no namespace or tmpfs can be had, it says so and exits 2.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import re
import shutil
import subprocess
import sys
import time
import zipfile
from pathlib import Path
from typing import Any

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))

from kill_drill import write_study
from ray_cluster import ROOT, can_hide, unshare_argv
from ray_drill import rank_no_run, study_files

INSIDE = "SUMO_AYSS_DISK_DRILL_INSIDE"


def pipeline(pipe: Path, out: Path, log: Path, flags: list[str]) -> int:
    cmd = [sys.executable, "-m", "sumo_ayss.pipeline", str(pipe), "--no-live", "--out", str(out)]
    with log.open("ab") as f:
        return subprocess.run([*cmd, *flags], cwd=ROOT, stdout=f, stderr=f, timeout=1800).returncode


def tree_bytes(folder: Path) -> int:
    return sum(p.stat().st_size for p in folder.rglob("*") if p.is_file())


def read_back(out: Path) -> dict[str, Any]:
    """Read every file the stopped run left: the ones that failed, and temporaries left."""
    bad, temporaries, checked = [], [], 0
    for p in sorted(out.rglob("*")):
        if not p.is_file():
            continue
        name = p.name
        if name.endswith(".tmp") or ".tmp." in name:
            temporaries.append(str(p.relative_to(out)))
            continue
        checked += 1
        try:
            if name.endswith(".json"):
                json.loads(p.read_text())
            elif name.endswith(".csv"):
                with p.open(newline="") as f:
                    rows = list(csv.reader(f))
                if not rows:
                    raise ValueError("empty")
            elif name.endswith((".yaml", ".yml")):
                yaml.safe_load(p.read_text())
            elif name.endswith(".zip"):
                with zipfile.ZipFile(p) as z:
                    if z.testzip() is not None:
                        raise ValueError("corrupt member")
            elif ".tfevents." in name:  # an append-only log: TensorBoard reads what is whole
                from tensorboard.backend.event_processing.event_file_loader import (
                    EventFileLoader,
                )

                sum(1 for _ in EventFileLoader(str(p)).Load())
            elif p.stat().st_size == 0 and name != "job.log":
                raise ValueError("empty")
        except Exception as e:
            bad.append(f"{p.relative_to(out)}: {e}")
    return {"checked": checked, "unreadable": bad, "temporaries": temporaries}


def drill(args: argparse.Namespace) -> int:
    work: Path = args.work
    study = write_study(work / "study", args.n_outcome)
    data = yaml.safe_load(study.read_text())
    data["grid"].update(vuts=args.vuts.split(","), seeds=[int(s) for s in args.seeds.split(",")])
    study.write_text(yaml.safe_dump(data))
    flags = ["--workers", "2"]
    t0 = time.perf_counter()
    ref = work / "reference"
    if pipeline(study, ref, work / "reference.log", flags) != 0 or rank_no_run(study, ref) != 0:
        print(f"the undisturbed run failed: {work}/reference.log")
        return 1
    expected = study_files(ref)
    size = tree_bytes(ref)
    print(f"undisturbed: {time.perf_counter() - t0:.1f} s, {size:,} bytes, {len(expected)} files")
    fs = work / "fs"
    fs.mkdir()
    tmpfs_b = 4 * size + (8 << 20)
    subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={tmpfs_b}", "tmpfs", str(fs)], check=True)
    results = []
    try:
        for k, fraction in enumerate(float(f) for f in args.fractions.split(",")):
            out, filler = fs / f"out_{k}", fs / "filler"
            free = os.statvfs(fs).f_bavail * os.statvfs(fs).f_frsize
            with filler.open("wb") as f:
                f.write(b"\0" * max(0, free - int(fraction * size)))
            left = os.statvfs(fs).f_bavail * os.statvfs(fs).f_frsize
            log = work / f"fraction_{k}.log"
            code = pipeline(study, out, log, flags)
            text = log.read_text(errors="replace")
            error = [ln for ln in text.splitlines() if ln.startswith("error:")]
            named = bool(error) and bool(
                re.search(r"of (/\S+): the file needs (more than )?[\d,]+ bytes", error[0])
            )
            readable = read_back(out)
            filler.unlink()  # the space is freed
            rerun = work / f"fraction_{k}.rerun.log"
            code2 = pipeline(study, out, rerun, flags)
            differ = ["rank --no-run failed"] if rank_no_run(study, out) != 0 else []
            got = study_files(out)
            differ += sorted(
                n for n in expected.keys() | got.keys() if expected.get(n) != got.get(n)
            )
            ok = code == 1 and named and not readable["unreadable"] and code2 == 0 and not differ
            r = {
                "fraction": fraction,
                "free_bytes": left,
                "exit": code,
                "error": error[0][:400] if error else None,
                "read_back": readable,
                "rerun_exit": code2,
                "differ": differ,
                "ok": ok,
            }
            results.append(r)
            print(json.dumps(r), flush=True)
            shutil.rmtree(out)
    finally:
        subprocess.run(["umount", str(fs)], check=False)
    summary = {"undisturbed_bytes": size, "tmpfs_bytes": tmpfs_b, "fractions": results}
    (work / "disk_full_drill.json").write_text(json.dumps(summary, indent=2) + "\n")
    n_ok = sum(r["ok"] for r in results)
    print(
        f"{n_ok} of {len(results)} full disks: a clear error, every file readable, an equal resume"
    )
    return 0 if n_ok == len(results) else 1


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--work", type=Path, default=Path("/tmp/disk_full_drill"))
    p.add_argument("--fractions", default="0.1,0.3,0.6,0.9", help="free space, of the study's size")
    p.add_argument("--n-outcome", type=int, default=20)
    p.add_argument("--vuts", default="pi1,pi2")
    p.add_argument("--seeds", default="0,1")
    args = p.parse_args(argv)
    if os.environ.get(INSIDE):
        return drill(args)
    if not can_hide():
        print("no private mount namespace with a tmpfs here (needs root or user namespaces)")
        return 2
    if args.work.exists():
        shutil.rmtree(args.work)
    args.work.mkdir(parents=True)
    env = {**os.environ, INSIDE: "1"}
    argv = [*unshare_argv(), sys.executable, str(Path(__file__).resolve()), *(argv or sys.argv[1:])]
    return subprocess.run(argv, env=env).returncode


if __name__ == "__main__":
    sys.exit(main())
