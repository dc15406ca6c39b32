"""Episodes against a scripted, seeded POV: the same scenarios and the same POV for every
VUT, so that a rule read from the trajectories (e.g. unjustified braking) can be compared
across VUTs without an RL opponent in the way.

Per decision the POV brakes hard (8 %), brakes mildly (12 %), holds its speed (65 %) or
speeds up (15 %); in cut-in it also changes lanes once, at a decision drawn uniformly from
the first 15. Used by ``benchmarks/unjustified_braking.py`` and the over-braking tests.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import numpy.typing as npt

from sumo_ayss.analysis.safety_measures import PairTrajectory
from sumo_ayss.config import EnvConfig, FollowerConfig
from sumo_ayss.envs import make_env
from sumo_ayss.envs.odd import sample_initial_conditions, with_followers
from sumo_ayss.scenarios.trajectory import trajectory_from_infos
from sumo_ayss.vuts.catalog import VehicleType

#: The scripted POV is written for the two paper cases' action spaces.
SCRIPTED_CASES = ("car_following", "cut_in")


def scripted_pov_action(
    case: str, rng: np.random.Generator, obs: npt.NDArray[np.float32], t: int, lc_at: int
) -> int:
    """The scripted POV's action at decision ``t``: car-following's action k asks for
    k·0.5·v_pov (2 holds the speed); cut-in's 0 is the lane change (at decision ``lc_at``)
    and 1 + k asks for k m/s around the POV's observed speed ``obs[0]`` [m/s]."""
    if case not in SCRIPTED_CASES:
        raise ValueError(f"case: the scripted POV drives {', '.join(SCRIPTED_CASES)}, not {case!r}")
    u = rng.random()
    if case == "car_following":
        return 0 if u < 0.08 else 1 if u < 0.2 else 2 if u < 0.85 else 3
    if t == lc_at:
        return 0
    d = -8 if u < 0.08 else -3 if u < 0.2 else 0 if u < 0.85 else 3
    return 1 + int(np.clip(round(float(obs[0])) + d, 0, 40))


def scripted_episodes(
    case: str, vut: str, vuts: Mapping[str, VehicleType], n: int, *, seed: int = 11
) -> list[PairTrajectory]:
    """``n`` episodes of ``vut`` in ``case`` against the scripted POV, follower on (real
    SUMO, SUMO seed 0): scenario ``i`` is the ``i``-th ODD draw of ``seed`` and its POV
    draws from ``default_rng(1000 + i)``, the same for every VUT."""
    cfg = EnvConfig(case=case, vuts=dict(vuts), vut=vut, follower=FollowerConfig(enabled=True))
    ics = with_followers(sample_initial_conditions(cfg.odd, n, seed), cfg.follower, seed)
    env = make_env(cfg, sumo_seed=0)
    out = []
    try:
        for i, ic in enumerate(ics):
            rng = np.random.default_rng(1000 + i)
            obs, info0 = env.reset(options={"initial_condition": ic})
            lc_at = int(rng.integers(0, 15))
            infos = []
            for t in range(cfg.max_decisions):
                obs, _, term, trunc, info = env.step(scripted_pov_action(case, rng, obs, t, lc_at))
                infos.append(info)
                if term or trunc:
                    break
            out.append(trajectory_from_infos(cfg, info0, infos))
    finally:
        env.close()
    return out
