"""SUMO's integration method is one global of the simulation (``env.sim.step_method``).

SUMO 1.28 switches every vehicle to ballistic integration as soon as one loaded type has an
``actionStepLength`` other than the step (``MSVehicleType.cpp``, "Setting it now to avoid
collisions"), so before this option a study's catalog moved all its VUTs. The testbed now
passes the method explicitly: ``auto`` reproduces SUMO's own choice, ``euler`` and
``ballistic`` pin it whatever the catalog holds. Real SUMO.
"""

from __future__ import annotations

import numpy as np
import pytest

from sumo_ayss.config import EnvConfig, SimConfig
from sumo_ayss.envs import make_env
from sumo_ayss.envs.odd import sample_initial_conditions
from sumo_ayss.util.errors import ConfigError
from sumo_ayss.vuts.catalog import BUILTIN_VUTS, VehicleType

#: pi1's law deciding every 0.4 s: only its presence in the catalog matters here.
HELD = VehicleType("IDM", {**BUILTIN_VUTS["pi1"].params, "actionStepLength": 0.4})
PLAIN = {"pi1": BUILTIN_VUTS["pi1"]}
BESIDE = {**PLAIN, "held": HELD}


def _episode(case: str, vuts: dict[str, VehicleType], method: str) -> np.ndarray:
    """pi1's observations and rewards over 15 steps of a fixed action sequence."""
    cfg = EnvConfig(case=case, vuts=vuts, vut="pi1", sim=SimConfig(step_method=method))  # type: ignore[arg-type]
    env = make_env(cfg)
    try:
        ic = sample_initial_conditions(cfg.odd, 1, 7)[0]
        obs, _ = env.reset(options={"initial_condition": ic})
        rows = []
        for a in np.random.default_rng(7).integers(0, env.action_space.n, size=15):
            obs, r, term, trunc, _ = env.step(int(a))
            rows.append(np.append(obs, r))
            if term or trunc:
                break
        return np.array(rows)
    finally:
        env.close()


@pytest.mark.sumo
@pytest.mark.parametrize("case", ["car_following", "cut_in"])
def test_the_catalog_moves_pi1_only_through_the_integration_method(case: str) -> None:
    plain = _episode(case, PLAIN, "auto")
    beside = _episode(case, BESIDE, "auto")
    assert not np.array_equal(plain, beside)  # SUMO's global switch, as it always was
    assert np.array_equal(_episode(case, PLAIN, "ballistic"), beside)
    assert np.array_equal(_episode(case, BESIDE, "euler"), plain)


def test_step_method_is_checked_and_not_settable_twice() -> None:
    with pytest.raises(
        ConfigError, match=r"env\.sim\.step_method must be one of \['auto', 'euler', 'ballistic'\]"
    ):
        SimConfig(step_method="rk4")  # type: ignore[arg-type]
    with pytest.raises(ConfigError, match=r"env\.sim\.step_method"):
        SimConfig(extra_args=("--step-method.ballistic", "true"))
