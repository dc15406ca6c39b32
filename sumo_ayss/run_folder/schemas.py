"""Schemas of the run folder's two tables, ``outcome.csv`` and ``ayss.csv``, and of the
case folder's ``crossplay.csv``.

* :data:`OUTCOME_SCHEMA` — ``<run>/outcome.csv``, one row per outcome episode (paper
  Tables II and III): the initial condition, the return, whether it crashed or changed lanes,
  the headway at the last step.
* :data:`AYSS_SCHEMA` — ``<run>/ayss.csv``, one row per kept adversarial-yet-safe sample of
  the Monte Carlo stage (paper Fig. 4 and 6): the sampled observation, the SPCP's action,
  TTC and the aggressiveness indicator.
* :data:`AYSS_BINS_SCHEMA` — ``<run>/ayss_bins.csv``, the same samples as per-headway-cell
  moments (:mod:`~sumo_ayss.run_folder.ayss_bins`), small enough to commit.
* :data:`CROSSPLAY_SCHEMA` — ``<out>/<case>/crossplay.csv``, one row per (VUT, opponent
  SPCP, scenario) of the cross-play stage (:mod:`sumo_ayss.crossplay`).

Written and read with :func:`~sumo_ayss.records.table.write_table` /
:func:`~sumo_ayss.records.table.read_table`.
"""

from __future__ import annotations

from sumo_ayss.cases import indicator_columns
from sumo_ayss.records.table import Column, TableSchema
from sumo_ayss.run_folder.measure_columns import EPISODE_HAZARD_COLUMNS, EPISODE_MEASURE_COLUMNS

__all__ = [
    "AYSS_BINS_SCHEMA",
    "AYSS_SCHEMA",
    "CROSSPLAY_SCHEMA",
    "OUTCOME_SCHEMA",
]

#: Per-episode columns the harm score and mobility read (issue 22), in both episode tables
#: (``outcome.csv``, ``crossplay.csv``); files written before them read as NaN.
EPISODE_HARM_COLUMNS: tuple[Column, ...] = (
    Column(
        "near_miss_pay",
        "float",
        "-",
        "adversarial reward paid over the episode, the sum of alpha_A·R_A; the collision "
        "term excluded (read from episode_return in files written before this column)",
        nullable=True,
        since=True,
    ),
    Column(
        "vut_mean_speed_mps",
        "float",
        "m/s",
        "the VUT's mobility: mean of its speed at the end of each decision (NaN in files "
        "written before this column)",
        nullable=True,
        since=True,
    ),
)

#: The crash label of both episode tables (:mod:`sumo_ayss.scenarios.preventability`);
#: files written before it read as NaN throughout: "not labelled".
EPISODE_LABEL_COLUMNS: tuple[Column, ...] = (
    Column(
        "crash_preventable",
        "float",
        "-",
        "a crash replayed with the reference driver in the VUT's place (the POV's actions "
        "open loop): 1 = the reference avoided contact (preventable), 0 = it collided too "
        "(unpreventable); empty without a crash, and throughout in files not labelled",
        nullable=True,
        since=True,
    ),
)

#: ``<run>/outcome.csv``: one row per episode of the outcome stage (paper Tables II, III).
OUTCOME_SCHEMA = TableSchema(
    "outcome",
    (
        Column("scenario", "int", "-", "index of the initial condition in the scenario set"),
        Column("v_pov0_mps", "float", "m/s", "POV speed at the start of the episode"),
        Column("v_vut0_mps", "float", "m/s", "VUT speed at the start of the episode"),
        Column(
            "gap0_m",
            "float",
            "m",
            "initial longitudinal gap, POV rear bumper minus VUT front bumper",
        ),
        Column("episode_return", "float", "-", "undiscounted sum of the rewards R of the episode"),
        Column("collided", "bool", "-", "the episode ended in a collision"),
        Column(
            "lane_changed",
            "bool",
            "-",
            "the POV started a lane change (cut-in); always 0 in car-following",
        ),
        Column(
            "final_headway_m",
            "float",
            "m",
            "headway h after the last step (POV rear minus VUT front; < 0 = overlap)",
        ),
        Column("n_steps", "int", "-", "decisions taken (25 for a full 5 s episode)"),
        *EPISODE_HARM_COLUMNS,
        *EPISODE_MEASURE_COLUMNS,
        *EPISODE_LABEL_COLUMNS,
        *EPISODE_HAZARD_COLUMNS,
    ),
)


#: ``<run>/ayss.csv``: one row per kept adversarial-yet-safe sample (paper Fig. 4 and 6).
AYSS_SCHEMA = TableSchema(
    "ayss",
    (
        Column("sample", "int", "-", "index of the draw in the seed's Monte Carlo sample"),
        Column("v_pov_mps", "float", "m/s", "sampled POV speed (observation)"),
        Column("v_vut_mps", "float", "m/s", "sampled VUT speed (observation)"),
        Column(
            "h_m",
            "float",
            "m",
            "sampled headway, POV rear bumper minus VUT front bumper (observation)",
        ),
        Column(
            "same_lane",
            "int",
            "-",
            "same-lane flag of the observation: 1 in car-following, 0 in cut-in",
        ),
        Column("action", "int", "-", "the SPCP's (greedy) action index"),
        Column(
            "target_speed_mps",
            "float",
            "m/s",
            "target speed the action asks for (cut-in lane change: the POV keeps v_pov)",
        ),
        Column(
            "ttc_s",
            "float",
            "s",
            "time to collision h / (v_vut - v_pov) when closing, +inf otherwise",
            allow_inf=True,
        ),
        Column(
            "indicator_name",
            "str",
            "-",
            "pov_accel_mps2 (car-following) or delta_v_bar_mps (cut-in)",
            choices=indicator_columns,  # of the registered cases, asked at each check
        ),
        Column(
            "indicator",
            "float",
            "m/s² or m/s",
            "aggressiveness: POV acceleration (< 0 brakes) or Δv̄ (< 0 closes in); "
            "smaller = more aggressive",
        ),
        Column(
            "h_after_m",
            "float",
            "m",
            "cut-in: headway after the 1-step scenario in SUMO; NaN in car-following",
            nullable=True,
        ),
        Column(
            "delta_v_bar_before_mps",
            "float",
            "m/s",
            "cut-in: Δv̄ at the sampled state, before the action acts (no lateral speed); "
            "NaN in car-following",
            nullable=True,
        ),
    ),
)


#: ``<run>/ayss_bins.csv``: the AYSS samples as moments per headway cell (1/32 m open
#: intervals and their edge points), :mod:`sumo_ayss.run_folder.ayss_bins`.
AYSS_BINS_SCHEMA = TableSchema(
    "ayss_bins",
    (
        Column("h_low_m", "float", "m", "lower end of the headway cell"),
        Column(
            "h_high_m",
            "float",
            "m",
            "upper end: h_low_m + 1/32 for the open interval between them, h_low_m for the "
            "edge point itself",
        ),
        Column("n", "int", "-", "AYSS samples in the cell"),
        Column("mean", "float", "m/s² or m/s", "mean indicator of the cell's samples"),
        Column(
            "m2",
            "float",
            "(m/s²)² or (m/s)²",
            "sum of squared deviations of the cell's indicator from its mean",
        ),
        Column(
            "indicator_name",
            "str",
            "-",
            "pov_accel_mps2 (car-following) or delta_v_bar_mps (cut-in)",
            choices=indicator_columns,
        ),
    ),
)


#: ``<out>/<case>/crossplay.csv``: every SPCP of a case against every VUT of that case.
CROSSPLAY_SCHEMA = TableSchema(
    "crossplay",
    (
        Column("vut", "str", "-", "the VUT driven against"),
        Column("opponent_vut", "str", "-", "the VUT the opponent SPCP was trained against"),
        Column("opponent_seed", "int", "-", "the training seed of the opponent SPCP"),
        Column("scenario", "int", "-", "index of the initial condition in the scenario set"),
        Column("episode_return", "float", "-", "undiscounted sum of the rewards R of the episode"),
        Column("collided", "bool", "-", "the episode ended in a collision"),
        Column(
            "final_headway_m",
            "float",
            "m",
            "headway h after the last step (POV rear minus VUT front; < 0 = overlap)",
        ),
        Column("n_steps", "int", "-", "decisions in the episode"),
        *EPISODE_HARM_COLUMNS,
        *EPISODE_MEASURE_COLUMNS,
        *EPISODE_LABEL_COLUMNS,
        *EPISODE_HAZARD_COLUMNS,
    ),
)
