"""Configuration: YAML overrides over typed defaults, clear errors naming the field."""

from __future__ import annotations

from pathlib import Path

import pytest

from sumo_ayss.config import (
    EnvConfig,
    OddConfig,
    env_config_from_mapping,
    read_yaml,
    to_dict,
)
from sumo_ayss.util.errors import ConfigError
from sumo_ayss.vuts.catalog import BUILTIN_VUTS


def test_defaults_are_the_paper() -> None:
    cfg = EnvConfig()
    assert cfg.max_decisions == 25 and cfg.steps_per_decision == 1
    assert cfg.actuator.accel_min_mps2 == -6.0 and cfg.actuator.accel_max_mps2 == 6.0
    assert cfg.reward.same_lane.peak_m == 0.25 and cfg.reward.same_lane.zero_m == 20.0
    assert cfg.reward.lane_change.peak_m == 1.0 and cfg.reward.lane_change.zero_m == 5.0
    assert BUILTIN_VUTS["pi1"].params["minGap"] == 5.0
    assert BUILTIN_VUTS["pi2"].params["minGap"] == 15.0


def test_yaml_overrides_merge_over_defaults(tmp_path: Path) -> None:
    cfg = env_config_from_mapping(
        {
            "vut": "mine",
            "vuts": {"mine": {"model": "Krauss", "params": {"minGap": 2.5, "sigma": 0.0}}},
            "odd": {"gap_m": [1, 10]},
            "reward": {"same_lane": {"kind": "quadratic"}},
        },
        tmp_path,
    )
    assert cfg.vut_type.model == "Krauss"
    assert set(cfg.vuts) == {"pi1", "pi2", "hwenv_pi1", "hwenv_pi2", "mine"}  # built-ins kept
    assert cfg.odd.gap_m == (1.0, 10.0)
    assert cfg.odd.vut_speed_mps == OddConfig().vut_speed_mps
    assert cfg.reward.same_lane.kind == "quadratic" and cfg.reward.same_lane.zero_m == 20.0


def test_round_trip_through_plain_dict(tmp_path: Path) -> None:
    cfg = env_config_from_mapping({"odd": {"gap_m": [3, 9]}, "vut": "pi2"}, tmp_path)
    again = env_config_from_mapping(to_dict(cfg), tmp_path)
    assert again == cfg


@pytest.mark.parametrize(
    ("data", "match"),
    [
        ({"odd": {"gap": [1, 2]}}, r"env\.odd: unknown key 'gap' \(did you mean 'gap_m'\?\)"),
        ({"rewrd": {}}, r"unknown key 'rewrd' \(did you mean 'reward'\?\)"),
        ({"odd": {"gap_m": [10, 2]}}, r"env\.odd\.gap_m must have min <= max"),
        ({"odd": {"gap_m": [1, 2, 3]}}, r"env\.odd\.gap_m must have 2 items"),
        (
            {"case": "merge"},
            r"env\.case must be one of \['car_following', 'cut_in', 'lead_and_cut_in'\]",
        ),
        (
            {"vut": "pi3"},
            r"env\.vut must be one of \['hwenv_pi1', 'hwenv_pi2', 'pi1', 'pi2'\], got 'pi3'",
        ),
        (
            {"vuts": {"x": {"model": "IDMX"}}},
            r"env\.vuts\.x\.model must be one of \[.*'IDM'.*\], got 'IDMX' \(did you mean",
        ),
        (
            {"vuts": {"x": {"model": "IDM", "params": {"minGap": -1}}}},
            r"env\.vuts\.x\.params\.minGap must be >= 0, got -1",
        ),
        (
            {"vuts": {"x": {"model": "IDM", "params": {"cc1": 1}}}},
            r"env\.vuts\.x\.params\.cc1 is not a parameter of SUMO model IDM.*allowed: \[",
        ),
        ({"network": "nope.net.xml"}, r"env\.network: file not found: .*nope\.net\.xml"),
        ({"sim": {"step_length_s": 0}}, r"env\.sim\.step_length_s must be > 0, got 0"),
        ({"decision_period_s": 0.3}, r"must be a positive multiple of sim\.step_length_s"),
        ({"actuator": {"accel_min_mps2": 1}}, r"env\.actuator\.accel_min_mps2 must be < 0"),
        ({"reward": {"same_lane": {"kind": "cubic"}}}, r"reward\.same_lane\.kind must be one"),
        ({"episode_s": "long"}, r"env\.episode_s must be a number, got 'long'"),
    ],
)
def test_bad_input_names_the_field(tmp_path: Path, data: dict, match: str) -> None:
    with pytest.raises(ConfigError, match=match):
        env_config_from_mapping(data, tmp_path)


def test_paths_resolve_relative_to_the_yaml_file(tmp_path: Path) -> None:
    from sumo_ayss.sim.network import NETWORK_DIR

    net = tmp_path / "nets" / "my.net.xml"
    net.parent.mkdir()
    net.write_text((NETWORK_DIR / "straight_1lane.net.xml").read_text())
    cfg_file = tmp_path / "sub" / "exp.yaml"
    cfg_file.parent.mkdir()
    cfg_file.write_text("env:\n  network: ../nets/my.net.xml\n")
    data = read_yaml(cfg_file)
    cfg = env_config_from_mapping(data["env"], cfg_file.parent)
    assert cfg.network == net.resolve()


def test_read_yaml_errors(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="config file not found"):
        read_yaml(tmp_path / "missing.yaml")
    bad = tmp_path / "bad.yaml"
    bad.write_text("- a\n- b\n")
    with pytest.raises(ConfigError, match="top level must be a mapping"):
        read_yaml(bad)


def test_odd_that_drives_off_the_road_is_refused() -> None:
    from sumo_ayss.envs.car_following import CarFollowingEnv

    with pytest.raises(ConfigError, match=r"env\.odd\.gap_m max .* beyond the 1000 m road"):
        CarFollowingEnv(config=EnvConfig(odd=OddConfig(gap_m=(2.0, 700.0))))
