"""Episodes of random POV actions against a controller-kind VUT, for exact comparisons of
VUT kinds (Python controller, FMU, process) that implement the same law."""

from __future__ import annotations

from typing import Any

import numpy as np

from sumo_ayss.config import EnvConfig
from sumo_ayss.envs import make_env
from sumo_ayss.vuts.catalog import ControllerSpec, VehicleType


def python_acc(time_gap_s: float = 2.0) -> ControllerSpec:
    return ControllerSpec(
        "examples.acc_controller:TimeGapACC", 3.0, 6.0, params={"time_gap_s": time_gap_s}
    )


def episodes(spec: ControllerSpec, case: str, n: int = 3) -> list[list[Any]]:
    """``n`` episodes of random POV actions against the VUT ``spec`` drives (real SUMO)."""
    cfg = EnvConfig(case=case, vut="v", vuts={"v": VehicleType(controller=spec)})  # type: ignore[arg-type]
    env = make_env(cfg, sumo_seed=0)
    rng = np.random.default_rng(7)
    out = []
    try:
        for episode in range(n):
            obs, _ = env.reset(seed=100 + episode)
            steps: list[Any] = [obs.tolist()]
            while True:
                obs, reward, terminated, truncated, info = env.step(
                    int(rng.integers(env.action_space.n))  # type: ignore[attr-defined]
                )
                steps.append((obs.tolist(), reward, terminated, info["vut_accel_mps2"]))
                if terminated or truncated:
                    break
            out.append(steps)
    finally:
        env.close()
    return out
