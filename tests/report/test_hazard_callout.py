"""Issue 33: the callout under the leaderboard names a VUT flagged OVER-BRAKING, or one the
cases rank at opposite ends, with each case's facts and the reason they suggest."""

from __future__ import annotations

from sumo_ayss.analysis.harm import VutOutcome
from sumo_ayss.report.sections.hazards import CaseFacts, callout_for


def _o(crashes: int, speed: float, dv: float | None = None, flag: bool = False) -> VutOutcome:
    h = None if dv is None else {"unjustified_braking": 0.5, "unjustified_dv_mps": dv}
    return VutOutcome(crashes, 100, 0.0, 0.1, speed, False, h, overbraking=flag)


def test_a_flagged_vut_is_named_with_the_reason() -> None:
    cf = CaseFacts(
        "car-following",
        {"ob": ("1", True, False), "pi2": ("2", False, False), "pi1": ("3", False, True)},
        {"ob": _o(3, 12.4, 4.0, True), "pi2": _o(3, 13.3, 1.9), "pi1": _o(3, 14.6, 0.8)},
    )
    c = callout_for([cf])
    assert c is not None and c.kind == "warning" and len(c.lines) == 1
    line = c.lines[0]
    assert line.startswith("ob is flagged OVER-BRAKING.")
    assert "rank 1 of 3" in line and "4.00 m/s shed per episode (median VUT 1.90)" in line
    assert "mean speed 93 % of the median VUT's" in line and "brakes for nothing" in line


def test_cases_that_disagree_are_named_and_explained() -> None:
    places_cf = {"a": ("1", True, False), "b": ("2", False, False), "c": ("3", False, True)}
    places_ci = {"b": ("1", True, False), "c": ("2", False, False), "a": ("3", False, True)}
    speeds = {"a": 20.0, "b": 15.0, "c": 15.0}
    cases = [
        CaseFacts("car-following", places_cf, {v: _o(2, s) for v, s in speeds.items()}),
        CaseFacts("cut-in", places_ci, {v: _o(10, s) for v, s in speeds.items()}),
    ]
    c = callout_for(cases)
    assert c is not None and len(c.lines) == 1  # only a: first in one case, last in the other
    line = c.lines[0]
    assert line.startswith("The cases disagree about a: first in car-following, last in cut-in.")
    assert "in cut-in, where it ranks last, it drives faster than the median VUT" in line
    # a VUT that ranks last no faster than the others: no reason is made up
    slow = {"a": 15.0, "b": 15.0, "c": 15.0}
    cases = [CaseFacts(x.title, x.places, {v: _o(2, s) for v, s in slow.items()}) for x in cases]
    c = callout_for(cases)
    assert c is not None and "Nothing in these columns explains it" in c.lines[0]


def test_nothing_to_say_means_no_callout() -> None:
    tied = {"a": ("1–2", True, True), "b": ("1–2", True, True)}
    agree = {"a": ("1", True, False), "b": ("2", False, True)}
    out = {"a": _o(1, 15.0, 0.1), "b": _o(1, 15.0, 0.2)}
    assert callout_for([CaseFacts("x", tied, out), CaseFacts("y", agree, out)]) is None
    assert callout_for([CaseFacts("x", agree, out), CaseFacts("y", agree, out)]) is None
