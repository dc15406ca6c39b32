"""The per-episode surrogate-safety-measure columns of ``outcome.csv`` and ``crossplay.csv``.

One column per field of :class:`~sumo_ayss.analysis.safety_measures.EpisodeMeasures`
(definitions, units, signs and references there). Files written before these columns read
as NaN ("not recorded": :attr:`~sumo_ayss.records.table.Column.since`).
"""

from __future__ import annotations

from sumo_ayss.records.table import Column

__all__ = ["EPISODE_HAZARD_COLUMNS", "EPISODE_MEASURE_COLUMNS"]


def _measure(name: str, unit: str, meaning: str, allow_inf: bool = False) -> Column:
    return Column(name, "float", unit, meaning, nullable=True, allow_inf=allow_inf, since=True)


#: The measure columns, in :data:`~sumo_ayss.analysis.safety_measures.MEASURE_NAMES` order.
EPISODE_MEASURE_COLUMNS: tuple[Column, ...] = (
    _measure(
        "min_ttc_s",
        "s",
        "minimum 1-D time to collision while the bodies overlap laterally (0 = overlap, "
        "inf = never closing in one path)",
        allow_inf=True,
    ),
    _measure(
        "min_ttc_2d_s",
        "s",
        "minimum 2-D time to collision of the two bodies at constant velocities, any lanes "
        "(Guo et al. 2023; inf = never on a collision course)",
        allow_inf=True,
    ),
    _measure(
        "min_thw_s",
        "s",
        "minimum time headway of the VUT to the POV ahead in its path (inf = never)",
        allow_inf=True,
    ),
    _measure(
        "max_drac_mps2",
        "m/s²",
        "maximum deceleration rate to avoid a crash, (v_vut - v_pov)² / (2 gap), > 0; 0 if "
        "the VUT never closed in",
    ),
    _measure("vut_max_braking_mps2", "m/s²", "the VUT's largest deceleration, > 0 = braking"),
    _measure(
        "vut_max_jerk_mps3",
        "m/s³",
        "the VUT's largest |jerk| between decisions (NaN with fewer than two decisions)",
    ),
    _measure(
        "intrusion_ttc_s",
        "s",
        "cut-in: the VUT's TTC when the POV's body enters its lane (NaN: no intrusion)",
        allow_inf=True,
    ),
    _measure(
        "intrusion_gap_m",
        "m",
        "cut-in: POV rear minus VUT front when the POV's body enters the VUT's lane (< 0: "
        "beside it; NaN: no intrusion)",
    ),
    _measure(
        "pet_s",
        "s",
        "cut-in: post-encroachment time, from the intrusion until the VUT's front reaches "
        "the point where the POV's rear entered (NaN where undefined)",
    ),
    _measure(
        "impact_speed_mps",
        "m/s",
        "collision: magnitude of the relative velocity at impact (NaN: no collision)",
    ),
    _measure(
        "r157_ttc_lane_intrusion_s",
        "s",
        "cut-in: TTC when the POV's side is 0.3 m inside the VUT's lane (UN R157's "
        "TTC_LaneIntrusion; NaN: no such intrusion)",
        allow_inf=True,
    ),
    _measure(
        "r157_must_avoid",
        "-",
        "1 if UN R157's cut-in TTC condition says the collision must be avoided, 0 if not, "
        "NaN without an intrusion",
    ),
    _measure(
        "r157_closing_mps",
        "m/s",
        "cut-in: VUT speed minus POV speed at the R157 lane intrusion (> 0 closing in; NaN: "
        "no such intrusion)",
    ),
)


#: What the VUT did to the traffic behind it (issue 33; :mod:`sumo_ayss.analysis.hazards`):
#: NaN in files written before these columns, and the follower's without a follower.
EPISODE_HAZARD_COLUMNS: tuple[Column, ...] = (
    _measure(
        "follower_min_ttc_s",
        "s",
        "the follower's minimum TTC on the VUT (inf = never closing in; NaN: no follower)",
        allow_inf=True,
    ),
    _measure(
        "follower_min_thw_s",
        "s",
        "the follower's minimum time headway to the VUT (NaN: no follower)",
        allow_inf=True,
    ),
    _measure(
        "follower_max_braking_mps2",
        "m/s²",
        "the follower's largest deceleration, > 0 = braking (NaN: no follower)",
    ),
    _measure(
        "follower_max_drac_mps2",
        "m/s²",
        "the follower's largest deceleration rate to avoid the VUT (NaN: no follower)",
    ),
    _measure("rear_end", "-", "1 if the follower ran into the VUT, else 0 (NaN: no follower)"),
    _measure(
        "unjustified_braking",
        "-",
        "1 if the VUT braked harder than 3.4 m/s² while nothing ahead was critical, else 0",
    ),
    _measure(
        "unjustified_braking_max_mps2",
        "m/s²",
        "the VUT's hardest unjustified braking (0: none)",
    ),
    _measure(
        "unjustified_dv_mps",
        "m/s",
        "speed the VUT shed in unjustified hard braking, the sum of braking × decision period",
    ),
    _measure(
        "rear_end_unjustified",
        "-",
        "1 if a rear-end followed the VUT's unjustified braking within 3 s, else 0 (NaN: no "
        "follower)",
    ),
)
