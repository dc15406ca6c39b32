"""SPCP selection is the argmax of the evaluation table; ties go to the earliest candidate."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from sumo_ayss.training.selection import select_spcp
from sumo_ayss.util.errors import ConfigError


def rows(returns, crashes=None):
    crashes = crashes or [0.0] * len(returns)
    return [
        {"step": 1000 * (i + 1), "mean_return": r, "crash_rate": c}
        for i, (r, c) in enumerate(zip(returns, crashes, strict=True))
    ]


@given(st.lists(st.floats(-100, 100), min_size=1, max_size=30))
def test_selected_is_the_argmax_and_earliest_on_ties(returns) -> None:
    choice = select_spcp(rows(returns))
    assert choice.score == max(returns)
    assert choice.index == returns.index(max(returns))
    assert choice.step == 1000 * (choice.index + 1)


def test_tie_is_documented_in_the_reason() -> None:
    choice = select_spcp(rows([1.0, 3.0, 3.0, 2.0]))
    assert choice.step == 2000
    assert "2 tied, the earliest wins" in choice.reason


def test_crash_free_criterion_skips_candidates_that_crash() -> None:
    table = rows([5.0, 4.0, 3.0], crashes=[0.01, 0.0, 0.0])
    assert select_spcp(table).step == 1000
    assert select_spcp(table, "mean_reward_crash_free").step == 2000


def test_bad_input() -> None:
    with pytest.raises(ConfigError, match=r"train\.selection must be one of"):
        select_spcp(rows([1.0]), "median")
    with pytest.raises(ConfigError, match="empty evaluation table"):
        select_spcp([])
