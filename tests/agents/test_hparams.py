"""DQNHyperParams: paper defaults, validation messages, from_mapping."""

from __future__ import annotations

import dataclasses
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

from sumo_ayss.agents.hparams import DQNHyperParams
from sumo_ayss.util.errors import ConfigError


def test_defaults_are_the_papers() -> None:
    hp = DQNHyperParams()
    assert (hp.gamma, hp.learning_rate) == (0.8, 1e-5)
    assert hp.double and hp.dueling and hp.prioritized
    assert hp.feature_net_arch == hp.value_net_arch == hp.advantage_net_arch == (256, 256)
    assert (hp.per_alpha, hp.per_beta0, hp.per_beta_steps, hp.per_eps) == (0.6, 0.4, None, 1e-6)
    assert (hp.buffer_size, hp.batch_size, hp.learning_starts) == (100_000, 64, 1000)
    assert (hp.train_freq, hp.gradient_steps, hp.target_update_interval) == (4, 1, 1000)
    assert (hp.exploration_fraction, hp.exploration_initial_eps) == (0.3, 1.0)
    assert (hp.exploration_final_eps, hp.max_grad_norm) == (0.05, 10.0)
    assert hp.update_to_data_ratio == 0.25


def test_frozen_and_hashable() -> None:
    hp = DQNHyperParams()
    with pytest.raises(dataclasses.FrozenInstanceError):
        hp.gamma = 0.9  # type: ignore[misc]
    assert hash(hp) == hash(DQNHyperParams())


def test_gamma_message_exact() -> None:
    with pytest.raises(ConfigError, match=r"^agent\.gamma must be in \(0, 1\], got 1\.5$"):
        DQNHyperParams(gamma=1.5)


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("gamma", 0.0),
        ("gamma", float("nan")),
        ("learning_rate", 0.0),
        ("learning_rate", "1e-5"),
        ("double", 1),
        ("dueling", "yes"),
        ("prioritized", None),
        ("feature_net_arch", (256, 0)),
        ("value_net_arch", (256.0,)),
        ("advantage_net_arch", "256"),
        ("per_alpha", 1.5),
        ("per_beta0", -0.1),
        ("per_beta_steps", 0),
        ("per_beta_steps", 1.5),
        ("per_eps", 0.0),
        ("buffer_size", 0),
        ("buffer_size", True),
        ("batch_size", 64.0),
        ("learning_starts", -1),
        ("train_freq", 0),
        ("gradient_steps", 0),
        ("target_update_interval", 0),
        ("exploration_fraction", 1.2),
        ("exploration_initial_eps", -0.5),
        ("exploration_final_eps", 2.0),
        ("max_grad_norm", 0.0),
    ],
)
def test_bad_value_names_field(field: str, value: Any) -> None:
    with pytest.raises(ConfigError, match=rf"^agent\.{field} must be"):
        DQNHyperParams(**{field: value})


def test_config_error_is_value_error() -> None:
    with pytest.raises(ValueError, match=r"agent\.batch_size"):
        DQNHyperParams(batch_size=0)


def test_update_to_data_ratio() -> None:
    assert DQNHyperParams(train_freq=2, gradient_steps=3).update_to_data_ratio == 1.5


def test_from_mapping_accepts_lists_and_keeps_defaults() -> None:
    hp = DQNHyperParams.from_mapping({"gamma": 0.9, "feature_net_arch": [64, 32], "double": False})
    assert hp.feature_net_arch == (64, 32)
    assert hp.gamma == 0.9 and not hp.double
    assert hp.value_net_arch == (256, 256) and hp.batch_size == 64


def test_from_mapping_unknown_key_suggests() -> None:
    with pytest.raises(
        ConfigError, match=r"^agent: unknown key 'gama' \(did you mean 'gamma'\?\)"
    ) as err:
        DQNHyperParams.from_mapping({"gama": 0.9})
    assert "allowed: ['advantage_net_arch', 'batch_size', " in str(err.value)
    assert "'gamma', 'gradient_steps', 'learning_rate'" in str(err.value)


def test_from_mapping_unknown_key_without_close_match() -> None:
    with pytest.raises(ConfigError, match=r"^agent: unknown key 'zzz'; allowed: \["):
        DQNHyperParams.from_mapping({"zzz": 1})


def test_from_mapping_uses_prefix() -> None:
    with pytest.raises(ConfigError, match=r"^learner\.per_alpha must be in \[0, 1\], got 2"):
        DQNHyperParams.from_mapping({"per_alpha": 2}, prefix="learner")
    with pytest.raises(ConfigError, match=r"^learner: unknown key 'batchsize' \(did you mean"):
        DQNHyperParams.from_mapping({"batchsize": 2}, prefix="learner")


def test_from_mapping_rejects_non_mapping() -> None:
    with pytest.raises(ConfigError, match="agent must be a mapping"):
        DQNHyperParams.from_mapping([("gamma", 0.9)])  # type: ignore[arg-type]


def test_to_dict_round_trip() -> None:
    hp = DQNHyperParams(gamma=0.5, value_net_arch=(8,), per_beta_steps=1000)
    data = hp.to_dict()
    assert data["value_net_arch"] == [8]
    assert DQNHyperParams.from_mapping(data) == hp


@given(st.floats(min_value=0.0, max_value=1.0, exclude_min=True))
def test_any_gamma_in_unit_interval_is_valid(gamma: float) -> None:
    assert DQNHyperParams(gamma=gamma).gamma == gamma


@given(st.floats(min_value=1.0, exclude_min=True, allow_nan=False))
def test_gamma_above_one_is_rejected(gamma: float) -> None:
    with pytest.raises(ConfigError, match=r"^agent\.gamma must be in"):
        DQNHyperParams(gamma=gamma)
