"""How each case names its aggressiveness indicator, titles and paper references.

Pure data (no SUMO, no torch): the analysis words its verdicts with it, the report titles
its sections and axes with it.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from sumo_ayss.analysis.safety_index import DELTA_V_BAR, POV_ACCELERATION, Indicator

__all__ = ["CASES", "CaseInfo", "case_info"]


@dataclass(frozen=True)
class CaseInfo:
    """How a case is named and drawn.

    Attributes:
        title: Section title, e.g. ``"One-lane car-following"``.
        indicator: Naming of its aggressiveness indicator for verdict sentences.
        axis_label: Matplotlib axis label of the indicator, with unit.
        symbol: The indicator's symbol in text (HTML / Markdown).
        paper_figure: The paper figure the indicator plot reproduces.
        paper_table: The paper table the outcome table reproduces.
        exposure_caution: Empty when exposure mode recovered known safety orders in this
            case (results/ladders); otherwise the caution every exposure verdict carries.
    """

    title: str
    indicator: Indicator
    axis_label: str
    symbol: str
    paper_figure: str
    paper_table: str
    exposure_caution: str = ""


CASES: Mapping[str, CaseInfo] = {
    "car_following": CaseInfo(
        title="One-lane car-following",
        indicator=POV_ACCELERATION,
        axis_label="POV acceleration implied by the SPCP's action [m/s²]",
        symbol="POV acceleration",
        paper_figure="Fig. 4",
        paper_table="Table II",
    ),
    "cut_in": CaseInfo(
        title="Two-lane cut-in",
        indicator=DELTA_V_BAR,
        axis_label=r"$\Delta\bar{v}$ [m/s]",
        symbol="Δv̄",
        paper_figure="Fig. 6",
        paper_table="Table III",
        exposure_caution=(
            "Caution: in cut-in, exposure mode has NOT recovered a known safety order: on the "
            "minGap ladder (results/ladders) the SPCPs extracted more reward from the VUTs "
            "with larger gaps, not less (docs/ranking.md). Treat this verdict as unvalidated."
        ),
    ),
}


def case_info(case: str) -> CaseInfo:
    """The :class:`CaseInfo` of ``case``; a generic one for an unknown case name."""
    if case in CASES:
        return CASES[case]
    return CaseInfo(
        title=case,
        indicator=Indicator(),
        axis_label="aggressiveness indicator",
        symbol="indicator",
        paper_figure="—",
        paper_table="—",
    )
