"""A pure forecast of one POV ahead of a braking VUT under the clipped POV law (no SUMO).

What a case's inevitable-start check (:attr:`~sumo_ayss.cases.Case.start_filter`) runs for
each of the POV's worst plain plays: the POV on :class:`~sumo_ayss.laws.clipped.ClippedPov`'s
law (target speed -> clipped acceleration -> next speed, :mod:`sumo_ayss.sim.actuator`),
the VUT braking at a constant deceleration from the first step, both moved as SUMO's Euler
update moves them (the step's new speed over the whole step). Longitudinal only: a POV in
the next lane counts as in the VUT's lane from the first step, so the forecast finds every
contact SUMO would find and a few more (a check built on it is conservative).
"""

from __future__ import annotations

from sumo_ayss.config import EnvConfig
from sumo_ayss.sim.actuator import next_speed, pov_acceleration

__all__ = ["braking_contact"]


def braking_contact(
    cfg: EnvConfig,
    gap_m: float,
    pov_speed_mps: float,
    vut_speed_mps: float,
    vut_decel_mps2: float,
    *,
    brake_offset_mps: float,
    brake_from: int | None,
) -> bool:
    """Whether the bumper gap closes (< 0) within the episode of ``cfg``.

    Args:
        cfg: The env (step, decisions, ``env.actuator``; mode ``clipped``).
        gap_m: POV rear bumper minus VUT front bumper at the start [m].
        pov_speed_mps: The POV's speed at the start [m/s].
        vut_speed_mps: The VUT's speed at the start [m/s].
        vut_decel_mps2: The VUT's constant deceleration from the first step [m/s², > 0].
        brake_offset_mps: From decision ``brake_from`` on, the POV's target is its speed at
            the decision plus this (< 0) [m/s]; before, it holds its start speed.
        brake_from: The first braking decision (0: at once); None: it never brakes.
    """
    act, dt = cfg.actuator, cfg.sim.step_length_s
    gap, v_pov, v_vut = gap_m, pov_speed_mps, vut_speed_mps
    target = pov_speed_mps
    for k in range(cfg.max_decisions):
        if brake_from is not None and k >= brake_from:
            target = max(v_pov + brake_offset_mps, 0.0)
        for _ in range(cfg.steps_per_decision):
            v_pov = next_speed(v_pov, pov_acceleration(v_pov, target, act), dt, act)
            v_vut = max(v_vut - vut_decel_mps2 * dt, 0.0)
            gap += (v_pov - v_vut) * dt
            if gap < 0.0:
                return True
    return False
