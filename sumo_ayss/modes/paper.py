"""Paper mode: the paper's indicator, the aggressiveness of the SPCP's action in the
adversarial-yet-safe states, condensed into a safety index over headway bins
(:mod:`sumo_ayss.analysis.safety_index`; hierarchical bootstrap, the slow part).

Its verdict is computed for every report (``CaseAnalysis.paper_verdict``); a ranking
in this mode lists it only when it was asked for. The mode words its verdicts here: a
pairwise verdict (:func:`verdict_sentence`), one under the report's significance rule
(:func:`pair_sentence`, the rule itself: :func:`significance_rule`) and the headline.
"""

from __future__ import annotations

import dataclasses
import math
from typing import TYPE_CHECKING, Any

from sumo_ayss.modes.formatting import fmt_interval, fmt_num, fmt_p
from sumo_ayss.modes.registry import Mode, Standing, register_mode

if TYPE_CHECKING:
    from sumo_ayss.analysis.case import CaseAnalysis
    from sumo_ayss.analysis.case_verdict import CaseVerdict
    from sumo_ayss.analysis.significance import PairVerdict, SignificanceOptions
    from sumo_ayss.analysis.verdict import Verdict

__all__ = [
    "MIN_SEEDS_FOR_INTERVAL",
    "PAPER",
    "PaperMode",
    "diff_interval",
    "pair_sentence",
    "paper_headline",
    "significance_rule",
    "verdict_sentence",
]

NAME = "paper"

#: Why a paper verdict is missing (:data:`sumo_ayss.analysis.case_verdict.NoVerdict`).
_NO_VERDICT = {
    "no_samples": "No verdict yet: no VUT of this case has AYSS samples (ayss.csv).",
    "not_comparable": "No verdict: the safety indices of the top two VUTs are not comparable.",
}

_CONFOUNDED = (
    " Confounded: the SPCPs did not reach the same overall outcome (premise check), "
    "so this aggressiveness comparison does not isolate the VUTs' safety."
)


def _fmt_h_range(h_range: tuple[float, float]) -> str:
    """``"h ≤ 5 m"`` when the range starts at 0, ``"2 m ≤ h ≤ 5 m"`` otherwise."""
    lo, hi = h_range
    return f"h ≤ {hi:g} m" if lo == 0.0 else f"{lo:g} m ≤ h ≤ {hi:g} m"


#: Fewest seeds per VUT for a printed bootstrap interval (as for the seed-level
#: t-intervals: resampling two seeds cannot show the seed-to-seed spread).
MIN_SEEDS_FOR_INTERVAL = 3


def diff_interval(v: Verdict, lo: float | None = None, hi: float | None = None) -> str:
    """The interval of a paired verdict's difference (``lo``/``hi``: the oriented bounds,
    default ``diff_lo``/``diff_hi``), or "no interval with n seeds" under
    :data:`MIN_SEEDS_FOR_INTERVAL` seeds on either side."""
    n = min(v.n_seeds_a, v.n_seeds_b)
    if n < MIN_SEEDS_FOR_INTERVAL:
        return f"no interval with {n} seed{'s' if n != 1 else ''}"
    return fmt_interval(v.diff_lo if lo is None else lo, v.diff_hi if hi is None else hi)


def _ci(v: Verdict, pct: str, lo: float | None = None, hi: float | None = None) -> str:
    """``"95 % CI 0.10–0.80"``, or "no interval with 2 seeds" (:func:`diff_interval`)."""
    text = diff_interval(v, lo, hi)
    return text if text.startswith("no interval") else f"{pct} CI {text}"


def verdict_sentence(v: Verdict) -> str:
    """One quotable sentence stating a pairwise verdict and its statistics."""
    pct = f"{100.0 * v.level:g} %"
    where = f"adversarial-yet-safe states with {_fmt_h_range(v.h_range)}"
    if v.safer is None:
        text = (
            f"No significant difference in safety between {v.name_a} and "
            f"{v.name_b}: over {where}, the mean {v.indicator.name} of "
            f"{v.name_b}'s SPCPs minus {v.name_a}'s is "
            f"{v.indicator.amount(v.difference)} ({_ci(v, pct)}; "
            f"P({v.name_a} safer) {fmt_p(v.p_a_safer, cap_high=True)}; "
            f"{v.n_seeds_a} vs {v.n_seeds_b} seeds)."
        )
    else:
        text = _safer_sentence(v, pct, where)
    if not v.same_bins:
        text += " Caution: the two indices average over different headway bins."
    return text


def _safer_sentence(v: Verdict, pct: str, where: str) -> str:
    """The sentence when one VUT is significantly safer."""
    a_safer = v.safer == v.name_a
    other = v.name_b if a_safer else v.name_a
    diff = v.difference if a_safer else -v.difference
    lo, hi = (v.diff_lo, v.diff_hi) if a_safer else (-v.diff_hi, -v.diff_lo)
    p = v.p_a_safer if a_safer else 1.0 - v.p_a_safer
    n_s, n_o = (v.n_seeds_a, v.n_seeds_b) if a_safer else (v.n_seeds_b, v.n_seeds_a)
    return (
        f"{v.safer} is safer than {other}: its SPCPs {v.indicator.phrase(diff)} on "
        f"average over {where} ({_ci(v, pct, lo, hi)}; "
        f"P({v.safer} safer) {fmt_p(p, cap_high=True)}; {n_s} vs {n_o} seeds)."
    )


def pair_sentence(pair: PairVerdict) -> str:
    """One quotable sentence stating a verdict under the report's significance rule."""
    v = pair.verdict
    adjusted = (
        f", adjusted p {fmt_p(pair.p_family)} (Holm over the ranking's adjacent claims)"
        if pair.p_family is not None and pair.p_family != v.p_seed_welch
        else ""
    )
    if v.significant and not pair.significant:
        neutral = verdict_sentence(dataclasses.replace(v, safer=None, significant=False))
        why = (
            f"the seed-level Welch test gives p {fmt_p(v.p_seed_welch)}{adjusted} "
            f"(needs < {pair.welch_alpha:g})"
            if math.isfinite(v.p_seed_welch)
            else "the seed-level Welch test is undefined (it needs two seeds per VUT with spread)"
        )
        return (
            f"{neutral} The bootstrap interval alone excludes 0, but {why}, so the difference "
            "is not called significant."
        )
    welch = (
        f"p {fmt_p(v.p_seed_welch)}"
        if math.isfinite(v.p_seed_welch)
        else "undefined (it needs two seeds per VUT with spread)"
    )
    if math.isfinite(v.p_seed_welch):
        welch += adjusted
    return f"{verdict_sentence(v)} Seed-level Welch test: {welch}."


def significance_rule(options: SignificanceOptions) -> str:
    """The rule of the paper mode (:mod:`sumo_ayss.analysis.significance`), in words."""
    pct = f"{100 * options.level:g} %"
    return (
        "Paper-mode significance rule: a difference between two VUTs is called significant "
        "only when "
        f"BOTH the {pct} hierarchical-bootstrap interval of the difference of their safety "
        "indices excludes 0 AND the seed-level Welch t-test on the per-seed indices gives "
        f"p < {options.welch_alpha:g}, that p adjusted by Holm over the ranking's adjacent "
        "pairs. With only a few seeds per VUT the bootstrap alone is "
        "anti-conservative (resampling a few seeds understates the seed-to-seed spread), so the "
        "Welch test, which treats each seed's SPCP as one observation, must agree."
    )


def paper_headline(a: CaseAnalysis[Any], v: CaseVerdict) -> str:
    """The paper mode's verdict in words."""
    from sumo_ayss.analysis.significance import PairVerdict

    if isinstance(v.top, PairVerdict):
        text = pair_sentence(v.top)
    elif v.missing == "one_vut":
        only = a.ranking[0].name if a.ranking else "?"
        text = f"No verdict yet: only {only} has AYSS samples; a verdict needs two VUTs."
    else:
        text = _NO_VERDICT.get(v.missing, _NO_VERDICT["not_comparable"])
    text = f"[{NAME} mode] {text}"
    return text + _CONFOUNDED if v.caveat == "premise_not_met" else text


def _standings(a: CaseAnalysis[Any]) -> list[Standing]:
    pairs = {(p.verdict.name_a, p.verdict.name_b): p for p in a.pairs}
    order = [r.name for r in a.ranking]
    out = []
    for i, ranked in enumerate(a.ranking):
        nxt = order[i + 1] if i + 1 < len(order) else None
        pair = pairs.get((ranked.name, nxt)) if nxt else None
        out.append(
            Standing(
                rank=ranked.rank,
                vut=ranked.name,
                score=ranked.point,
                lo=ranked.lo,
                hi=ranked.hi,
                n_seeds=ranked.n_seeds,
                next_vut=nxt,
                significant=pair.significant if pair else None,
                ranked_apart=bool(pair.significant) if pair else False,
                p=pair.verdict.p_seed_welch if pair else None,
                p_adjusted=pair.p_family if pair else None,
                margin=pair.verdict.difference if pair else math.nan,
                margin_lo=pair.verdict.diff_lo if pair else math.nan,
                margin_hi=pair.verdict.diff_hi if pair else math.nan,
                test="Welch t" if pair else "",
                # Tagged like the seed-level modes' sentences ("[exposure mode] ...").
                vs_next=f"[{NAME} mode] {pair_sentence(pair)}" if pair else "",
            )
        )
    return out


def _ends(a: CaseAnalysis[Any], safest: str, least: str) -> tuple[bool, float]:
    pair = next(
        (p for p in a.pairs if {p.verdict.name_a, p.verdict.name_b} == {safest, least}),
        None,
    )
    return pair is not None and pair.safer == safest, math.nan


def _score_text(a: CaseAnalysis[Any], s: Standing) -> str:
    ci = fmt_interval(s.lo, s.hi)
    return f"{fmt_num(s.score)} {a.info.indicator.unit}" + (f" ({ci})" if ci else "")


class PaperMode(Mode):
    """Paper mode: its ranking, verdict and words (see the module docstring)."""

    def available(self, a: CaseAnalysis[Any]) -> bool:
        # Ranked in paper mode only: the bootstrap is skipped in the other modes.
        return bool(a.ranking) and a.mode == NAME

    def standings(self, a: CaseAnalysis[Any]) -> list[Standing]:
        return _standings(a)

    def verdict(self, a: CaseAnalysis[Any]) -> CaseVerdict:
        return a.paper_verdict  # computed first, for every report

    def headline(self, a: CaseAnalysis[Any], v: CaseVerdict) -> str:
        return paper_headline(a, v)

    def unit(self, a: CaseAnalysis[Any]) -> str:
        return f"{a.info.indicator.unit} (higher = safer)"

    def ends(self, a: CaseAnalysis[Any], safest: str, least: str) -> tuple[bool, float]:
        return _ends(a, safest, least)

    def score_text(self, a: CaseAnalysis[Any], s: Standing) -> str:
        return _score_text(a, s)

    def interval_text(self, lo: float, hi: float, n_seeds: int, digits: int) -> str:
        return fmt_interval(lo, hi, digits)


PAPER = register_mode(
    PaperMode(
        name=NAME,
        description=(
            "Paper mode: the paper's indicator, the aggressiveness of the SPCP's action in the "
            "adversarial-yet-safe states (POV acceleration in car-following, Δv̄ in cut-in), "
            "condensed into a safety index over headway bins; meaningful only when the SPCPs "
            "reached the same overall outcome (the premise check)."
        ),
        score_name="safety index (higher = safer)",
        interval_name="bootstrap interval",
        digits=2,
        needs_safety_index=True,
    )
)
