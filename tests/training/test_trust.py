"""Report guards: budget and SPCP state shown, small budgets flagged, mixed runs refused."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from sumo_ayss.config.budget import BUDGETS
from sumo_ayss.report import write_report
from sumo_ayss.run_folder import (
    RunConfig,
    RunFolder,
    read_run,
    read_run_config,
    write_eval_table,
    write_run_config,
    write_spcp,
)
from sumo_ayss.training.selection import Selection
from sumo_ayss.training.trust import (
    Training,
    budget_note,
    fewest_seeds,
    mixing_problems,
    training_status,
    trust_warnings,
    validated_budget,
)
from sumo_ayss.util.errors import ConfigError
from tests.report.test_report import FAST, make_run


def _set_budget(run_dir: Path, total: int, every: int = 10_000) -> None:
    folder = RunFolder(run_dir)
    config = read_run_config(folder.config)
    train = {"total_timesteps": total, "eval_every": every}
    write_run_config(
        folder.config, RunConfig(config.vut, config.seed, {**config.experiment, "train": train})
    )


def _set_eval(run_dir: Path, returns: list[float], spcp_step: int) -> None:
    folder = RunFolder(run_dir)
    rows = [
        {
            "step": 10_000 * (k + 1),
            "mean_return": r,
            "std_return": 2.0,
            "crash_rate": 0.0,
            "lane_change_rate": 0.0,
            "mean_final_headway_m": 2.0,
            "n_episodes": 100,
            "wall_s": 1.0,
            "checkpoint": folder.checkpoint_model(folder.step_dir(10_000 * (k + 1))),
        }
        for k, r in enumerate(returns)
    ]
    write_eval_table(folder.eval_table, rows)
    row = next(r for r in rows if r["step"] == spcp_step)
    choice = Selection(rows.index(row), spcp_step, row["mean_return"], "mean_reward", "best")
    write_spcp(folder.spcp_json, choice, row["checkpoint"], row)


def test_spcp_state_from_the_learning_curve(tmp_path: Path) -> None:
    run = make_run(tmp_path, "car_following", "pi1", 0, files=("config", "eval", "spcp"))
    _set_eval(run, [10.0, 12.0, 13.0], 30_000)  # best at the end
    t = read_run(run).training
    assert t.still_improving
    assert training_status(t) == "may still improve: SPCP is the last candidate"
    _set_eval(run, [10.0, 13.0, 12.9], 20_000)  # SE = 2 / sqrt(100) = 0.2: 0.5 SE below
    t = read_run(run).training
    assert training_status(t) == "plateau: last candidate within 0.5 SE of the SPCP"
    _set_eval(run, [10.0, 13.0, 11.0], 20_000)  # 10 SE below
    t = read_run(run).training
    assert not t.still_improving
    assert training_status(t) == "peaked: last candidate 10.0 SE below the SPCP"


def test_small_budget_report_says_so_first(tmp_path: Path) -> None:
    for vut in ("pi1", "pi2"):
        for seed in (0, 1):
            _set_budget(make_run(tmp_path / "runs", "car_following", vut, seed), 2_500, 1_250)
    html = write_report([tmp_path / "runs"], tmp_path / "out", options=FAST)
    md = (tmp_path / "out" / "summary.md").read_text()
    first = md.split("## Verdicts")[0]
    assert "Small training budget: 2,500 transitions per run" in first
    assert "below the 5,000 of the smallest budget" in first  # 'fast' (issue 40)
    assert "NOT to be trusted" in first
    assert "| total_timesteps | eval_every |" in md and "| 2,500 | 1,250 |" in md
    assert "NOT to be trusted" in html.read_text()
    assert str(tmp_path) not in md  # run folders relative to the report
    assert "../runs/car_following/pi1/seed_0" in md


def test_full_budget_gives_no_budget_warning(tmp_path: Path) -> None:
    run = make_run(tmp_path, "car_following", "pi1", 0, files=("config", "eval", "spcp"))
    _set_budget(run, 100_000)
    _set_eval(run, [10.0, 13.0, 11.0], 20_000)
    assert trust_warnings([("r", read_run(run).training)]) == []


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


def test_too_few_seeds_for_the_budget_are_named() -> None:
    """A named budget is validated with its seeds: 20,000 transitions needs 4 per VUT,
    100,000 needs 3; fewer seeds at that budget warn (low power), enough do not."""
    t20 = Training(20_000, 5_000, "k", 4, 20_000, 20_000, 0.0, False)
    t100 = Training(100_000, 10_000, "k", 10, 60_000, 100_000, 5.0, False)
    few = trust_warnings([("a", t20)], seeds_per_vut=2)
    assert len(few) == 1 and few[0].startswith("Few training seeds: 2 per VUT at 20,000")
    assert "4 at 20,000 (verdict)" in few[0] and "3 at 100,000 (paper)" in few[0]
    assert "5 at 10,000 (quick)" in few[0]
    t10 = Training(10_000, 5_000, "k", 2, 10_000, 10_000, 0.0, False)
    assert trust_warnings([("a", t10)], seeds_per_vut=5) == []
    assert trust_warnings([("a", t10)], seeds_per_vut=4)[0].startswith("Few training seeds")
    assert trust_warnings([("a", t20)], seeds_per_vut=4) == []
    assert trust_warnings([("a", t100)], seeds_per_vut=3) == []
    assert trust_warnings([("a", t100)], seeds_per_vut=2)[0].startswith("Few training seeds")
    assert fewest_seeds([("cut_in", "a"), ("cut_in", "a"), ("cut_in", "b")]) == 1
    assert fewest_seeds([]) is None


def test_default_budget_first_screen_claims_nothing_the_verdict_curve_contradicts(
    tmp_path: Path,
) -> None:
    """At the verdict budget (20,000 transitions, 4 seeds) with SPCPs that were the last
    candidate, the first screen says what was validated and what not, once; it does not say
    that more training could change the verdicts (the verdict curve found the ranking
    unchanged by it), and the run list sits in the inputs section, folded."""
    for vut in ("pi1", "pi2"):
        for seed in range(4):
            run = make_run(tmp_path / "runs", "car_following", vut, seed)
            _set_budget(run, 20_000, 5_000)
            _set_eval(run, [10.0, 12.0, 13.0], 30_000)  # the SPCP is the last candidate
    write_report([tmp_path / "runs"], tmp_path / "out", options=FAST)
    md = (tmp_path / "out" / "summary.md").read_text()
    first = md.split("## Verdicts")[0]
    assert "more training could change" not in md
    assert first.count("Validated at this budget") == 1
    assert "8 of 8 SPCPs were the last candidate" in first
    assert "car_following pi1 seed 0" not in first  # the list is in Inputs
    inputs = md.split("## Inputs")[1]
    assert "SPCPs that were the last candidate of their training (8 of 8)" in inputs
    assert "car_following pi1 seed 0" in inputs


def test_unvalidated_budget_still_warns_about_improving_spcps() -> None:
    improving = Training(50_000, 5_000, "k", 10, 50_000, 50_000, 0.0, True)
    warnings = trust_warnings([("a", improving)], seeds_per_vut=2)
    assert warnings[0].startswith("Few training seeds")
    assert "more training could change them" in warnings[-1]
    assert trust_warnings([("a", improving)], seeds_per_vut=4) == []


def test_runs_that_must_not_be_pooled_are_named() -> None:
    t = Training(total_timesteps=1000, eval_every=500, config_key="k")
    ok = [("car_following", v, s, f"{v}/{s}", t) for v in ("pi1", "pi2") for s in (0, 1)]
    assert mixing_problems(ok) == []
    twice = [*ok, ("car_following", "pi1", 0, "elsewhere/pi1/0", t)]
    assert mixing_problems(twice) == [
        "car_following pi1 seed 0 appears 2 times: pi1/0, elsewhere/pi1/0"
    ]
    other = Training(total_timesteps=2000, eval_every=500, config_key="k")
    budgets = mixing_problems([*ok, ("car_following", "pi3", 0, "pi3/0", other)])
    assert len(budgets) == 1 and "different training budgets" in budgets[0]


def test_a_budget_counts_only_at_the_learning_rate_it_was_validated_with() -> None:
    """'fast' was validated at 5e-5: 5,000 transitions at the paper's 1e-5 is another
    protocol, named as such; a run whose learning rate is unknown is not held against it."""
    fast = Training(5_000, 5_000, "k", 1, 5_000, 5_000, 0.0, True, 5e-5)
    assert trust_warnings([("a", fast)], seeds_per_vut=5) == []
    found = validated_budget([("a", fast)], 5)
    assert found is not None and found[0] == "fast"
    note = budget_note([("a", fast)], 5)
    assert note is not None and "learning rate 5e-05" in note and "fresh seeds" in note
    assert "10,000 to 100,000" not in note
    slow = dataclasses.replace(fast, learning_rate=1e-5)
    warnings = trust_warnings([("a", slow)], seeds_per_vut=5)
    assert warnings[0].startswith("Learning rate 1e-05 at 5,000 transitions per run")
    assert "trained at 5e-05 (fast)" in warnings[0]
    assert "more training could change them" in warnings[-1]
    assert validated_budget([("a", slow)], 5) is None and budget_note([("a", slow)], 5) is None
    unknown = dataclasses.replace(fast, learning_rate=None)
    assert trust_warnings([("a", unknown)], seeds_per_vut=5) == []
    t20 = Training(20_000, 5_000, "k", 4, 20_000, 20_000, 0.0, False, 5e-5)
    assert trust_warnings([("a", t20)], seeds_per_vut=4)[0].startswith("Learning rate 5e-05")
    assert validated_budget([("a", t20)], 5) == ("fast", BUDGETS["fast"])  # 5 seeds: fast's
    t20_paper = dataclasses.replace(t20, learning_rate=1e-5)
    assert validated_budget([("a", t20_paper)], 4) == ("verdict", BUDGETS["verdict"])


def test_a_run_folder_records_its_learning_rate(tmp_path: Path) -> None:
    run = make_run(tmp_path, "car_following", "pi1", 0, files=("config", "eval", "spcp"))
    assert read_run(run).training.learning_rate is None  # its config.yaml names none
    folder = RunFolder(run)
    config = read_run_config(folder.config)
    agent = {**config.experiment["agent"], "learning_rate": 5e-5}
    write_run_config(
        folder.config, RunConfig(config.vut, config.seed, {**config.experiment, "agent": agent})
    )
    assert read_run(run).training.learning_rate == 5e-5
