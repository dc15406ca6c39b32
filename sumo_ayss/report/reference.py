"""The paper's reference tables (highway-env, not this testbed), shown beside ours."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

__all__ = ["PAPER_TABLES", "PaperRow"]


@dataclass(frozen=True)
class PaperRow:
    """One row of the paper's Table II / III (highway-env, not this testbed).

    Attributes:
        vut: VUT name (pi1: s0 = 10 m, pi2: s0 = 20 m).
        seed: Seed index 1..3 within the VUT (the paper's π*_1..6 in order).
        crash_pct: Crash rate c in %.
        lane_change_pct: Lane-change rate lc in % (cut-in), else None.
        mean_return: Mean episode reward r̄_epi.
        mean_final_headway_m: Mean headway at the last step h̄, m.
    """

    vut: str
    seed: int
    crash_pct: float
    lane_change_pct: float | None
    mean_return: float
    mean_final_headway_m: float


PAPER_TABLES: Mapping[str, tuple[PaperRow, ...]] = {
    "car_following": (
        PaperRow("pi1", 1, 0.0, None, 19.48, 1.65),
        PaperRow("pi1", 2, 0.0, None, 19.45, 1.82),
        PaperRow("pi1", 3, 0.0, None, 19.43, 1.71),
        PaperRow("pi2", 1, 0.0, None, 19.30, 2.42),
        PaperRow("pi2", 2, 0.0, None, 19.31, 2.62),
        PaperRow("pi2", 3, 0.0, None, 19.29, 3.76),
    ),
    "cut_in": (
        PaperRow("pi1", 1, 1.0, 99.0, 20.99, 0.36),
        PaperRow("pi1", 2, 2.0, 99.0, 20.74, 0.36),
        PaperRow("pi1", 3, 0.5, 98.0, 20.78, 0.36),
        PaperRow("pi2", 1, 3.5, 100.0, 20.41, 0.41),
        PaperRow("pi2", 2, 1.0, 100.0, 20.93, 0.38),
        PaperRow("pi2", 3, 1.0, 100.0, 21.14, 0.35),
    ),
}
"""The paper's Tables II (car-following) and III (cut-in), for reference."""
