"""Issue 33's over-braker, driven in SUMO behind a POV that holds its speed: the new flag
catches it in car-following, where the mean-speed TIMID rule does not."""

from __future__ import annotations

import numpy as np
import pytest

from sumo_ayss.analysis.harm import mobility_flags
from sumo_ayss.analysis.hazards import overbraking_flags
from sumo_ayss.config import EnvConfig, FollowerConfig
from sumo_ayss.envs import make_env
from sumo_ayss.scenarios.outcome import run_outcome
from sumo_ayss.vuts.catalog import BUILTIN_VUTS
from sumo_ayss.vuts.controllers import ControllerInput
from sumo_ayss.vuts.overbraking import OverBraker
from sumo_ayss.vuts.reference_types import OVERBRAKER_VUT

pytestmark = pytest.mark.sumo


def test_it_brakes_hard_only_with_a_near_leader() -> None:
    ob = OverBraker()
    near = ControllerInput(0.0, 0.2, 20.0, 30.0, 0.0, 0)  # 30 m < 2 + 2 s x 20 m/s
    far = ControllerInput(0.0, 0.2, 20.0, 50.0, 0.0, 0)
    free = ControllerInput(0.0, 0.2, 29.9, float("inf"), 0.0, 0)
    assert ob.acceleration(near) == -6.0
    assert ob.acceleration(far) == 2.0
    assert ob.acceleration(free) == pytest.approx(0.5)  # up to its cruise speed


def test_the_new_flag_catches_it_and_the_mean_speed_rule_does_not() -> None:
    vuts = {**BUILTIN_VUTS, "overbraker": OVERBRAKER_VUT}
    dv, speed = {}, {}
    for vut in ("pi1", "pi2", "overbraker"):
        cfg = EnvConfig(vuts=vuts, vut=vut, follower=FollowerConfig(enabled=True))
        env = make_env(cfg, sumo_seed=0)
        try:
            result = run_outcome(env, lambda obs: np.array([2]), n=40)  # the POV holds speed
        finally:
            env.close()
        dv[vut] = float(np.mean(result.table["unjustified_dv_mps"]))
        speed[vut] = float(np.mean(result.table["vut_mean_speed_mps"]))
    assert overbraking_flags(dv) == {"pi1": False, "pi2": False, "overbraker": True}
    assert not mobility_flags(speed)["overbraker"]


@pytest.mark.parametrize("case", ["car_following", "cut_in"])
def test_the_revised_rule_spares_idm_and_still_flags_the_over_braker(case: str) -> None:
    """Issue 33, session 10: on the same 40 episodes per VUT, the first rule called the IDM
    VUTs' braking unjustified in about half of them (answers to a POV that braked a moment
    earlier, at gaps below R157's following distance); the revised rule rarely does, and
    the over-braker stays flagged."""
    from sumo_ayss.analysis.hazards import unjustified_braking
    from sumo_ayss.scenarios.scripted import scripted_episodes

    vuts = {**BUILTIN_VUTS, "overbraker": OVERBRAKER_VUT}
    share: dict[str, dict[str, float]] = {"first": {}, "revised": {}}
    dv: dict[str, float] = {}
    for vut in ("pi1", "pi2", "overbraker"):
        trs = scripted_episodes(case, vut, vuts, 40)
        first = [
            unjustified_braking(t, reaction_window_s=0.0, following_distance=False) for t in trs
        ]
        revised = [unjustified_braking(t) for t in trs]
        share["first"][vut] = float(np.mean([u.any() for u in first]))
        share["revised"][vut] = float(np.mean([u.any() for u in revised]))
        dv[vut] = float(
            np.mean(
                [
                    u.sum() * float(t.time_s[1] - t.time_s[0])
                    for u, t in zip(revised, trs, strict=True)
                ]
            )
        )
    assert min(share["first"]["pi1"], share["first"]["pi2"]) > 0.4  # before
    assert share["revised"]["pi1"] <= 0.1 and share["revised"]["pi2"] <= 0.25  # after
    assert share["revised"]["overbraker"] > 2 * share["revised"]["pi2"]
    assert overbraking_flags(dv) == {"pi1": False, "pi2": False, "overbraker": True}
