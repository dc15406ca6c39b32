"""The README's commands work as written (at a tiny budget) from a fresh folder.

The quick-start block (after ``<!-- quick-start ...-->`` in README.md) is run line by line in
a temporary folder that links ``configs/``, with the training budget and the evaluation sizes
shrunk by appended options; ``make demo``'s pipeline runs on a tiny copy of
``configs/demo.yaml`` (slow).
"""

from __future__ import annotations

import dataclasses
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from sumo_ayss.config import PROJECT_ROOT

README = (PROJECT_ROOT / "README.md").read_text()

TINY = {
    "sumo_ayss.train": ["--total-timesteps", "1200", "--eval-every", "600", "--no-progress"],
    "sumo_ayss.evaluate": ["--n-outcome", "10", "--n-ayss", "2000"],
    "sumo_ayss.report": ["--n-boot", "200"],
}


def quick_start_commands() -> list[list[str]]:
    block = re.search(r"<!-- quick-start.*?-->\s*```bash\n(.*?)```", README, re.S)
    assert block, "README.md has no quick-start block"
    commands = []
    for line in block.group(1).splitlines():
        argv = shlex.split(line, comments=True)
        if argv:
            commands.append(argv)
    return commands


def _run(argv: list[str], cwd: Path) -> subprocess.CompletedProcess[str]:
    assert argv[:2] == [".venv/bin/python", "-m"], argv
    module = argv[2]
    cmd = [sys.executable, "-m", module, *argv[3:], *TINY.get(module, [])]
    return subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=600)


def test_quick_start_block_is_train_evaluate_report() -> None:
    modules = [argv[2] for argv in quick_start_commands()]
    assert modules == ["sumo_ayss.train", "sumo_ayss.evaluate", "sumo_ayss.report"]


@pytest.mark.sumo
def test_quick_start_commands_run_as_written(tmp_path: Path) -> None:
    (tmp_path / "configs").symlink_to(PROJECT_ROOT / "configs")
    outputs = []
    for argv in quick_start_commands():
        done = _run(argv, tmp_path)
        assert done.returncode == 0, (
            f"{shlex.join(argv)}\n{done.stdout[-2000:]}{done.stderr[-3000:]}"
        )
        outputs.append(done.stdout.strip().splitlines()[-1])
    run_dir = tmp_path / "runs" / "single" / "car_following" / "pi2" / "seed_0"
    assert (run_dir / "spcp.json").is_file() and (run_dir / "ayss.csv").is_file()
    report = Path(outputs[-1])
    report = report if report.is_absolute() else tmp_path / report
    assert report.is_file() and "NOT to be trusted" in report.read_text()


@pytest.mark.sumo
@pytest.mark.slow
def test_make_demo_pipeline_at_a_tiny_budget(tmp_path: Path) -> None:
    assert (
        "$(BIN)/python -m sumo_ayss.pipeline configs/demo.yaml"
        in (PROJECT_ROOT / "Makefile").read_text()
    )
    demo = yaml.safe_load((PROJECT_ROOT / "configs" / "demo.yaml").read_text())
    demo["experiments"] = {
        k: str(PROJECT_ROOT / "configs" / v) for k, v in demo["experiments"].items()
    }
    demo.update(out="runs/demo", total_timesteps=1200, eval_every=600)
    demo["grid"]["seeds"] = [0]
    demo["evaluate"] = {"n_outcome": 10, "n_ayss": 2000}
    (tmp_path / "demo.yaml").write_text(yaml.safe_dump(demo))
    done = subprocess.run(
        [sys.executable, "-m", "sumo_ayss.pipeline", "demo.yaml"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-3000:]
    lines = done.stdout.strip().splitlines()
    assert lines[-1].startswith("report: ")
    assert any(x.startswith("WARNING: Small training budget: 1,200") for x in lines)
    assert "car_following/pi1/seed_0: started" in done.stderr  # one line per job event


DOCS = {name: (PROJECT_ROOT / name).read_text() for name in ("README.md", "docker/README.md")}


@pytest.mark.parametrize("doc", sorted(DOCS))
def test_named_modules_commands_and_files_exist(doc: str) -> None:
    import importlib

    from sumo_ayss.cli import COMMANDS
    from tests.test_layers import main_guard_imports, module_files

    guards = main_guard_imports(module_files())
    text = DOCS[doc]
    for module in set(re.findall(r"python -m (sumo_ayss[\w.]*)", text)):
        loaded = importlib.import_module(module)
        if hasattr(loaded, "__path__"):  # a package: `python -m` runs its __main__
            loaded = importlib.import_module(f"{module}.__main__")
        elif guards.get(module):  # a stage whose __main__ guard runs its command
            loaded = importlib.import_module(guards[module][0])
        assert callable(loaded.main), module
    for command in set(re.findall(r"sumo-ayss (\w+)", text)) | set(
        re.findall(r"sumo-ayss \\\n\s+(\w+)", text)
    ):
        assert command in COMMANDS, f"{doc}: sumo-ayss {command}"
    for path in set(re.findall(r"\b((?:configs|examples|docker)/[\w./-]+\.(?:yaml|py|sh))", text)):
        assert (PROJECT_ROOT / path).is_file(), f"{doc}: {path}"


def test_controller_pipeline_block_adds_to_the_shipped_experiment(tmp_path: Path) -> None:
    """The README's controller YAML trains like ``configs/car_following.yaml`` (its learner,
    its pairs per simulation), with the controller VUT added: not the code's defaults."""
    from sumo_ayss.config import load_experiment
    from sumo_ayss.config.pipeline import load_pipeline
    from sumo_ayss.pipeline import plan_jobs

    block = re.search(r"<!-- controller-pipeline.*?-->\s*```yaml\n(.*?)```", README, re.S)
    assert block, "README.md has no controller-pipeline block"
    path = tmp_path / "my_acc.yaml"
    path.write_text(block.group(1))
    cfg = load_pipeline(path)
    jobs = plan_jobs(cfg)
    shipped = load_experiment(PROJECT_ROOT / "configs" / "car_following.yaml")
    acc = [j for j in jobs if j.vut == "acc_tg2"]
    assert len(acc) == 3
    # The experiment's training settings, the pipeline's budget (transitions, cadence and,
    # at `fast`, the learning rate) aside.
    expected = dataclasses.replace(
        shipped.train,
        progress_bar=False,
        total_timesteps=cfg.total_timesteps or shipped.train.total_timesteps,
        eval_every=cfg.eval_every or shipped.train.eval_every,
    )
    for job in acc:
        assert job.experiment.env.vut_type.controller is not None
        assert job.experiment.train == expected
        lr = cfg.learning_rate or shipped.agent.learning_rate
        assert job.experiment.agent == dataclasses.replace(shipped.agent, learning_rate=lr)
    assert shipped.train.n_envs > 1  # the snippet alone would have given 1


def test_black_box_pipeline_block_reads_an_fmu_and_a_process_vut(tmp_path: Path) -> None:
    """The README's FMU and process YAML is read (no FMU opened, no process started)."""
    from sumo_ayss.config.pipeline import load_pipeline
    from sumo_ayss.pipeline import plan_jobs
    from sumo_ayss.vuts.fmu_spec import FmuSpec
    from sumo_ayss.vuts.process_spec import ProcessSpec

    block = re.search(r"<!-- black-box-pipeline.*?-->\s*```yaml\n(.*?)```", README, re.S)
    assert block, "README.md has no black-box-pipeline block"
    path = tmp_path / "my_black_boxes.yaml"
    path.write_text(block.group(1))
    kinds = {
        j.vut: type(j.experiment.env.vut_type.controller) for j in plan_jobs(load_pipeline(path))
    }
    assert kinds == {"acc_fmu": FmuSpec, "acc_proc": ProcessSpec}
    fmu = next(j for j in plan_jobs(load_pipeline(path)) if j.vut == "acc_fmu")
    spec = fmu.experiment.env.vut_type.controller
    assert isinstance(spec, FmuSpec) and spec.path == str(tmp_path / "runs" / "fmus" / "acc.fmu")


def test_readme_commands_exist_on_a_fresh_clone_and_write_only_ignored_folders() -> None:
    """Console scripts live in .venv/bin (not on PATH after `make`); outputs go to runs/,
    which git ignores."""
    for tool in ("ray", "tensorboard", "sumo-ayss"):
        for m in re.finditer(rf"(\S*){tool} (start|--logdir|\w+)", README):
            if tool == "sumo-ayss" and m.group(1) == "":
                continue  # "sumo-ayss <command>" named in prose, with .venv/bin/ given once
            assert m.group(1).endswith(".venv/bin/") or m.group(1).startswith("'"), m.group(0)
    ignored = (PROJECT_ROOT / ".gitignore").read_text().splitlines()
    assert "runs/" in ignored
    for out in re.findall(r"--out (\S+)", README):
        assert out.startswith(("runs/", "DIR", "<")), f"--out {out}: not under runs/"


def test_krauss_example_is_the_deterministic_vut_it_says() -> None:
    """The README's Krauss block says ``sigma: 0.0``; SUMO's default speedDev 0.1 would still
    draw a random speed factor, so the example must switch it off too (issue 35)."""
    from sumo_ayss.vuts.catalog import VehicleType

    block = re.search(r"```yaml\n(env:\n  vut: my_krauss\n.*?)```", README, re.S)
    assert block, "README.md has no Krauss example"
    spec = yaml.safe_load(block.group(1))["env"]["vuts"]["my_krauss"]
    vtype = VehicleType(model=spec["model"], params=spec["params"])
    assert vtype.random_draws() == ()


def test_replay_export_example_reads_a_run_the_quick_start_makes() -> None:
    """The OpenSCENARIO example exports a run folder the quick start writes (issue 35)."""
    evaluate = next(a for a in quick_start_commands() if a[2] == "sumo_ayss.evaluate")
    block = re.search(r"sumo_ayss\.replay export (\S+) \\\n\s+--outcome-row", README)
    assert block, "README.md has no replay export example"
    assert block.group(1) == evaluate[3]


def test_readme_states_the_demos_own_budget() -> None:
    """The demo's seeds and transitions as README states them are demo.yaml's (issue 35:
    it said the demo was marked untrusted and that experiments use 100,000 transitions)."""
    from sumo_ayss.config.pipeline import load_pipeline

    demo = load_pipeline(PROJECT_ROOT / "configs" / "demo.yaml")  # its budget resolved
    intro = README.split("## Glossary")[0]
    flat = " ".join(intro.split())
    assert (
        f"trains {demo.total_timesteps:,} transitions per run with {len(demo.seeds)} seeds" in flat
    )
    assert "the experiments use 100,000" not in " ".join(README.split())
    assert "not to be trusted" not in intro
