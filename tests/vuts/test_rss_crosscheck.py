"""RSS's safe longitudinal distance against ad-rss-lib's own (the ``ad_rss`` binding)."""

from __future__ import annotations

from typing import Any

import pytest

from sumo_ayss.vuts.reference import rss_safe_distance_m

rss = pytest.importorskip("ad_rss.ad_rss_python311", reason="ad_rss (PyPI) is not installed")
physics = pytest.importorskip("ad_physics.ad_physics_python311").physics


def _state(v_mps: float) -> Any:
    """A same-direction object at ``v_mps`` with the parameters our driver defaults to
    (rho 1 s, a_max 3.5, b_min 4, b_max 8 m/s²; no extra margin)."""
    o = rss.rss.core.RelativeObjectState()
    d = o.dynamics
    d.alpha_lon.accel_max = physics.Acceleration(3.5)
    d.alpha_lon.brake_max = physics.Acceleration(-8.0)
    d.alpha_lon.brake_min = physics.Acceleration(-4.0)
    d.alpha_lon.brake_min_correct = physics.Acceleration(-3.0)
    d.alpha_lat.accel_max = physics.Acceleration(0.2)
    d.alpha_lat.brake_min = physics.Acceleration(-0.8)
    d.response_time = physics.Duration(1.0)
    d.max_speed_on_acceleration = physics.Speed(100.0)
    d.min_longitudinal_safety_distance = physics.Distance(0.0)
    d.lateral_fluctuation_margin = physics.Distance(0.0)
    u = d.unstructured_settings  # validated by the library even where unused
    u.pedestrian_turning_radius = physics.Distance(2.0)
    u.drive_away_max_angle = physics.Angle(2.4)
    u.vehicle_yaw_rate_change = physics.AngularAcceleration(0.3)
    u.vehicle_min_radius = physics.Distance(3.5)
    u.vehicle_trajectory_calculation_step = physics.Duration(0.2)
    us = o.unstructured_object_state
    us.yaw = physics.Angle(0.0)
    us.yaw_rate = physics.AngularVelocity(0.0)
    us.steering_angle = physics.Angle(0.0)
    us.dimension.length = physics.Distance(5.0)
    us.dimension.width = physics.Distance(1.8)
    us.center_point.x = physics.Distance(0.0)
    us.center_point.y = physics.Distance(0.0)
    us.speed_range.minimum = physics.Speed(v_mps)
    us.speed_range.maximum = physics.Speed(v_mps)
    s = o.structured_object_state
    s.velocity.speed_lon_min = physics.Speed(v_mps)
    s.velocity.speed_lon_max = physics.Speed(v_mps)
    s.velocity.speed_lat_min = physics.Speed(0.0)
    s.velocity.speed_lat_max = physics.Speed(0.0)
    s.is_in_correct_lane = True
    s.distance_to_enter_intersection = physics.Distance(1000.0)
    s.distance_to_leave_intersection = physics.Distance(1000.0)
    o.object_type = rss.rss.world.ObjectType.OtherVehicle
    return o


@pytest.mark.parametrize(
    ("v_rear", "v_front"), [(20.0, 20.0), (30.0, 10.0), (10.0, 30.0), (25.0, 0.0), (0.0, 0.0)]
)
def test_safe_distance_equals_ad_rss_lib(v_rear: float, v_front: float) -> None:
    out = physics.Distance(0.0)
    ok = rss.rss.structured.calculateSafeLongitudinalDistanceSameDirection(
        _state(v_front), _state(v_rear), out
    )
    assert ok
    # The library prints its Distance with 6 significant digits.
    assert float(str(out)) == pytest.approx(rss_safe_distance_m(v_rear, v_front), abs=1e-3)
