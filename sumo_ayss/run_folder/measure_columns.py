"""The per-episode surrogate-safety-measure columns of ``outcome.csv`` and ``crossplay.csv``.

One column per field of :class:`~sumo_ayss.analysis.safety_measures.EpisodeMeasures`
(definitions, units, signs and references there). Files written before these columns read
as NaN ("not recorded": :attr:`~sumo_ayss.run_folder.table.Column.since`).
"""

from __future__ import annotations

from sumo_ayss.run_folder.table import Column

__all__ = ["EPISODE_MEASURE_COLUMNS"]


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
