"""A stand-in for :class:`~sumo_ayss.sim.pair.VehiclePair` that records what a law commands.

Laws talk to SUMO only through the pair, so they can be tested without SUMO: the fake holds
the readings a test sets and logs every command.
"""

from __future__ import annotations

from typing import Any


class FakePair:
    """Straight two-lane road along +x, lanes 3.2 m wide, lane 0's centre at y = -4.8 m."""

    def __init__(self, pov_front: tuple[float, float], vut_front: tuple[float, float]) -> None:
        self.pov_front = pov_front
        self.vut_front = vut_front
        self.pov_lane, self.vut_lane = 1, 0
        self.speeds = (20.0, 20.0)  # (POV, VUT) [m/s]
        self.vut_accel = 0.5
        self.log: list[tuple[Any, ...]] = []

    def world_fronts(self) -> tuple[tuple[float, float], tuple[float, float]]:
        return self.pov_front, self.vut_front

    def lanes(self) -> tuple[int, int]:
        return self.pov_lane, self.vut_lane

    def lane_centre_y_m(self, lane: int) -> float:
        return -4.8 + 3.2 * lane

    def lane_width_m(self, lane: int) -> float:
        return 3.2

    def longitudinal(self) -> tuple[float, float, float, float]:
        return self.pov_front[0], self.speeds[0], self.vut_front[0], self.speeds[1]

    def vut_accel_mps2(self) -> float:
        return self.vut_accel

    def __getattr__(self, name: str) -> Any:
        """Every other pair method (commands) is logged as ``(name, *args)``."""
        if name.startswith("_"):
            raise AttributeError(name)

        def record(*args: Any) -> None:
            self.log.append((name, *args))

        return record
