"""The callout under the leaderboard about what the VUTs do to the traffic behind them
(issue 33): a VUT flagged OVER-BRAKING, or one the cases rank at opposite ends, and why.

A VUT can look safe in one case and not in another for reasons the harm score alone does
not show: braking for nothing keeps every gap wide (low harm, a hazard to the follower), and
a VUT that drives faster than the others meets the POV's moves faster. The callout puts, per
such VUT and case, its rank, crash rate, mean speed against the median VUT's and its
unjustified braking beside each other, with a sentence saying which of these explains it.
Nothing is shown for a study without hazards unless the cases disagree.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from sumo_ayss.analysis.case import CaseAnalysis
from sumo_ayss.analysis.harm import VutOutcome
from sumo_ayss.modes import EXPOSURE, get_mode
from sumo_ayss.modes.formatting import rank_labels
from sumo_ayss.report.blocks import Callout
from sumo_ayss.run_folder import RunRecord

__all__ = ["CaseFacts", "callout_for", "hazard_callout"]


@dataclass(frozen=True)
class CaseFacts:
    """What the callout reads of one case.

    Attributes:
        title: The case's title.
        places: Per VUT, safest first: its rank label, whether it is in the first rank group,
            whether in the last.
        outcomes: Per VUT, its crashes, mobility and hazards (the ranking mode's).
    """

    title: str
    places: Mapping[str, tuple[str, bool, bool]]
    outcomes: Mapping[str, VutOutcome]


def _places(a: CaseAnalysis[RunRecord]) -> dict[str, tuple[str, bool, bool]]:
    """Per VUT: its rank label, whether it is in the case's first rank group and in its
    last (both for a case whose VUTs are all tied)."""
    standings = get_mode(a.ranking_mode).standings(a)
    if not standings:
        return {}
    labels = rank_labels([bool(s.significant) for s in standings[:-1]])
    first, last = labels[0], labels[-1]
    return {
        s.vut: (lab, lab == first, lab == last) for s, lab in zip(standings, labels, strict=True)
    }


def _outcomes(a: CaseAnalysis[RunRecord]) -> Mapping[str, VutOutcome]:
    """The ranking mode's outcomes, else the VUTs' own SPCPs' (as the leaderboard's)."""
    return get_mode(a.ranking_mode).outcomes(a) or EXPOSURE.outcomes(a)


def _median(values: Sequence[float]) -> float:
    known = [v for v in values if math.isfinite(v)]
    return float(np.median(known)) if known else math.nan


#: A VUT ranked last that drove this much faster than the median VUT is said to meet the
#: POV's moves faster (a description, not a test).
FASTER = 1.05


def _case_text(c: CaseFacts, vut: str) -> tuple[str, str]:
    """One case's facts about ``vut`` and the reason they suggest ("" when none stands out)."""
    rank, first, last = c.places[vut]
    last = last and not first
    outcomes = c.outcomes
    o = outcomes.get(vut)
    text = f"{c.title}: rank {rank} of {len(c.places)}"
    if o is None:
        return text, ""
    speed_median = _median([x.mobility for x in outcomes.values()])
    crash_median = _median([x.crash_rate for x in outcomes.values()])
    text += f", crashes {100 * o.crash_rate:.1f} % (median VUT {100 * crash_median:.1f} %)"
    faster = last and math.isfinite(o.mobility) and o.mobility > FASTER * speed_median
    if math.isfinite(o.mobility) and math.isfinite(speed_median) and speed_median > 0:
        text += f", mean speed {100 * o.mobility / speed_median:.0f} % of the median VUT's"
    h = o.hazards
    if h is not None and math.isfinite(h.get("unjustified_dv_mps", math.nan)):
        dv_median = _median(
            [(x.hazards or {}).get("unjustified_dv_mps", math.nan) for x in outcomes.values()]
        )
        text += (
            f", unjustified hard braking in {100 * h['unjustified_braking']:.0f} % of episodes, "
            f"{h['unjustified_dv_mps']:.2f} m/s shed per episode (median VUT {dv_median:.2f})"
        )
    if o.overbraking:
        text += ", flagged OVER-BRAKING"
        why = (
            f"in {c.title} its harm is low because it brakes for nothing: every gap stays "
            "wide, and the traffic behind it pays (read its rank there with the flag)"
        )
    elif faster:
        why = (
            f"in {c.title}, where it ranks last, it drives faster than the median VUT and "
            "so meets the POV's moves with less time to answer"
        )
    else:
        why = ""
    return text, why


def hazard_callout(analyses: Sequence[CaseAnalysis[RunRecord]]) -> Callout | None:
    """:func:`callout_for` the cases of ``analyses`` (their ranking modes)."""
    return callout_for([CaseFacts(a.info.title, _places(a), _outcomes(a)) for a in analyses])


def callout_for(cases: Sequence[CaseFacts]) -> Callout | None:
    """The callout naming every VUT flagged OVER-BRAKING in a case, or ranked in the first
    rank group of one case and the last of another (the cases disagree about it), with
    each case's facts and the reason they suggest; None when there is none."""
    vuts = list(dict.fromkeys(v for c in cases for v in c.places))
    lines: list[str] = []
    for vut in vuts:
        mine = [c for c in cases if vut in c.places]
        flagged = any(o.overbraking for c in mine if (o := c.outcomes.get(vut)) is not None)
        top = [c.title for c in mine if c.places[vut][1] and not c.places[vut][2]]
        bottom = [c.title for c in mine if c.places[vut][2] and not c.places[vut][1]]
        disagree = bool(top) and bool(bottom)
        if not flagged and not disagree:
            continue
        facts, whys = zip(*(_case_text(c, vut) for c in mine), strict=True)
        head = (
            f"The cases disagree about {vut}: first in {', '.join(top)}, "
            f"last in {', '.join(bottom)}."
            if disagree
            else f"{vut} is flagged OVER-BRAKING."
        )
        reasons = [w for w in whys if w]
        why = (
            " What the columns suggest: " + "; ".join(reasons) + "."
            if reasons
            else " Nothing in these columns explains it: read its crash rate and near-misses "
            "in each case's section."
        )
        lines.append(f"{head} " + "; ".join(facts) + "." + why)
    if not lines:
        return None
    return Callout("What the leaderboard's ranks hide", tuple(lines), "warning")
