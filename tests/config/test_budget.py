"""Named budgets (config.budget): what a pipeline trains when its YAML names one, or none."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from sumo_ayss.agents.hparams import DQNHyperParams
from sumo_ayss.config import load_pipeline
from sumo_ayss.config.budget import BUDGETS, DEFAULT_BUDGET, PAPER_LEARNING_RATE
from sumo_ayss.pipeline import plan_jobs
from sumo_ayss.util.errors import ConfigError
from sumo_ayss.util.paths import PROJECT_ROOT


def _yaml(tmp_path: Path, **data: object) -> Path:
    path = tmp_path / "p.yaml"
    base = {"grid": {"cases": ["cut_in"], "vuts": ["pi1"]}, "out": "out"}
    path.write_text(yaml.safe_dump(base | data))
    return path


def _trained(path: Path, **overrides: object) -> tuple[set[int], set[int], tuple[int, ...]]:
    cfg = load_pipeline(path, **overrides)
    jobs = plan_jobs(cfg)
    return (
        {j.experiment.train.total_timesteps for j in jobs},
        {j.experiment.train.eval_every for j in jobs},
        tuple(sorted({j.seed for j in jobs})),
    )


def test_a_pipeline_that_names_no_budget_trains_the_default_one(tmp_path: Path) -> None:
    b = BUDGETS[DEFAULT_BUDGET]
    total, every, seeds = _trained(_yaml(tmp_path))
    assert (total, every, seeds) == ({b.total_timesteps}, {b.eval_every}, tuple(range(b.seeds)))
    assert DEFAULT_BUDGET == "fast" and b.total_timesteps < BUDGETS["paper"].total_timesteps
    assert {
        j.experiment.agent.learning_rate for j in plan_jobs(load_pipeline(_yaml(tmp_path)))
    } == {5e-5}


def test_the_paper_budget_is_the_papers_protocol(tmp_path: Path) -> None:
    assert _trained(_yaml(tmp_path, budget="paper")) == ({100_000}, {10_000}, (0, 1, 2))


def test_given_settings_win_over_the_budget(tmp_path: Path) -> None:
    path = _yaml(tmp_path, budget="paper", total_timesteps=3000, eval_every=1500)
    data = yaml.safe_load(path.read_text())
    data["grid"]["seeds"] = [7]
    path.write_text(yaml.safe_dump(data))
    assert _trained(path) == ({3000}, {1500}, (7,))


def test_no_budget_keeps_each_experiments_train_section(tmp_path: Path) -> None:
    exp = yaml.safe_load((PROJECT_ROOT / "configs/cut_in.yaml").read_text())["train"]
    total, every, seeds = _trained(_yaml(tmp_path, budget=None))
    assert (total, every, seeds) == ({exp["total_timesteps"]}, {exp["eval_every"]}, (0, 1, 2))


def test_the_command_line_budget_replaces_the_yamls(tmp_path: Path) -> None:
    path = _yaml(tmp_path, budget="paper")
    b = BUDGETS["verdict"]
    assert _trained(path, budget="verdict")[0] == {b.total_timesteps}
    assert _trained(path, budget="none")[0] == {100_000}  # configs/cut_in.yaml's own


def test_an_unknown_budget_is_refused_with_the_allowed_names(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match=r"budget.*paper.*verdict|budget.*verdict.*paper"):
        load_pipeline(_yaml(tmp_path, budget="fastest"))


def test_an_empty_seed_list_is_still_refused(tmp_path: Path) -> None:
    path = _yaml(tmp_path)
    data = yaml.safe_load(path.read_text())
    data["grid"]["seeds"] = []
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(ConfigError, match=r"grid\.seeds must not be empty"):
        load_pipeline(path)


@pytest.mark.parametrize(
    "config",
    [
        "paper.yaml",
        "paper_fidelity.yaml",
        "ladders/braking.yaml",
        "ladders/time_headway.yaml",
        "ladders/min_gap.yaml",
        "ladders/acc_time_gap.yaml",
        "ladders/reaction.yaml",
        "fidelity_ablation/sumo_vut.yaml",
        "fidelity_ablation/clipped_pov.yaml",
    ],
)
def test_committed_studies_still_train_what_they_ran(config: str) -> None:
    """Their results were made at 100,000 transitions with a candidate every 10,000 and
    three seeds; the default budget must not change what rerunning them does."""
    path = PROJECT_ROOT / "configs" / config
    total, every, seeds = _trained(path)
    assert (total, every, len(seeds)) == ({100_000}, {10_000}, 3)
    assert seeds == tuple(sorted(yaml.safe_load(path.read_text())["grid"]["seeds"]))


def test_the_verdict_budget_draws_fewer_ayss_samples_unless_told(tmp_path: Path) -> None:
    verdict = load_pipeline(_yaml(tmp_path, budget="verdict"))
    assert verdict.evaluate.ayss.n_samples == BUDGETS["verdict"].n_ayss == 20_000
    assert load_pipeline(_yaml(tmp_path, budget="paper")).evaluate.ayss.n_samples == 100_000
    told = load_pipeline(_yaml(tmp_path, evaluate={"n_ayss": 5000}))
    assert told.evaluate.ayss.n_samples == 5000
    told = load_pipeline(_yaml(tmp_path, evaluate={"ayss": {"n_samples": 7000}}))
    assert told.evaluate.ayss.n_samples == 7000


def test_adaptive_seeding_cap_comes_with_the_budgets_seeds_only(tmp_path: Path) -> None:
    """The verdict budget's seeds may grow to its cap; named seeds make a fixed grid unless
    max_seeds is given; a cap below the seeds is refused by name."""
    path = _yaml(tmp_path, budget="verdict")
    cfg = load_pipeline(path)
    assert cfg.seeds == (0, 1, 2, 3) and cfg.max_seeds == BUDGETS["verdict"].max_seeds == 6
    assert cfg.added_seeds == (4, 5)
    fixed = load_pipeline(path, seeds=[401, 402, 403, 404])
    assert fixed.max_seeds == 4 and fixed.added_seeds == ()
    grown = load_pipeline(path, seeds=[401, 402, 403, 404], max_seeds=6)
    assert grown.added_seeds == (405, 406)
    assert load_pipeline(path, budget="paper").added_seeds == ()
    with pytest.raises(ConfigError, match=r"max_seeds must be an integer from the 4 seeds"):
        load_pipeline(path, max_seeds=3)
    assert (
        load_pipeline(
            _yaml(tmp_path, grid={"cases": ["cut_in"], "vuts": ["pi1"], "seeds": [0, 1]})
        ).max_seeds
        == 2
    )
    with pytest.raises(ConfigError, match="max_seeds"):
        load_pipeline(_yaml(tmp_path, max_seeds="six"))


def test_the_quick_budget_trains_half_the_transitions_with_one_seed_more(tmp_path: Path) -> None:
    """``quick`` (issue 40): 10,000 transitions, a candidate every 5,000, seeds 0-4 growing to
    7 where the ranking has not settled; the default stays ``verdict``."""
    path = _yaml(tmp_path, budget="quick")
    assert _trained(path) == ({10_000}, {5_000}, (0, 1, 2, 3, 4))
    cfg = load_pipeline(path)
    assert cfg.max_seeds == 7 and cfg.added_seeds == (5, 6)
    assert cfg.evaluate.ayss.n_samples == 20_000
    assert _trained(_yaml(tmp_path))[0] == {5_000}  # the default: fast


def _learning_rates(path: Path, **overrides: object) -> set[float]:
    return {j.experiment.agent.learning_rate for j in plan_jobs(load_pipeline(path, **overrides))}


def test_the_fast_budget_trains_a_quarter_of_the_transitions_at_a_larger_learning_rate(
    tmp_path: Path,
) -> None:
    """``fast`` (issue 40): 5,000 transitions, one candidate, seeds 0-4 growing to 7, and
    the learner's learning rate 5e-5 in every experiment; a pipeline's own learning rate
    (YAML or ``--learning-rate``) wins, and no other budget touches the experiment's."""
    path = _yaml(tmp_path, budget="fast")
    assert _trained(path) == ({5_000}, {5_000}, (0, 1, 2, 3, 4))
    assert load_pipeline(path).added_seeds == (5, 6)
    assert _learning_rates(path) == {5e-5}
    assert _learning_rates(path, learning_rate=2e-5) == {2e-5}
    assert _learning_rates(_yaml(tmp_path, budget="fast", learning_rate=3e-5)) == {3e-5}
    for other in ("verdict", "quick", "paper"):
        assert _learning_rates(_yaml(tmp_path, budget=other)) == {1e-5}  # configs/cut_in.yaml
    assert _learning_rates(_yaml(tmp_path, budget="paper"), learning_rate=4e-5) == {4e-5}
    assert "learning rate 5e-05" in BUDGETS["fast"].describe()


def test_a_bad_learning_rate_is_refused_by_name(tmp_path: Path) -> None:
    for bad in (0.0, -1e-5):
        with pytest.raises(ConfigError, match=r"learning_rate must be in \(0, inf\)"):
            load_pipeline(_yaml(tmp_path, learning_rate=bad))


def test_the_papers_learning_rate_is_the_shipped_configs() -> None:
    """A budget without a learning rate was validated with the shipped configs' (trust)."""
    assert DQNHyperParams().learning_rate == PAPER_LEARNING_RATE
    for case in ("car_following", "cut_in", "lead_and_cut_in"):
        data = yaml.safe_load((PROJECT_ROOT / "configs" / f"{case}.yaml").read_text())
        assert data["agent"]["learning_rate"] == PAPER_LEARNING_RATE
    assert BUDGETS["verdict"].validated_learning_rate == PAPER_LEARNING_RATE
    assert BUDGETS["fast"].validated_learning_rate == 5e-5


def test_every_committed_pipeline_config_names_its_budget() -> None:
    """A study's config says what it trained: a change of the default budget (``verdict`` ->
    ``fast``, session 13) must not change what rerunning a committed study does."""
    unnamed = [
        str(path.relative_to(PROJECT_ROOT))
        for path in sorted((PROJECT_ROOT / "configs").rglob("*.yaml"))
        if "grid" in (data := yaml.safe_load(path.read_text()) or {}) and "budget" not in data
    ]
    assert unnamed == []
