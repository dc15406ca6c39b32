"""Pure-math analysis of AYSS results: metrics, statistics, safety index and ranking.

Depends on numpy, scipy and the standard library only (no SUMO, no torch), so reports and
tests can use it on any machine.

* :mod:`.metrics` — time to collision, Δv̄.
* :mod:`.validate`, :mod:`.stats`, :mod:`.bootstrap` — argument checks,
  Student t (scipy), intervals and binned means, hierarchical bootstraps.
* :mod:`.safety_index`, :mod:`.verdict`, :mod:`.ranking` — safety index per VUT, pairwise
  verdicts, rankings; :mod:`.significance` — the report's two-test rule.
* :mod:`.seeds`, :mod:`.premise` — seed-level (exposure) ranking, the premise check.
* :mod:`.case` — everything above for one case's runs (:func:`.case.analyse_case`), with
  the verdict of the mode asked for as a record (:mod:`.case_verdict`).

Numbers and records only: the ranking modes (:mod:`sumo_ayss.modes`) word the verdicts, the
report (:mod:`sumo_ayss.report`) the rest.
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
