"""Pure-math analysis of AYSS results: metrics, statistics, safety index and ranking.

Depends on numpy and the standard library only (no SUMO, no torch), so reports and tests can
use it on any machine.

* :mod:`.metrics` — time to collision, Δv̄.
* :mod:`.stats` — Student t intervals, binned means, hierarchical bootstrap.
* :mod:`.ranking` — safety index per VUT, pairwise verdicts, rankings.
"""

from __future__ import annotations

from sumo_ayss.analysis.metrics import (
    delta_v_bar,
    delta_v_bar_between,
    time_to_collision,
    ttc_longitudinal,
)
from sumo_ayss.analysis.ranking import (
    DELTA_V_BAR,
    POV_ACCELERATION,
    Indicator,
    RankedVut,
    SafetyIndex,
    Verdict,
    compare,
    rank,
    safety_index,
)
from sumo_ayss.analysis.stats import (
    BinnedStats,
    binned_mean_ci,
    bootstrap_ci,
    cohens_d,
    hierarchical_bootstrap,
    mean_ci,
    t_quantile,
    welch_t_test,
)

__all__ = [
    "DELTA_V_BAR",
    "POV_ACCELERATION",
    "BinnedStats",
    "Indicator",
    "RankedVut",
    "SafetyIndex",
    "Verdict",
    "binned_mean_ci",
    "bootstrap_ci",
    "cohens_d",
    "compare",
    "delta_v_bar",
    "delta_v_bar_between",
    "hierarchical_bootstrap",
    "mean_ci",
    "rank",
    "safety_index",
    "t_quantile",
    "time_to_collision",
    "ttc_longitudinal",
    "welch_t_test",
]
