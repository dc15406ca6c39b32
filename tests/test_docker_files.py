"""The Docker files that can be checked without an engine: the image installs the ray
extra, the smoke script is valid shell and runs a pipeline command the CLI accepts."""

from __future__ import annotations

import itertools
import re
import shutil
import subprocess

import pytest

from sumo_ayss.config import PROJECT_ROOT
from sumo_ayss.config.pipeline import load_pipeline
from sumo_ayss.pipeline import plan_jobs

DOCKER = PROJECT_ROOT / "docker"
SMOKE = DOCKER / "smoke.sh"


def test_image_installs_the_ray_extra() -> None:
    dockerfile = (DOCKER / "Dockerfile").read_text()
    assert re.search(r'pip install "\./\[ray\]"', dockerfile)
    assert '"./[ray]"' in (DOCKER / "check_install.sh").read_text()  # the check mirrors it


def test_smoke_script_is_valid_shell() -> None:
    subprocess.run(["bash", "-n", str(SMOKE)], check=True)
    shellcheck = shutil.which("shellcheck")
    if shellcheck is None:
        pytest.skip("shellcheck is not installed")
    done = subprocess.run([shellcheck, str(SMOKE)], capture_output=True, text=True)
    assert done.returncode == 0, done.stdout


def test_smoke_pipeline_command_is_accepted_and_tiny() -> None:
    text = SMOKE.read_text()
    cmd = re.search(r"pipeline (configs/\S+) (.*?)\| tee", text.replace("\\\n", " "), re.S)
    assert cmd, "smoke.sh runs no pipeline"
    args = cmd.group(2).split()
    flags = {
        name.removeprefix("--").replace("-", "_"): int(value)
        for name, value in itertools.pairwise(args)
        if name in ("--total-timesteps", "--eval-every", "--n-outcome", "--n-ayss")
    }
    assert set(flags) == {"total_timesteps", "eval_every", "n_outcome", "n_ayss"}
    seeds = [int(args[args.index("--seeds") + 1])]
    cfg = load_pipeline(PROJECT_ROOT / cmd.group(1), seeds=seeds, **flags)
    jobs = plan_jobs(cfg)
    assert len(jobs) == 4 and all(j.experiment.train.total_timesteps <= 2000 for j in jobs)
    assert "--no-live" in args and "engine" in text and "podman" in text
