"""Case ``car_following``: one lane, the POV ahead of the VUT (paper V-A, Fig. 4, Table II).

Env :class:`sumo_ayss.envs.car_following.CarFollowingEnv`; AYSS indicator: the POV
acceleration [m/s²] the SPCP's action implies (:func:`sumo_ayss.scenarios.ayss.
car_following_rows`, no SUMO needed).
"""

from __future__ import annotations

from sumo_ayss.cases.registry import BASE_OBSERVATION, Case, Indicator, PaperRow, register_case

__all__ = ["CAR_FOLLOWING", "INDICATOR_COLUMN", "POV_ACCELERATION"]

#: ``indicator_name`` of car-following AYSS rows: POV acceleration [m/s²], < 0 brakes.
INDICATOR_COLUMN = "pov_accel_mps2"

POV_ACCELERATION = Indicator("POV acceleration", "m/s²", "brake {amount} harder")
"""Car-following indicator: POV acceleration implied by the SPCP's action, m/s²."""

CAR_FOLLOWING = register_case(
    Case(
        name="car_following",
        title="One-lane car-following",
        network="straight_1lane",
        lanes=1,
        env="sumo_ayss.envs.car_following:CarFollowingEnv",
        gym_id="sumo_ayss/CarFollowing-v0",
        observation=BASE_OBSERVATION,
        ayss_rows="sumo_ayss.scenarios.ayss:car_following_rows",
        indicator_column=INDICATOR_COLUMN,
        indicator=POV_ACCELERATION,
        axis_label="POV acceleration implied by the SPCP's action [m/s²]",
        symbol="POV acceleration",
        outcome_columns=("crash", "return", "headway"),
        paper_figure="Fig. 4",
        paper_table="Table II",
        paper_rows=(
            PaperRow("pi1", 1, 0.0, None, 19.48, 1.65),
            PaperRow("pi1", 2, 0.0, None, 19.45, 1.82),
            PaperRow("pi1", 3, 0.0, None, 19.43, 1.71),
            PaperRow("pi2", 1, 0.0, None, 19.30, 2.42),
            PaperRow("pi2", 2, 0.0, None, 19.31, 2.62),
            PaperRow("pi2", 3, 0.0, None, 19.29, 3.76),
        ),
    )
)
"""The car-following case."""
