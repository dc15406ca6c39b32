"""Ray fault drill (issue 38): a head and a worker node started with the README's commands on
this machine; a tiny study's pipeline joins them with ``--address``; kill a worker process
mid-job, kill the worker node mid-job, kill the head while jobs are queued.

    .venv/bin/python scripts/ray_drill.py [--work DIR] [--total-timesteps 3000] [--drills ...]

The study: car-following, VUTs pi1 and pi2, training seeds 0 and 1 (4 jobs), the tiny learner
(``scripts/kill_drill.py``'s), ``--total-timesteps`` transitions per run. First an undisturbed
run on the local process pool (the reference). Then a cluster (``scripts/ray_cluster.py``):
a head with 1 CPU and a worker node with 1 CPU, the worker started from another working
directory and home folder (no token file: the token reaches it in ``RAY_AUTH_TOKEN``) and, where
this machine allows a private mount namespace, with the driver's folder (study YAML and output
folders) covered by an empty tmpfs, so that run folders can only travel inside the tasks.

- ``refused``: the pipeline without the README's variables (no token): a clear error;
- ``worker``: SIGKILL the Ray worker process running a job on the worker node, 2 s into it;
- ``node``: SIGKILL every process of the worker node, 2 s into a job there (then a new one);
- ``head``: SIGKILL every process of the head once a job has finished and others are still
  queued; the pipeline must stop with a clear error within seconds; then a new head and
  worker on the same address, and the same command again.

After each: the pipeline exits 0, every job finished exactly once ("done" once; a job finished
before a rerun is not submitted again), and the study equals the reference byte for byte
(every ``outcome.csv``, ``ayss.csv``, ``crossplay.csv``, ``crossplay_reference.csv``, the
``ranking.csv`` of ``rank --no-run``, and each ``spcp.json`` but its wall time). One line per
drill and ``<work>/ray_drill.json``. Every node started is stopped at the end (never ``ray
stop``, which would stop every Ray of the machine). Exit status 0 when every drill passed.
"""

from __future__ import annotations

import argparse
import json
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from kill_drill import write_study
from ray_cluster import ROOT, Cluster, Node, can_hide

KILL_AFTER_S = 2.0  # seconds into a job on the worker node


def study_files(out: Path) -> dict[str, bytes]:
    """The files compared (by path): the tables, and spcp.json without its wall time."""
    files: dict[str, bytes] = {}
    for pattern in (
        "ranking.csv",
        "*/crossplay.csv",
        "*/crossplay_reference.csv",
        "*/*/seed_*/outcome.csv",
        "*/*/seed_*/ayss.csv",
    ):
        for p in sorted(out.glob(pattern)):
            files[str(p.relative_to(out))] = p.read_bytes()
    for p in sorted(out.glob("*/*/seed_*/spcp.json")):
        spcp = json.loads(p.read_text())
        spcp.get("row", {}).pop("wall_s", None)
        files[str(p.relative_to(out))] = json.dumps(spcp, sort_keys=True).encode()
    return files


def rank_no_run(pipe: Path, out: Path) -> int:
    """``rank --no-run`` on a finished output folder: writes its ``ranking.csv``."""
    cmd = [sys.executable, "-m", "sumo_ayss.rank", str(pipe), "--no-run", "--no-live"]
    with (out.parent / f"{out.name}.rank.log").open("wb") as f:
        return subprocess.run(
            [*cmd, "--out", str(out)], cwd=ROOT, stdout=f, stderr=f, timeout=600
        ).returncode


def job_events(log: str) -> dict[str, dict[str, int]]:
    """Per job: how often the log says it was submitted, done, failed or not submitted."""
    events: dict[str, dict[str, int]] = {}
    for line in log.splitlines():
        m = re.search(r"\] (\S+/seed_\d+): (submitted|done in|failed|FAILED)", line)
        if m:
            kind = m.group(2).split()[0].lower()
            if "already finished, not submitted" in line:
                kind = "not_submitted"
            job = events.setdefault(m.group(1), {})
            job[kind] = job.get(kind, 0) + 1
    return events


class Drill:
    def __init__(self, work: Path, timesteps: int, n_outcome: int) -> None:
        self.work = work
        self.driver = work / "driver"  # what a worker node must not see
        self.pipe = write_study(self.driver / "study", n_outcome)
        self.flags = [
            "--total-timesteps",
            str(timesteps),
            "--eval-every",
            str(timesteps // 3),
            "--no-live",
        ]
        self.cluster = Cluster(work / "cluster")
        self.hide = self.driver if can_hide() else None
        self.elsewhere = work / "elsewhere"
        self.workers = 0
        self.reference: dict[str, bytes] = {}

    # -- nodes ------------------------------------------------------------------------

    def start(self) -> tuple[Node, Node]:
        head = self.cluster.start_head(cpus=1)
        self.workers += 1
        worker = self.cluster.start_worker(
            f"w{self.workers}", cwd=self.elsewhere, cpus=1, hide=self.hide
        )
        return head, worker

    # -- runs -------------------------------------------------------------------------

    def local(self) -> float:
        out = self.driver / "out_local"
        t0 = time.perf_counter()
        cmd = [sys.executable, "-m", "sumo_ayss.pipeline", str(self.pipe), *self.flags]
        with (self.work / "local.log").open("wb") as f:
            code = subprocess.run(
                [*cmd, "--out", str(out), "--workers", "2"], cwd=ROOT, stdout=f, stderr=f
            ).returncode
        if code != 0 or rank_no_run(self.pipe, out) != 0:
            raise RuntimeError(f"the undisturbed local run failed; see {self.work}/local.log")
        self.reference = study_files(out)
        return time.perf_counter() - t0

    def launch(self, name: str) -> tuple[subprocess.Popen[bytes], Path, Path]:
        out = self.driver / f"out_{name}"
        log = self.work / f"{name}.log"
        cmd = self.cluster.pipeline_command(self.pipe, *self.flags, "--out", str(out))
        with log.open("ab") as f:
            proc = subprocess.Popen(
                cmd, cwd=ROOT, env=self.cluster.driver_env(), stdout=f, stderr=f
            )
        return proc, out, log

    def compare(self, out: Path) -> list[str]:
        if rank_no_run(self.pipe, out) != 0:
            return ["rank --no-run failed"]
        got = study_files(out)
        return sorted(
            n for n in self.reference.keys() | got.keys() if self.reference.get(n) != got.get(n)
        )

    # -- drills -----------------------------------------------------------------------

    def kill_in_job(self, name: str, whole_node: bool) -> dict[str, Any]:
        _head, worker = self.start()
        proc, out, log = self.launch(name)
        first_seen: dict[int, float] = {}
        killed = ""
        while proc.poll() is None and not killed:
            for pid in worker.task_processes():
                first_seen.setdefault(pid, time.monotonic())
                if time.monotonic() - first_seen[pid] >= KILL_AFTER_S:
                    if whole_node:
                        killed = f"worker node {worker.name} ({worker.kill()} processes)"
                    else:
                        subprocess.run(["kill", "-9", str(pid)], check=False)
                        killed = f"Ray worker process {pid} on {worker.name}"
                    break
            time.sleep(0.1)
        code = proc.wait(timeout=900)
        text = log.read_text(errors="replace")
        self.cluster.stop()
        events = job_events(text)
        retried = [j for j, e in events.items() if e.get("failed")]
        once = all(e.get("done") == 1 for e in events.values()) and len(events) == 4
        differ = self.compare(out)
        why = re.findall(r"failed \(([^:]*(?:Error|Exception))", text)
        return {
            "drill": name,
            "killed": killed or "nothing (the job ended first)",
            "exit": code,
            "retried": retried,
            "failure": sorted(set(why)),
            "every_job_done_once": once,
            "differ": differ,
            "ok": bool(killed) and code == 0 and once and bool(retried) and not differ,
        }

    def refused(self) -> dict[str, Any]:
        """The pipeline without the README's variables (no RAY_AUTH_MODE, no token): the
        head refuses it; the error must say so, and nothing is written."""
        self.start()
        env = {k: v for k, v in self.cluster.driver_env().items() if not k.startswith("RAY_AUTH")}
        out = self.driver / "out_refused"
        cmd = self.cluster.pipeline_command(self.pipe, *self.flags, "--out", str(out))
        t0 = time.monotonic()
        done = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True, timeout=600)
        wall = time.monotonic() - t0
        self.cluster.stop()
        error = [ln for ln in done.stderr.splitlines() if ln.startswith("error:")]
        ok = done.returncode == 1 and bool(error) and "token" in error[0]
        return {
            "drill": "refused",
            "exit": done.returncode,
            "after_s": round(wall, 1),
            "error": error[:1],
            "wrote": out.exists() and any(out.rglob("*.csv")),
            "ok": ok and not (out.exists() and any(out.rglob("*.csv"))),
        }

    def kill_head(self) -> dict[str, Any]:
        head, worker = self.start()
        proc, out, log = self.launch("head")
        killed_at = None
        while proc.poll() is None:
            text = log.read_text(errors="replace")
            if re.search(r"\[[1-3]/4 done", text):
                killed_at = time.monotonic()
                head.kill()
                break
            time.sleep(0.1)
        code = proc.wait(timeout=600)
        stop_s = time.monotonic() - killed_at if killed_at else None
        text = log.read_text(errors="replace")
        error = [ln for ln in text.splitlines() if ln.startswith("error:")]
        finished = sorted(
            str(p.parent.relative_to(out)) for p in out.glob("*/*/seed_*/evaluate.done.json")
        )
        worker.kill()  # its head is gone
        self.cluster.stop()
        # a new head and worker on the same address; the same command again
        self.start()
        proc2, _, _ = self.launch("head")  # appends to the same log
        code2 = proc2.wait(timeout=900)
        self.cluster.stop()
        rerun = log.read_text(errors="replace")[len(text) :]
        events = job_events(rerun)
        not_resent = sorted(j for j, e in events.items() if e.get("not_submitted"))
        resent = sorted(j for j, e in events.items() if e.get("submitted"))
        differ = self.compare(out)
        ok = (
            killed_at is not None
            and code != 0
            and bool(error)
            and stop_s is not None
            and stop_s < 30
            and code2 == 0
            and not_resent == finished
            and not set(resent) & set(finished)
            and not differ
        )
        return {
            "drill": "head",
            "exit": code,
            "stopped_after_s": round(stop_s, 1) if stop_s is not None else None,
            "error": error[:1],
            "finished_before": finished,
            "rerun_exit": code2,
            "rerun_not_submitted": not_resent,
            "rerun_submitted": resent,
            "differ": differ,
            "ok": ok,
        }


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--work", type=Path, default=Path("/tmp/ray_drill"))
    p.add_argument("--total-timesteps", type=int, default=3000)
    p.add_argument("--n-outcome", type=int, default=20)
    p.add_argument("--drills", default="refused,worker,node,head")
    args = p.parse_args(argv)
    if args.work.exists():
        shutil.rmtree(args.work)
    drill = Drill(args.work, args.total_timesteps, args.n_outcome)
    results: list[dict[str, Any]] = []
    try:
        wall = drill.local()
        hidden = f"hidden from the worker node: {drill.hide}" if drill.hide else "not hidden"
        print(f"undisturbed local run: {wall:.1f} s, {len(drill.reference)} files; {hidden}")
        for name in args.drills.split(","):
            if name == "head":
                r = drill.kill_head()
            elif name == "refused":
                r = drill.refused()
            else:
                r = drill.kill_in_job(name, whole_node=name == "node")
            results.append(r)
            print(json.dumps(r), flush=True)
    finally:
        drill.cluster.stop()
        left = drill.cluster.leftovers()
        if left:
            print(f"LEFT RUNNING: {left}")
    summary = {"hidden": str(drill.hide), "drills": results, "leftovers": left}
    (args.work / "ray_drill.json").write_text(json.dumps(summary, indent=2) + "\n")
    n_ok = sum(r["ok"] for r in results)
    print(f"{n_ok} of {len(results)} drills passed")
    return 0 if n_ok == len(results) and not left else 1


if __name__ == "__main__":
    sys.exit(main())
