"""The POV's actuator: target speed -> bounded acceleration -> next speed.

SUMO's own checks are switched off for the POV (speed mode 0), which removes every limit
(a ``setSpeed(pov, 0)`` would stop it from 25 m/s in one 0.2 s step). This module is the
one place that bounds it. Pure math, no SUMO: the env and the Monte Carlo AYSS stage both
call it, so the acceleration an action implies is computed by the same code everywhere.

Sign convention: acceleration > 0 speeds up, < 0 brakes. Units m/s, m/s², s.
"""

from __future__ import annotations

from sumo_ayss.config import ActuatorConfig


def pov_acceleration(speed_mps: float, target_speed_mps: float, cfg: ActuatorConfig) -> float:
    """Acceleration [m/s²] that drives ``speed_mps`` toward ``target_speed_mps``.

    ``a = clip((v_target - v) / time_constant_s, accel_min_mps2, accel_max_mps2)``, with the
    target first clipped to ``[0, max_speed_mps]``. In ``mode: highway_env``:
    highway-env's ``ControlledVehicle.speed_control``, ``(v_target - v) / time_constant_s``
    with neither clip (what the action implies at the decision's first sub-step; the speed
    itself is soft-capped at ``max_speed_mps`` by the kinematics).
    """
    if cfg.mode == "highway_env":
        return (target_speed_mps - speed_mps) / cfg.time_constant_s
    target = min(max(target_speed_mps, 0.0), cfg.max_speed_mps)
    accel = (target - speed_mps) / cfg.time_constant_s
    return min(max(accel, cfg.accel_min_mps2), cfg.accel_max_mps2)


def next_speed(speed_mps: float, accel_mps2: float, dt_s: float, cfg: ActuatorConfig) -> float:
    """Speed [m/s] after ``dt_s`` at constant ``accel_mps2``, kept in ``[0, max_speed_mps]``."""
    return min(max(speed_mps + accel_mps2 * dt_s, 0.0), cfg.max_speed_mps)
