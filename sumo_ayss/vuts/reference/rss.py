"""RSS's longitudinal proper response as a driver (``rss``), and full braking for the
inevitable-collision states."""

from __future__ import annotations

import math
from dataclasses import dataclass

from sumo_ayss.vuts.controllers import ControllerInput
from sumo_ayss.vuts.reference.common import (
    G_MPS2,
    OWN_WIDTH_M,
    ahead,
    check_param,
    in_lane,
    lead_of,
)

# ----------------------------------------------------------------------------- RSS

__all__ = ["FullBraking", "RssDriver", "rss_lateral_safe_distance_m", "rss_safe_distance_m"]


def rss_safe_distance_m(
    v_rear_mps: float,
    v_front_mps: float,
    rho_s: float = 1.0,
    a_max_mps2: float = 3.5,
    b_min_mps2: float = 4.0,
    b_max_mps2: float = 8.0,
) -> float:
    """RSS's minimum safe longitudinal distance, same direction [m] (ad-rss-lib's
    ``calculateSafeLongitudinalDistanceSameDirection`` without its speed cap and extra
    margin): ``max(0, v_r·ρ + a_max·ρ²/2 + (v_r + ρ·a_max)²/(2·b_min) - v_f²/(2·b_max))``;
    equal to the ``ad_rss`` binding's (PyPI 5.0) on the same inputs
    (``tests/vuts/test_rss_crosscheck.py``)."""
    v_resp = v_rear_mps + rho_s * a_max_mps2
    d = (
        v_rear_mps * rho_s
        + 0.5 * a_max_mps2 * rho_s**2
        + v_resp**2 / (2.0 * b_min_mps2)
        - v_front_mps**2 / (2.0 * b_max_mps2)
    )
    return max(0.0, d)


def rss_lateral_safe_distance_m(
    v_lat_toward_mps: float,
    rho_s: float = 1.0,
    a_lat_max_mps2: float = 0.2,
    b_lat_min_mps2: float = 0.8,
    mu_m: float = 0.1,
) -> float:
    """RSS's minimum safe lateral distance [m] between the own car (no lateral speed) and an
    object moving toward it at ``v_lat_toward_mps``: each car's stated braking pattern
    (accelerate laterally at ``a_lat_max`` for ρ, then brake at ``b_lat_min``) plus μ."""

    def offset(v: float) -> float:
        v_resp = v + rho_s * a_lat_max_mps2
        return (
            v * rho_s
            + 0.5 * a_lat_max_mps2 * rho_s**2
            + max(v_resp, 0.0) ** 2 / (2.0 * b_lat_min_mps2)
        )

    return mu_m + offset(0.0) + offset(max(v_lat_toward_mps, 0.0))


@dataclass
class RssDriver:
    """RSS's longitudinal proper response as a driver: hold speed while safe; brake at
    ``b_min_mps2`` while an object is closer than RSS's safe distance both longitudinally
    (:func:`rss_safe_distance_m`) and laterally (:func:`rss_lateral_safe_distance_m`, an
    object already reaching into the own lane is laterally unsafe). The response is
    immediate: ρ is the response time RSS *allows* the rear car, built into the distance."""

    rho_s: float = 1.0
    a_max_mps2: float = 3.5
    b_min_mps2: float = 4.0
    b_max_mps2: float = 8.0
    a_lat_max_mps2: float = 0.2
    b_lat_min_mps2: float = 0.8
    mu_m: float = 0.1

    def __post_init__(self) -> None:
        check_param("rho_s", self.rho_s, low=0.0)
        check_param("mu_m", self.mu_m, low=0.0)
        for name in ("a_max_mps2", "b_min_mps2", "b_max_mps2", "a_lat_max_mps2", "b_lat_min_mps2"):
            check_param(name, getattr(self, name), low=0.0, strict=True)

    def reset(self) -> None:
        """Stateless: nothing to forget."""

    def acceleration(self, state: ControllerInput) -> float:
        """``-b_min`` while some object is RSS-unsafe, else 0 [m/s²]."""
        half = 0.5 * (state.lane_width_m if math.isfinite(state.lane_width_m) else 3.2)
        objects = list(state.objects) or ([o] if (o := lead_of(state)) else [])
        for o in objects:
            if not ahead(o):
                continue
            u_r = state.speed_mps
            d_lon = rss_safe_distance_m(
                u_r, u_r + o.rel_speed_mps, self.rho_s, self.a_max_mps2, self.b_min_mps2,
                self.b_max_mps2,
            )  # fmt: skip
            if o.gap_m >= d_lon:
                continue
            if not in_lane(o, state.lane_width_m):
                toward = -math.copysign(1.0, o.lateral_offset_m) * o.lateral_speed_mps
                lat_gap = abs(o.lateral_offset_m) - 0.5 * o.width_m - (half - 0.5 * OWN_WIDTH_M)
                lat_gap -= 0.5 * OWN_WIDTH_M
                d_lat = rss_lateral_safe_distance_m(
                    toward, self.rho_s, self.a_lat_max_mps2, self.b_lat_min_mps2, self.mu_m
                )
                if lat_gap >= d_lat:
                    continue
            return -self.b_min_mps2
        return 0.0


@dataclass
class FullBraking:
    """Brakes at ``decel_mps2`` (default 0.85 g, the CC driver's AEB) from the first step,
    whatever it sees: the best any driver could do by braking, for the inevitable-collision
    states of :mod:`sumo_ayss.scenarios.inevitable`."""

    decel_mps2: float = 0.85 * G_MPS2

    def __post_init__(self) -> None:
        check_param("decel_mps2", self.decel_mps2, low=0.0, strict=True)

    def reset(self) -> None:
        """Stateless."""

    def acceleration(self, state: ControllerInput) -> float:
        del state
        return -self.decel_mps2
