"""Case ``cut_in``: two lanes, the POV in the left lane may cut in (paper V-B, Fig. 6,
Table III).

Env :class:`sumo_ayss.envs.cut_in.CutInEnv`; AYSS indicator: Δv̄ [m/s] one step after the
SPCP's lane change, run in SUMO (:func:`sumo_ayss.scenarios.ayss.cut_in_rows`).
"""

from __future__ import annotations

from sumo_ayss.cases.registry import BASE_OBSERVATION, Case, Indicator, PaperRow, register_case

__all__ = ["CUT_IN", "DELTA_V_BAR", "INDICATOR_COLUMN"]

#: ``indicator_name`` of cut-in AYSS rows: Δv̄ [m/s], < 0 closes in.
INDICATOR_COLUMN = "delta_v_bar_mps"

DELTA_V_BAR = Indicator("Δv̄", "m/s", "close in {amount} faster (lower Δv̄)")
"""Cut-in indicator: relative velocity projected on relative position, m/s."""

CUT_IN = register_case(
    Case(
        name="cut_in",
        title="Two-lane cut-in",
        network="straight_2lane",
        lanes=2,
        lane_change=True,
        env="sumo_ayss.envs.cut_in:CutInEnv",
        gym_id="sumo_ayss/CutIn-v0",
        observation=(*BASE_OBSERVATION, "same_lane"),
        ayss_fixed_obs=(0.0,),  # the POV in the left lane: the cut-in moment
        ayss_rows="sumo_ayss.scenarios.ayss:cut_in_rows",
        indicator_column=INDICATOR_COLUMN,
        indicator=DELTA_V_BAR,
        axis_label=r"$\Delta\bar{v}$ [m/s]",
        symbol="Δv̄",
        outcome_columns=(
            "crash",
            "lane_change",
            "lc_return",
            "lc_headway",
            "lc_episodes",
            "return_all",
            "headway_all",
        ),
        outcome_note=(
            "As in the paper, r̄_epi and h̄ are over episodes with a lane change and no collision."
        ),
        paper_figure="Fig. 6",
        paper_table="Table III",
        paper_rows=(
            PaperRow("pi1", 1, 1.0, 99.0, 20.99, 0.36),
            PaperRow("pi1", 2, 2.0, 99.0, 20.74, 0.36),
            PaperRow("pi1", 3, 0.5, 98.0, 20.78, 0.36),
            PaperRow("pi2", 1, 3.5, 100.0, 20.41, 0.41),
            PaperRow("pi2", 2, 1.0, 100.0, 20.93, 0.38),
            PaperRow("pi2", 3, 1.0, 100.0, 21.14, 0.35),
        ),
        exposure_caution=(
            "Caution: in cut-in, exposure mode has NOT recovered a known safety order: on the "
            "minGap and time-headway ladders (results/ladders) each VUT's own SPCPs differ "
            "more than the VUTs do, and no ladder was ranked (docs/ranking.md). Treat this "
            "verdict as unvalidated; cross-play is."
        ),
        one_decision_note=(
            "Cut-in, one decision: the POV starts its lane change from the centre of its own "
            "lane, so during the first 0.2 s a SUMO car-following VUT does not see it yet and "
            "drives freely; one-decision responses then differ only where the VUTs' free "
            "driving differs, and Δv̄ after one step can differ between SPCPs only through "
            "the states at which they choose to cut in. The reaction to the cut-in itself "
            "shows over two decisions (--decisions 2)."
        ),
    )
)
"""The cut-in case."""
