"""AYSS rows of the two-POV case ``lead_and_cut_in``: Δv̄ of the primary POV (docs/cases.md).

Every safety-critical Monte Carlo sample is run one step in SUMO: the env is reset to the
sampled state, its supporting POV at the case's fixed AYSS state (the observation's
columns after the first three), the SPCP's joint action is taken, and Δv̄ between the VUT
and the primary POV is read after the step. Every action counts: the primary here is the
lead POV, whose braking is the adversarial act (no lane-change filter).
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
import numpy.typing as npt
from tqdm import tqdm

from sumo_ayss.cases.lead_and_cut_in import INDICATOR_COLUMN
from sumo_ayss.envs.lead_and_cut_in import LeadAndCutInEnv, TwoPovStart
from sumo_ayss.envs.pair_env import PairEnv
from sumo_ayss.records.table import Table
from sumo_ayss.scenarios.ayss import ayss_rows_table
from sumo_ayss.util.errors import SimulationError

__all__ = ["lead_and_cut_in_rows"]

#: Reset must reproduce a sample to this tolerance [m, m/s] (float32 observation).
_RESET_TOL = 1e-3


def lead_and_cut_in_rows(
    env: PairEnv,
    obs: npt.NDArray[np.float32],
    ttc: npt.NDArray[np.float64],
    critical: npt.NDArray[np.int64],
    actions: npt.NDArray[np.int64],
    counts: dict[str, Any],
    progress: bool,
) -> tuple[Table, float]:
    """The case's AYSS rows (arguments as :func:`sumo_ayss.scenarios.ayss.car_following_rows`)."""
    assert isinstance(env, LeadAndCutInEnv)
    kept = obs[critical].astype(np.float64)
    n = len(critical)
    after, before, h_after, target = (np.empty(n) for _ in range(4))
    t0 = time.perf_counter()
    rows = tqdm(range(n), desc="ayss (SUMO)", unit="sample", disable=not progress, leave=False)
    for i in rows:
        vp, vv, h, _same, v_sup, h_sup, primary = kept[i].tolist()
        start = TwoPovStart(
            vp, vv, h, support_speed_mps=v_sup, support_gap_m=h_sup, primary=round(primary)
        )
        o, info0 = env.reset(options={"initial_condition": start})
        if np.max(np.abs(o - kept[i])) > _RESET_TOL:
            raise SimulationError(f"reset to {kept[i].tolist()} gave observation {o.tolist()}")
        _, _, _, _, info = env.step(int(actions[i]))
        after[i] = info["delta_v_bar_mps"]
        before[i] = info0["delta_v_bar_mps"]
        h_after[i] = info["headway_m"]
        target[i] = info["target_speed_mps"]
    wall = time.perf_counter() - t0
    table = ayss_rows_table(
        critical,
        obs[critical],
        actions,
        target,
        ttc[critical],
        INDICATOR_COLUMN,
        after,
        h_after,
        before,
    )
    return table, wall
