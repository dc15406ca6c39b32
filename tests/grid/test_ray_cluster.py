"""A two-node Ray cluster started with the README's own commands (issue 38): token
authentication, a worker node that sees none of the driver's files, a job's worker process
killed mid-job. The full drill (a node and the head killed too, byte-identical studies):
``scripts/ray_drill.py``."""

from __future__ import annotations

import re
import subprocess
import time
from pathlib import Path

import pytest

from tests.test_pipeline import PROJECT_ROOT, write_configs

pytest.importorskip("ray", reason="ray is not installed (pip install 'sumo_ayss[ray]')")
from scripts.ray_cluster import Cluster, can_hide, readme_commands


def test_readme_cluster_block_is_the_one_run() -> None:
    commands = readme_commands()
    assert commands[0].endswith("ray get-auth-token --generate")
    assert all(c.startswith("RAY_AUTH_MODE=token ") for c in commands[1:])
    assert "RAY_AUTH_TOKEN=<token>" in commands[2] and "--address HEAD:6379" in commands[2]
    assert "--backend ray --address HEAD:6379" in commands[3]


@pytest.mark.sumo
@pytest.mark.timeout(900)  # two Ray nodes, a refused join and 4 tiny jobs: ~2 min on 2 busy cores
def test_pipeline_on_a_two_node_cluster_retries_a_killed_worker(tmp_path: Path) -> None:
    cluster = Cluster(tmp_path / "cluster")
    try:
        cluster.start_head(cpus=1)
    except RuntimeError:
        cluster.stop()
        raise
    driver = tmp_path / "driver"
    driver.mkdir()
    pipe = write_configs(driver, [0, 1], total_timesteps=1500, eval_every=500)
    hide = driver if can_hide() else None  # the worker node sees an empty folder there
    try:
        worker = cluster.start_worker("w1", cwd=tmp_path / "elsewhere", cpus=1, hide=hide)

        # Without the head's token the pipeline is refused with an error that names it.
        env = cluster.driver_env()
        del env["RAY_AUTH_TOKEN_PATH"]
        env["HOME"] = str(tmp_path / "no_token_home")
        refused = subprocess.run(
            cluster.pipeline_command(pipe, "--no-live"),
            cwd=PROJECT_ROOT,
            env=env,
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert refused.returncode == 1
        assert "error: --address" in refused.stderr and "token" in refused.stderr
        assert not list(driver.glob("runs/*/*/seed_*"))  # no job started

        # With it: 4 jobs on 2 nodes; the first job's worker process on w1 is killed.
        log = tmp_path / "pipeline.log"
        with log.open("wb") as f:
            proc = subprocess.Popen(
                cluster.pipeline_command(pipe, "--no-live"),
                cwd=PROJECT_ROOT,
                env=cluster.driver_env(),
                stdout=f,
                stderr=subprocess.STDOUT,
            )
        killed = None
        while proc.poll() is None and killed is None:
            tasks = worker.task_processes()
            if tasks:
                time.sleep(0.5)  # into the job
                subprocess.run(["kill", "-9", str(tasks[0])], check=False)
                killed = tasks[0]
            time.sleep(0.05)
        code = proc.wait(timeout=600)
    finally:
        cluster.stop()
    assert not cluster.leftovers()
    text = log.read_text(errors="replace")
    assert code == 0, text[-3000:]
    assert killed is not None, "no job ran on the worker node"
    failed = re.findall(r"\] (\S+): failed \(ray\.exceptions\.WorkerCrashedError", text)
    assert len(failed) == 1, text[-3000:]
    assert f"{failed[0]}: submitted to Ray (try 2)" in text
    done = re.findall(r"\] (\S+): done in ", text)
    assert sorted(done) == sorted(set(done)) and len(done) == 4  # each job once
    assert "grid finished: 4 done (1 after a retry), 0 failed" in text
    assert len(set(re.findall(r"done in .* on (\S+:\w+)", text))) == 2  # both nodes worked
    for run in (driver / "runs" / "car_following").glob("*/seed_*"):
        assert (run / "outcome.csv").is_file() and (run / "spcp.json").is_file()
    assert (driver / "runs" / "car_following" / "crossplay.csv").is_file()
