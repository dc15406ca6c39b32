"""Case ``lead_and_cut_in``: two lanes, a lead POV ahead of the VUT and a cut-in POV in the
left lane, one of them the episode's primary adversary (issue 39; docs/cases.md).

Env :class:`sumo_ayss.envs.lead_and_cut_in.LeadAndCutInEnv`; AYSS indicator: Δv̄ [m/s] of
the primary POV one step after the SPCP's action, run in SUMO
(:func:`sumo_ayss.scenarios.ayss_two_pov.lead_and_cut_in_rows`).
"""

from __future__ import annotations

from sumo_ayss.cases.registry import BASE_OBSERVATION, Case, Indicator, register_case

__all__ = ["AYSS_SUPPORT_GAP_M", "AYSS_SUPPORT_SPEED_MPS", "INDICATOR_COLUMN", "LEAD_AND_CUT_IN"]

#: ``indicator_name`` of the case's AYSS rows: Δv̄ of the primary POV [m/s], < 0 closes in.
INDICATOR_COLUMN = "delta_v_bar_primary_mps"

#: The supporting (cut-in) POV in the AYSS Monte Carlo: 40 m ahead in the left lane at
#: 20 m/s, outside the 5 m box of the primary lead POV.
AYSS_SUPPORT_SPEED_MPS = 20.0
AYSS_SUPPORT_GAP_M = 40.0

LEAD_AND_CUT_IN = register_case(
    Case(
        name="lead_and_cut_in",
        title="Two-lane lead and cut-in (two POVs)",
        network="straight_2lane",
        lanes=2,
        lane_change=True,
        vec_env=False,
        default_grid=False,  # the paper's two cases stay the default grid
        povs=2,
        start_filter="sumo_ayss.envs.two_pov:start_filter",
        env="sumo_ayss.envs.lead_and_cut_in:LeadAndCutInEnv",
        gym_id="sumo_ayss/LeadAndCutIn-v0",
        observation=(
            *BASE_OBSERVATION,
            "same_lane",
            "v_support_mps",
            "h_support_m",
            "primary_cut_in",
        ),
        # The lead is the primary, in the VUT's lane; the cut-in POV supports, far ahead.
        ayss_fixed_obs=(1.0, AYSS_SUPPORT_SPEED_MPS, AYSS_SUPPORT_GAP_M, 0.0),
        ayss_rows="sumo_ayss.scenarios.ayss_two_pov:lead_and_cut_in_rows",
        indicator_column=INDICATOR_COLUMN,
        indicator=Indicator("Δv̄ (primary POV)", "m/s", "close in {amount} faster (lower Δv̄)"),
        axis_label=r"$\Delta\bar{v}$ of the primary POV [m/s]",
        symbol="Δv̄ (primary)",
        outcome_columns=("crash", "lane_change", "return", "headway"),
        outcome_note=(
            "Crash: the primary POV and the VUT touched; contacts of the supporting POV end "
            "an episode as the POVs' failure and are not the VUT's crashes (docs/cases.md)."
        ),
    )
)
"""The lead-and-cut-in case."""
