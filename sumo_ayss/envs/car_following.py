"""``sumo_ayss/CarFollowing-v0``: the POV drives ahead of the VUT in one lane (paper V-A).

Observation ``(v_pov, v_vut, h)``: POV and VUT speeds [m/s] and the headway h [m], POV rear
bumper minus VUT front bumper (from SUMO positions and lengths, not ``getLeader``, whose gap
already subtracts the follower's minGap). Action k ∈ {0..20} sets the POV's target speed to
``0.5·k·v_pov`` (k = 2 holds speed, k = 0 asks for a stop); the actuator turns it into a
bounded acceleration. Reward: ``α_A·R_A(h)`` with the ``same_lane`` shape, or the minimum
``-α_C`` at a collision, which ends the episode.
"""

from __future__ import annotations

from typing import Any, ClassVar

from sumo_ayss.cases.car_following import CAR_FOLLOWING
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.envs.pair_env import (
    HEADWAY_HIGH_M,
    HEADWAY_LOW_M,
    SPEED_HIGH_MPS,
    VUT_START_POS_M,
    PairEnv,
    PairKinematics,
)
from sumo_ayss.envs.rewards import adversarial_reward
from sumo_ayss.sim.pair import PairPlacement

#: Number of actions and the factor per action index: target = TARGET_STEP·k·v_pov.
N_ACTIONS = 21
TARGET_STEP = 0.5


def target_speed_mps(action: int, pov_speed_mps: float) -> float:
    """Target speed [m/s] of car-following action ``action`` at POV speed ``pov_speed_mps``."""
    return TARGET_STEP * action * pov_speed_mps


class CarFollowingEnv(PairEnv):
    """One-lane car-following: POV ahead of the VUT in the same lane."""

    CASE: ClassVar[str] = CAR_FOLLOWING.name
    RESPONSE_ACTION: ClassVar[int] = round(1.0 / TARGET_STEP)  # target = 1.0 · v_pov
    RESPONSE_HOLDS_SPEED: ClassVar[bool] = True
    OBS_LOW: ClassVar[tuple[float, ...]] = (0.0, 0.0, HEADWAY_LOW_M)
    OBS_HIGH: ClassVar[tuple[float, ...]] = (SPEED_HIGH_MPS, SPEED_HIGH_MPS, HEADWAY_HIGH_M)
    N_ACTIONS: ClassVar[int] = N_ACTIONS
    ICS_STRATEGIES: ClassVar[dict[str, tuple[int, ...]]] = {"brake": (0,)}

    def _placement(self, ic: InitialCondition) -> PairPlacement:
        pov_front = VUT_START_POS_M + ic.gap_m + self._pov_length_m
        return PairPlacement(VUT_START_POS_M, ic.vut_speed_mps, 0, pov_front, ic.pov_speed_mps, 0)

    def _observation_values(self, k: PairKinematics) -> tuple[float, ...]:
        # Clipped with Python floats: np.clip costs more than the rest of this method.
        return (
            min(k.pov_speed_mps, SPEED_HIGH_MPS),
            min(k.vut_speed_mps, SPEED_HIGH_MPS),
            min(max(k.headway_m, HEADWAY_LOW_M), HEADWAY_HIGH_M),
        )

    def _apply_action(self, action: int, k: PairKinematics) -> float:
        return target_speed_mps(action, k.pov_speed_mps)

    def _reward_terms(self, k: PairKinematics, collided: bool) -> tuple[float, dict[str, Any]]:
        return adversarial_reward(k.headway_m, self.config.reward.same_lane), {}
