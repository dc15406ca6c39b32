"""Reward shapes: the adversarial term R_A(h) and the collision term R_C.

R = alpha_adversarial·R_A + alpha_collision·R_C (paper eq. 5). R_A ∈ [0, 1] rewards small
headways h [m]; R_C = -1 on a collision step, else 0, so a collision gets the minimum reward
``-alpha_collision``. Shapes between the paper's anchor points (peak, zero) are ours and
configurable (:class:`sumo_ayss.config.RewardShape`); ``docs/reward_shapes.png`` draws them.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from sumo_ayss.config import RewardConfig, RewardShape

#: exp(-K·u) rescaled to hit 0 at u = 1; K = 3 keeps 5 % of the peak at u = 1 before rescale.
_EXP_RATE = 3.0
_EXP_FLOOR = math.exp(-_EXP_RATE)


def adversarial_reward(headway_m: float, shape: RewardShape) -> float:
    """R_A(h) ∈ [0, 1] for a headway ``headway_m`` [m] (bumper to bumper, >= 0)."""
    h = headway_m
    if h >= shape.zero_m:
        return 0.0
    if h <= shape.peak_m:
        if shape.peak_m == 0.0:
            return 1.0
        frac = max(h, 0.0) / shape.peak_m
        return shape.value_at_contact + (1.0 - shape.value_at_contact) * frac
    u = (h - shape.peak_m) / (shape.zero_m - shape.peak_m)
    if shape.kind == "linear":
        return 1.0 - u
    if shape.kind == "quadratic":
        return (1.0 - u) ** 2
    return (math.exp(-_EXP_RATE * u) - _EXP_FLOOR) / (1.0 - _EXP_FLOOR)


def adversarial_reward_array(
    headway_m: npt.ArrayLike, shape: RewardShape
) -> npt.NDArray[np.float64]:
    """Elementwise :func:`adversarial_reward` (for plots and tables)."""
    h = np.asarray(headway_m, dtype=float)
    rewards: npt.NDArray[np.float64] = np.vectorize(
        lambda x: adversarial_reward(float(x), shape), otypes=[float]
    )(h)
    return rewards


def lane_phase_reward(
    headway_m: float,
    both_lengths_m: float,
    changing: bool,
    same_lane: bool,
    lane_change: RewardShape,
    same: RewardShape,
) -> tuple[float, str]:
    """R_A and its phase for a POV that may cut in: 0 once it is wholly behind the VUT
    (``headway_m`` <= -``both_lengths_m``, the two lengths [m]), the lane-change shape
    while it changes lanes, the same-lane shape in the VUT's lane, else 0."""
    if headway_m <= -both_lengths_m:
        return 0.0, "behind"
    if changing:
        return adversarial_reward(headway_m, lane_change), "lane_change"
    if same_lane:
        return adversarial_reward(headway_m, same), "same_lane"
    return 0.0, "different_lanes"


def total_reward(r_adversarial: float, collided: bool, cfg: RewardConfig) -> float:
    """R = α_A·R_A + α_C·R_C with R_C = -1 on a collision (R_A is then not paid)."""
    if collided:
        return -cfg.alpha_collision
    return cfg.alpha_adversarial * r_adversarial
