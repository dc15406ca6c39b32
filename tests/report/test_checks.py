"""Report guards: budget and SPCP state shown, small budgets flagged, mixed runs refused."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml

from sumo_ayss.errors import ConfigError
from sumo_ayss.report import write_report
from sumo_ayss.report.checks import read_training, trust_warnings
from tests.report.test_report import FAST, make_run


def _set_budget(run_dir: Path, total: int, every: int = 10_000) -> None:
    path = run_dir / "config.yaml"
    data = yaml.safe_load(path.read_text())
    data["train"] = {"total_timesteps": total, "eval_every": every}
    path.write_text(yaml.safe_dump(data))


def _set_eval(run_dir: Path, returns: list[float], spcp_step: int) -> None:
    lines = ["step,mean_return,std_return,n_episodes"]
    lines += [f"{10_000 * (k + 1)},{r},2.0,100" for k, r in enumerate(returns)]
    (run_dir / "eval.csv").write_text("\n".join(lines) + "\n")
    spcp = json.loads((run_dir / "spcp.json").read_text())
    (run_dir / "spcp.json").write_text(json.dumps({**spcp, "step": spcp_step}))


def test_spcp_state_from_the_learning_curve(tmp_path: Path) -> None:
    run = make_run(tmp_path, "car_following", "pi1", 0, files=("config", "eval", "spcp"))
    _set_eval(run, [10.0, 12.0, 13.0], 30_000)  # best at the end
    t = read_training(run)
    assert t.still_improving and t.status == "may still improve: SPCP is the last candidate"
    _set_eval(run, [10.0, 13.0, 12.9], 20_000)  # SE = 2 / sqrt(100) = 0.2: 0.5 SE below
    assert read_training(run).status == "plateau: last candidate within 0.5 SE of the SPCP"
    _set_eval(run, [10.0, 13.0, 11.0], 20_000)  # 10 SE below
    t = read_training(run)
    assert not t.still_improving and t.status == "peaked: last candidate 10.0 SE below the SPCP"


def test_small_budget_report_says_so_first(tmp_path: Path) -> None:
    for vut in ("pi1", "pi2"):
        for seed in (0, 1):
            _set_budget(make_run(tmp_path / "runs", "car_following", vut, seed), 20_000, 5_000)
    html = write_report([tmp_path / "runs"], tmp_path / "out", options=FAST)
    md = (tmp_path / "out" / "summary.md").read_text()
    first = md.split("## Verdicts")[0]
    assert "Small training budget: 20,000 transitions per run" in first
    assert "NOT to be trusted" in first
    assert "| total_timesteps | eval_every |" in md and "| 20,000 | 5,000 |" in md
    assert "NOT to be trusted" in html.read_text()
    assert str(tmp_path) not in md  # run folders relative to the report
    assert "../runs/car_following/pi1/seed_0" in md


def test_full_budget_gives_no_budget_warning(tmp_path: Path) -> None:
    run = make_run(tmp_path, "car_following", "pi1", 0, files=("config", "eval", "spcp"))
    _set_budget(run, 100_000)
    _set_eval(run, [10.0, 13.0, 11.0], 20_000)
    assert trust_warnings([("r", read_training(run))]) == []


def test_duplicate_case_vut_seed_is_refused_naming_both(tmp_path: Path) -> None:
    a = make_run(tmp_path / "a", "car_following", "pi1", 0)
    b = make_run(tmp_path / "b", "car_following", "pi1", 0)
    make_run(tmp_path / "b", "car_following", "pi2", 0)
    with pytest.raises(ConfigError, match="car_following pi1 seed 0 appears 2 times") as exc:
        write_report([tmp_path / "a", tmp_path / "b"], tmp_path / "out", options=FAST)
    assert a.name in str(exc.value) and str(b.parent.parent.parent.name) in str(exc.value)


def test_different_budgets_in_one_case_are_refused(tmp_path: Path) -> None:
    _set_budget(make_run(tmp_path / "runs", "car_following", "pi1", 0), 4_000)
    _set_budget(make_run(tmp_path / "runs", "car_following", "pi1", 1), 20_000)
    _set_budget(make_run(tmp_path / "runs", "car_following", "pi2", 0), 20_000)
    with pytest.raises(ConfigError, match="different training budgets") as exc:
        write_report([tmp_path / "runs"], tmp_path / "out", options=FAST)
    assert "total_timesteps=4000" in str(exc.value) and "pi1/seed_0" in str(exc.value)


def test_different_cases_may_have_different_configs(tmp_path: Path) -> None:
    _set_budget(make_run(tmp_path / "runs", "car_following", "pi1", 0), 100_000)
    _set_budget(make_run(tmp_path / "runs", "cut_in", "pi1", 0), 150_000)
    assert write_report([tmp_path / "runs"], tmp_path / "out", options=FAST).is_file()
