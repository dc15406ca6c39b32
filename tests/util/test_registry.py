"""One registry type for the cases and the ranking modes."""

from __future__ import annotations

import pytest

from sumo_ayss.cases import registry as case_registry
from sumo_ayss.modes import registry as mode_registry
from sumo_ayss.util.errors import ConfigError
from sumo_ayss.util.registry import Registry


def test_records_keep_their_order_and_unknown_names_are_refused_by_name() -> None:
    r: Registry[int] = Registry("widget")
    r.register("one", 1)
    r.register("two", 2)
    r.register("one", 1)  # the same record again: a no-op
    assert r.names() == ("one", "two") and r.records() == (1, 2) and list(r) == [1, 2]
    assert "one" in r and r.find("three") is None and r.get("two") == 2
    with pytest.raises(ConfigError, match=r"widget 'one' is already registered"):
        r.register("one", 11)
    assert r.register("one", 11, replace=True) == 11
    with pytest.raises(ConfigError, match=r"unknown widget 'tow' \(did you mean 'two'\?\)"):
        r.get("tow")
    assert r.unregister("two") == 2 and r.names() == ("one",)
    with pytest.raises(ConfigError, match=r"allowed: \['one'\]"):
        r.unregister("two")


def test_cases_and_modes_share_the_registry_type() -> None:
    assert type(case_registry._REGISTRY) is Registry
    assert type(mode_registry._REGISTRY) is Registry
    assert case_registry._REGISTRY.names() == case_registry.case_names()
    assert mode_registry._REGISTRY.names() == mode_registry.mode_names()
