"""highway-env's (v1.8.2) vehicle kinematics and collision test, as pure functions.

Used by :mod:`sumo_ayss.laws.hwenv` (read its docstring for the coordinates and the laws)
and :mod:`sumo_ayss.laws.highway_env`: the vehicle state, highway-env's kinematic bicycle
(``Vehicle.step``) and its rotated-body collision test (``_is_colliding``). Positions are of
the vehicle's centre [m], ``y`` positive to the left, headings [rad] from +x toward +y.
"""

from __future__ import annotations

import itertools
import math
from typing import NamedTuple

__all__ = ["KinematicState", "bicycle_step", "collision_check", "not_zero"]


def not_zero(x: float, eps: float = 1e-2) -> float:
    """highway-env's ``utils.not_zero``: ``x`` if ``|x| > eps``, else ``±eps``."""
    if abs(x) > eps:
        return x
    return eps if x >= 0 else -eps


class KinematicState(NamedTuple):
    """A vehicle's state in highway-env's terms.

    Attributes:
        x_m: Longitudinal position of the centre [m] (along the road, +x).
        y_m: Lateral position of the centre [m], positive to the left.
        heading_rad: Heading from +x toward +y [rad].
        speed_mps: Speed along the heading [m/s].
    """

    x_m: float
    y_m: float
    heading_rad: float
    speed_mps: float

    @property
    def vx_mps(self) -> float:
        """Velocity along the road [m/s]: ``speed·cos(heading)`` (highway-env's velocity)."""
        return self.speed_mps * math.cos(self.heading_rad)

    @property
    def vy_mps(self) -> float:
        """Lateral velocity [m/s], + left: ``speed·sin(heading)``."""
        return self.speed_mps * math.sin(self.heading_rad)


# ------------------------------------------------------------------------------ kinematics


def bicycle_step(
    s: KinematicState,
    accel_mps2: float,
    steering_rad: float,
    dt_s: float,
    length_m: float = 5.0,
    max_speed_mps: float = 40.0,
    min_speed_mps: float = 0.0,
) -> KinematicState:
    """One explicit-Euler step of highway-env's ``Vehicle.step`` (kinematic bicycle).

    Args:
        s: State before the step.
        accel_mps2: Acceleration command [m/s²].
        steering_rad: Front-wheel angle [rad].
        dt_s: Step [s] (highway-env: 1/15 s).
        length_m: Vehicle length [m] (``Vehicle.LENGTH``, 5 m).
        max_speed_mps: ``Vehicle.MAX_SPEED`` [m/s]: above it the acceleration is capped at
            ``1/s·(max_speed − v)`` (``clip_actions``), not clipped hard.
        min_speed_mps: Speed floor [m/s] (0: a SUMO vehicle cannot reverse; highway-env:
            −40 with the mirror-image soft cap). See the module docstring.

    Returns:
        The state after the step.
    """
    v = s.speed_mps
    if v > max_speed_mps:
        accel_mps2 = min(accel_mps2, max_speed_mps - v)
    elif v < -40.0:
        accel_mps2 = max(accel_mps2, -40.0 - v)
    beta = math.atan(0.5 * math.tan(steering_rad))
    x = s.x_m + v * math.cos(s.heading_rad + beta) * dt_s
    y = s.y_m + v * math.sin(s.heading_rad + beta) * dt_s
    heading = s.heading_rad + v * math.sin(beta) / (length_m / 2) * dt_s
    speed = max(v + accel_mps2 * dt_s, min_speed_mps)
    return KinematicState(x, y, heading, speed)


# ------------------------------------------------------------------------------ collisions


def _polygon(s: KinematicState, length_m: float, width_m: float) -> list[tuple[float, float]]:
    """highway-env's ``RoadObject.polygon``: the rotated body, first corner repeated."""
    c, sn = math.cos(s.heading_rad), math.sin(s.heading_rad)
    pts = []
    for lx, ly in (
        (-length_m / 2, -width_m / 2),
        (-length_m / 2, width_m / 2),
        (length_m / 2, width_m / 2),
        (length_m / 2, -width_m / 2),
    ):
        pts.append((c * lx - sn * ly + s.x_m, sn * lx + c * ly + s.y_m))
    pts.append(pts[0])
    return pts


def _interval_distance(min_a: float, max_a: float, min_b: float, max_b: float) -> float:
    return min_b - max_a if min_a < min_b else min_a - max_b


def collision_check(
    a: KinematicState,
    b: KinematicState,
    dt_s: float,
    length_m: tuple[float, float] = (5.0, 5.0),
    width_m: tuple[float, float] = (2.0, 2.0),
) -> tuple[bool, bool]:
    """highway-env's ``_is_colliding`` / ``are_polygons_intersecting`` (separating axes).

    Returns:
        ``(intersecting, will_intersect)``: the rotated bodies overlap now (touching
        counts); they would overlap after moving ``velocity · dt_s`` (highway-env then
        pushes them apart and marks both crashed at the next step).
    """
    diag_a = math.hypot(length_m[0], width_m[0])
    diag_b = math.hypot(length_m[1], width_m[1])
    if math.hypot(b.x_m - a.x_m, b.y_m - a.y_m) > (diag_a + diag_b) / 2 + a.speed_mps * dt_s:
        return False, False
    pa = _polygon(a, length_m[0], width_m[0])
    pb = _polygon(b, length_m[1], width_m[1])
    disp_x = (a.vx_mps - b.vx_mps) * dt_s
    disp_y = (a.vy_mps - b.vy_mps) * dt_s
    intersecting = will_intersect = True
    for poly in (pa, pb):
        for (x1, y1), (x2, y2) in itertools.pairwise(poly):
            nx, ny = -y2 + y1, x2 - x1
            norm = math.hypot(nx, ny)
            nx, ny = nx / norm, ny / norm
            proj_a = [x * nx + y * ny for x, y in pa]
            proj_b = [x * nx + y * ny for x, y in pb]
            min_a, max_a = min(proj_a), max(proj_a)
            min_b, max_b = min(proj_b), max(proj_b)
            if _interval_distance(min_a, max_a, min_b, max_b) > 0:
                intersecting = False
            vp = nx * disp_x + ny * disp_y
            if vp < 0:
                min_a += vp
            else:
                max_a += vp
            if _interval_distance(min_a, max_a, min_b, max_b) > 0:
                will_intersect = False
            if not intersecting and not will_intersect:
                return False, False
    return intersecting, will_intersect
