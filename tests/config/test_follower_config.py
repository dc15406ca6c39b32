"""``env.follower`` (issue 33): defaults, YAML, and bad input named by its field."""

from __future__ import annotations

import pytest

from sumo_ayss.config import EnvConfig, FollowerConfig, env_config_from_mapping, to_dict
from sumo_ayss.config.follower import FOLLOWER_TYPE
from sumo_ayss.util.errors import ConfigError


def test_off_by_default_and_said_so_in_the_resolved_config() -> None:
    cfg = EnvConfig()
    assert cfg.follower.enabled is False
    assert to_dict(cfg)["follower"]["enabled"] is False
    on = env_config_from_mapping({"follower": {"enabled": True}})
    assert on.follower.enabled and on.follower.vtype == FOLLOWER_TYPE
    assert on.follower.sumo_type.params["treaction"] == 1.0


@pytest.mark.parametrize(
    ("section", "message"),
    [
        ({"time_headway_s": [-1.0, 2.0]}, r"env\.follower\.time_headway_s must be > 0 s"),
        ({"time_headway_s": [0.0, 2.0]}, r"starts the follower inside the VUT"),
        ({"reaction_s": -0.5}, r"env\.follower\.reaction_s must be a number > 0"),
        ({"reaction_s": 0}, r"env\.follower\.reaction_s must be a number > 0"),
        ({"vtype": {"model": "Gipps"}}, r"env\.follower\.vtype\.model must be one of"),
        ({"vtype": {"model": "IDM"}}, r"env\.follower\.vtype\.model must be one of \['EIDM'\]"),
        (
            {"vtype": {"model": "EIDM", "params": {"treaction": 1.0}}},
            r"env\.follower\.vtype\.params\.treaction: give the reaction time as "
            r"env\.follower\.reaction_s",
        ),
        (
            {"vtype": {"model": "EIDM", "params": {"minGap": -1.0}}},
            r"env\.follower\.vtype\.params\.minGap",
        ),
        ({"enabled": "yes"}, r"env\.follower\.enabled must be true or false"),
        ({"headway": [1, 2]}, r"env\.follower"),
    ],
)
def test_bad_follower_input_is_named(section, message) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ConfigError, match=message):
        env_config_from_mapping({"follower": section})


def test_a_controller_is_not_a_follower() -> None:
    with pytest.raises(ConfigError, match=r"env\.follower\.vtype"):
        env_config_from_mapping({"follower": {"vtype": {"controller": {"target": "full_braking"}}}})


def test_direct_construction_checks_too() -> None:
    with pytest.raises(ConfigError, match="reaction_s"):
        FollowerConfig(reaction_s=-1.0)
