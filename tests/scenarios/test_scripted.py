"""The scripted POV: reproducible per seed, refuses a case it was not written for."""

from __future__ import annotations

import numpy as np
import pytest

from sumo_ayss.scenarios.scripted import scripted_pov_action


def test_the_same_seed_gives_the_same_actions() -> None:
    obs = np.array([20.0, 20.0, 30.0], dtype=np.float32)
    runs = [
        [scripted_pov_action("cut_in", np.random.default_rng(7), obs, t, 3) for t in range(10)]
        for _ in range(2)
    ]
    assert runs[0] == runs[1]
    assert runs[0][3] == 0  # the lane change at its drawn decision
    assert all(1 <= a <= 41 for i, a in enumerate(runs[0]) if i != 3)


def test_car_following_actions_stay_in_its_action_space() -> None:
    rng = np.random.default_rng(0)
    obs = np.zeros(3, dtype=np.float32)
    acts = {scripted_pov_action("car_following", rng, obs, t, -1) for t in range(500)}
    assert acts == {0, 1, 2, 3}


def test_an_unknown_case_is_refused_by_name() -> None:
    with pytest.raises(ValueError, match="case: the scripted POV drives car_following, cut_in"):
        scripted_pov_action("lead_and_cut_in", np.random.default_rng(0), np.zeros(3), 0, 0)
