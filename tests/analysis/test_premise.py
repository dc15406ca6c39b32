"""The premise check: equal overall outcomes across VUTs, against stated tolerances."""

from __future__ import annotations

import pytest

from sumo_ayss.analysis.premise import premise_check
from sumo_ayss.util.errors import ConfigError


def test_equal_outcomes_meet_the_premise():
    p = premise_check(
        {
            "mean_return": {"a": [19.8, 20.1, 20.0], "b": [19.6, 20.3, 19.9]},
            "crash_rate": {"a": [0.0, 0.005, 0.0], "b": [0.005, 0.0, 0.01]},
            "mean_final_headway_m": {"a": [2.4, 2.6, 2.5], "b": [3.9, 4.1, 4.3]},
        }
    )
    assert p.met and not p.failed()
    reward = p.metrics[0]
    assert reward.per_vut["a"][0] == pytest.approx(19.9667, abs=1e-4)
    assert reward.per_vut["a"][1] < reward.per_vut["a"][0] < reward.per_vut["a"][2]
    assert reward.per_vut["a"][3] == 3


def test_a_ladder_with_ordered_rewards_fails_it():
    # The minGap ladder with the clipped POV: rewards 12.6 > 11.7 > 10.5 > 9.7.
    p = premise_check({"mean_return": {"g2": [12.6], "g5": [11.7], "g10": [10.5], "g15": [9.7]}})
    assert not p.met
    assert p.failed()[0].spread == pytest.approx(2.9)


def test_tolerance_is_configurable_and_validated():
    values = {"mean_final_headway_m": {"a": [2.0, 2.2], "b": [5.0, 5.2]}}
    assert not premise_check(values).met
    assert premise_check(values, tolerances={"mean_final_headway_m": 3.5}).met
    with pytest.raises(ConfigError, match="unknown metric"):
        premise_check(values, tolerances={"reward": 1.0})
    with pytest.raises(ConfigError, match=">= 0"):
        premise_check(values, tolerances={"crash_rate": -1.0})


def test_one_vut_or_no_data_is_not_a_premise():
    p = premise_check({"mean_return": {"a": [1.0, 2.0]}, "crash_rate": {"a": [], "b": []}})
    assert p.metrics == () and not p.met
