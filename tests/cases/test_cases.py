"""The case registry (:mod:`sumo_ayss.cases`): lookups, the record's checks, the built-in
cases against their envs, and a toy third case that configuration, analysis and report
pick up without an edit elsewhere (no SUMO run)."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from sumo_ayss.cases import (
    BASE_OBSERVATION,
    Case,
    Indicator,
    PaperRow,
    case_info,
    case_names,
    case_of_indicator,
    get_case,
    indicator_columns,
    register_case,
    registered_cases,
    unregister_case,
)
from sumo_ayss.config import (
    ActuatorConfig,
    AyssConfig,
    EnvConfig,
    GridConfig,
    PipelineConfig,
    SimConfig,
)
from sumo_ayss.records.table import Table, write_table
from sumo_ayss.run_folder import AYSS_SCHEMA, RunFolder
from sumo_ayss.util.errors import ConfigError

BUILTIN = ("car_following", "cut_in", "lead_and_cut_in")

TOY = Case(
    name="toy_merge",
    title="Toy on-ramp merge",
    network="straight_2lane",
    lanes=2,
    lane_change=True,
    observation=(*BASE_OBSERVATION, "same_lane", "ramp_left_m"),
    ayss_fixed_obs=(0.0, 50.0),
    indicator_column="toy_closing_mps",
    indicator=Indicator("closing speed", "m/s", "close in {amount} faster (toy)"),
    axis_label="closing speed [m/s]",
    symbol="closing speed",
    outcome_columns=("crash", "lane_change", "return_all", "headway_all"),
    outcome_note="Toy outcome note.",
    paper_figure="Fig. 99",
    paper_table="Table IX",
    paper_rows=(PaperRow("pi1", 1, 5.0, 50.0, 12.34, 1.0),),
    exposure_caution="Toy exposure caution.",
)
"""A third case at the data level: no env, no AYSS row builder (they would need SUMO)."""


@pytest.fixture
def toy() -> Iterator[Case]:
    register_case(TOY)
    try:
        yield TOY
    finally:
        unregister_case(TOY.name)


# --------------------------------------------------------------------------- the registry


def test_builtin_cases_are_registered_in_order() -> None:
    assert case_names() == BUILTIN
    assert [c.name for c in registered_cases()] == list(BUILTIN)
    assert indicator_columns() == (
        "pov_accel_mps2",
        "delta_v_bar_mps",
        "delta_v_bar_primary_mps",
    )
    assert case_of_indicator("delta_v_bar_mps") == "cut_in" and case_of_indicator("x") is None


def test_the_case_package_is_a_leaf() -> None:
    """Configuration, analysis and report read it: it imports nothing heavy and no other
    layer of the package (the env class and the row builder are import paths)."""
    from tests.helpers import loaded_among, modules_loaded_by

    heavy = ("torch", "libsumo", "traci", "stable_baselines3", "matplotlib")
    assert loaded_among("import sumo_ayss.cases", heavy) == []
    ours = {m for m in modules_loaded_by("import sumo_ayss.cases") if m.startswith("sumo_ayss")}
    assert ours == {
        "sumo_ayss",
        "sumo_ayss.cases",
        "sumo_ayss.cases.car_following",
        "sumo_ayss.cases.cut_in",
        "sumo_ayss.cases.lead_and_cut_in",
        "sumo_ayss.cases.registry",
        "sumo_ayss.util",  # a docstring only (tests/test_layers.py checks it)
        "sumo_ayss.util.registry",  # the registry type, shared with the ranking modes
        "sumo_ayss.util.errors",
        "sumo_ayss.util.validation",
    }


def test_get_case_names_the_registered_cases() -> None:
    assert get_case("cut_in").lanes == 2
    with pytest.raises(ConfigError, match=r"unknown case 'cut-in' \(did you mean 'cut_in'\?\); "):
        get_case("cut-in")
    with pytest.raises(
        ConfigError, match=r"allowed: \['car_following', 'cut_in', 'lead_and_cut_in'\]"
    ):
        get_case("merge")


def test_case_info_describes_an_unknown_case_generically() -> None:
    assert case_info("cut_in") is get_case("cut_in")
    info = case_info("some case")
    assert info.title == "some case" and info.paper_rows == () and not info.lane_change
    with pytest.raises(ConfigError, match="no env"):
        info.env_class()


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"name": "Cut In"}, "case name must be lower-case"),
        ({"lanes": 0}, "lanes must be >= 1"),
        ({"observation": ("h_m", "v_pov_mps", "v_vut_mps")}, "observation must start with"),
        ({"ayss_fixed_obs": ()}, r"ayss_fixed_obs must give one value per .*\['same_lane'\]"),
        ({"outcome_columns": ("crash", "headwy")}, r"'headwy' \(did you mean 'headway'\?\)"),
        ({"env": "sumo_ayss.envs.cut_in.CutInEnv"}, "env must be 'package.module:name'"),
    ],
)
def test_case_record_is_checked(change: dict[str, object], message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        dataclasses.replace(get_case("cut_in"), **change)  # type: ignore[arg-type]


def test_register_refuses_a_taken_name_or_indicator(toy: Case) -> None:
    assert register_case(toy) is toy  # the same record again: a no-op
    with pytest.raises(ConfigError, match="'toy_merge' is already registered"):
        register_case(dataclasses.replace(toy, title="another"))
    with pytest.raises(ConfigError, match="indicator column 'delta_v_bar_mps' is case 'cut_in'"):
        register_case(dataclasses.replace(toy, name="toy2", indicator_column="delta_v_bar_mps"))
    assert case_names() == (*BUILTIN, "toy_merge")


def test_builtin_cases_match_their_envs() -> None:
    import gymnasium as gym

    from sumo_ayss.sim.network import network_path

    for case in registered_cases():
        cls = case.env_class()
        assert case.name == cls.CASE
        env = cls(EnvConfig(case=case.name))  # SUMO starts at the first reset only
        try:
            assert env.observation_space.shape == (len(case.observation),)
            assert 0 <= cls.RESPONSE_ACTION < env.action_space.n
        finally:
            env.close()
        assert network_path(case.name).is_file()
        assert gym.spec(case.gym_id).entry_point == case.env
        assert callable(case.ayss_row_builder())


# --------------------------------------------------------------------------- a third case


def test_configuration_accepts_a_registered_case(toy: Case) -> None:
    assert EnvConfig(case=toy.name).case == toy.name
    with pytest.raises(
        ConfigError, match=r"\['car_following', 'cut_in', 'lead_and_cut_in', 'toy_merge'\]"
    ):
        EnvConfig(case="toy")
    with pytest.raises(ConfigError, match=r"highway_env in toy_merge: the POV's free lateral"):
        EnvConfig(case=toy.name, actuator=ActuatorConfig(mode="highway_env"))
    EnvConfig(
        case=toy.name,
        actuator=ActuatorConfig(mode="highway_env"),
        sim=SimConfig(lateral_resolution_m=0.1),
    )
    assert GridConfig(cases=(toy.name,)).cases == (toy.name,)
    pipeline = PipelineConfig()  # the default grid: every registered case but the opt-in
    assert pipeline.grid.cases == ("car_following", "cut_in", toy.name)
    assert pipeline.experiments[toy.name].name == "toy_merge.yaml"


def test_the_toy_case_is_sampled_but_has_no_env(toy: Case) -> None:
    from sumo_ayss.envs import make_env
    from sumo_ayss.scenarios.ayss import sample_observations

    obs = sample_observations(AyssConfig(n_samples=50, seed=1), toy.name)
    assert obs.shape == (50, 5)
    assert (obs[:, 3] == 0.0).all() and (obs[:, 4] == 50.0).all()
    assert np.array_equal(
        obs[:, :3], sample_observations(AyssConfig(n_samples=50, seed=1), "car_following")
    )
    with pytest.raises(ConfigError, match="case 'toy_merge' has no env"):
        make_env(EnvConfig(case=toy.name))


def _toy_ayss(folder: RunFolder, vut: str, seed: int) -> None:
    rng = np.random.default_rng([seed, len(vut)])
    n = 300
    h = np.round(rng.uniform(0.0, 5.0, n), 4)
    y = -1.0 - 0.2 * h - 1.5 * (vut == "pi2") + rng.normal(0.0, 0.5, n)
    columns = {
        "sample": np.arange(n),
        "v_pov_mps": np.full(n, 20.0),
        "v_vut_mps": np.full(n, 22.0),
        "h_m": h,
        "same_lane": np.zeros(n, dtype=int),
        "action": np.zeros(n, dtype=int),
        "target_speed_mps": np.full(n, 20.0),
        "ttc_s": np.full(n, 2.5),
        "indicator_name": np.full(n, TOY.indicator_column),
        "indicator": np.round(y, 4),
        "h_after_m": np.full(n, np.nan),
        "delta_v_bar_before_mps": np.full(n, np.nan),
    }
    write_table(folder.ayss_csv, Table(AYSS_SCHEMA, columns))


def test_analysis_and_report_word_a_registered_case(toy: Case, tmp_path: Path) -> None:
    from sumo_ayss.report import ReportOptions, write_report
    from tests.report.test_report import make_run

    for vut in ("pi1", "pi2"):
        for seed in range(3):
            files = ("config", "eval", "spcp", "outcome", "versions")
            path = make_run(tmp_path, toy.name, vut, seed, files=files)
            _toy_ayss(RunFolder(path), vut, seed)
    report = write_report([tmp_path], options=ReportOptions(n_boot=200))
    text = (report.parent / "summary.md").read_text(encoding="utf-8")
    assert "Toy on-ramp merge (toy_merge)" in text
    assert "Aggressiveness vs headway (Fig. 99 equivalent)" in text
    assert "| mean closing speed |" in text
    assert "Outcome of each SPCP (Table IX)" in text and "12.34" in text  # the paper's row
    assert "lane-change rate lc [%]" in text and "r̄_epi (all)" in text
    assert "Toy outcome note." in text and "Toy exposure caution." in text
    assert "pi2 is safer than pi1: its SPCPs close in" in text and "(toy)" in text
    assert "belongs to" not in text  # the toy indicator is recognised as the toy case's
