"""Paper mode: the paper's indicator, the aggressiveness of the SPCP's action in the
adversarial-yet-safe states, condensed into a safety index over headway bins
(:mod:`sumo_ayss.analysis.safety_index`; hierarchical bootstrap, the slow part).

Its result (:class:`PaperResult`, :func:`compute_paper`: the safety indices, their
ranking and pairwise verdicts, the premise check and the verdict) is computed for every
report; a ranking in this mode lists it only when it was asked for. The mode words its
verdicts here: a pairwise verdict (:func:`verdict_sentence`), one under the report's
significance rule (:func:`pair_sentence`, the rule itself: :func:`significance_rule`) and
the headline.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from sumo_ayss.modes.formatting import fmt_interval, fmt_num, fmt_p
from sumo_ayss.modes.registry import Mode, Standing, mode_result, register_mode

if TYPE_CHECKING:
    from sumo_ayss.analysis.case import CaseAnalysis
    from sumo_ayss.analysis.case_verdict import CaseVerdict
    from sumo_ayss.analysis.premise import Premise
    from sumo_ayss.analysis.ranking import RankedVut, SafetyIndex
    from sumo_ayss.analysis.significance import PairVerdict, SignificanceOptions
    from sumo_ayss.analysis.verdict import Verdict

__all__ = [
    "MIN_SEEDS_FOR_INTERVAL",
    "PAPER",
    "PaperMode",
    "PaperResult",
    "compute_paper",
    "diff_interval",
    "pair_sentence",
    "paper_headline",
    "paper_result",
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


@dataclass(frozen=True)
class PaperResult:
    """The paper mode's result for one case.

    Attributes:
        verdict: The paper mode's verdict (also when another mode was asked for).
        indices: ``{vut: safety index}`` for VUTs with AYSS samples (empty when the
            analysis drew no bootstrap, :attr:`~sumo_ayss.analysis.case.CaseAnalysis.bootstrap`).
        ranking: VUTs safest first (point estimate).
        pairs: Verdicts of every pair, in ranking order (A ranked above B).
        premise: Whether the SPCPs reached the same overall outcome (the premise of reading
            their aggressiveness), or None.
    """

    verdict: CaseVerdict
    indices: dict[str, SafetyIndex] = field(default_factory=dict)
    ranking: list[RankedVut] = field(default_factory=list)
    pairs: list[PairVerdict] = field(default_factory=list)
    premise: Premise | None = None


def compute_paper(a: CaseAnalysis[Any], name: str = "paper") -> PaperResult:
    """Safety index per VUT from its runs' AYSS samples (the hierarchical bootstrap, when
    ``a.bootstrap``), their ranking and pairwise verdicts under
    :func:`~sumo_ayss.analysis.significance.pair_verdict` (Holm over the adjacent pairs), the
    premise check over the runs' outcome summaries, and the verdict; a VUT without a safety
    index and a pair that is not comparable get a line in ``a.problems``."""
    from sumo_ayss.analysis.case import bootstrap_rng, vut_safety_index
    from sumo_ayss.analysis.case_verdict import paper_verdict
    from sumo_ayss.analysis.premise import premise_check
    from sumo_ayss.analysis.ranking import rank
    from sumo_ayss.analysis.significance import family_adjusted, pair_verdict
    from sumo_ayss.util.errors import ConfigError

    options = a.options
    indices = {}
    for vut, members in a.runs.items() if a.bootstrap else ():
        idx = vut_safety_index(members, options, bootstrap_rng(options, a.case, vut))
        if idx is not None:
            indices[vut] = idx
        else:
            a.problems.append(
                f"{vut}: no AYSS sample with h in [0, {options.h_max_m:g}] m, so no safety index"
            )
    ranking = rank(indices, level=options.level) if indices else []
    order = [r.name for r in ranking]
    pairs = []
    for i, first in enumerate(order):
        for second in order[i + 1 :]:
            try:
                pairs.append(
                    pair_verdict(
                        indices[first],
                        indices[second],
                        name_a=first,
                        name_b=second,
                        indicator=a.info.indicator,
                        level=options.level,
                        welch_alpha=options.welch_alpha,
                    )
                )
            except ConfigError as exc:
                a.problems.append(f"{first} vs {second}: not comparable ({exc})")
    pairs = family_adjusted(pairs, order)
    metrics: dict[str, dict[str, list[float]]] = {
        "mean_return": {},
        "crash_rate": {},
        "mean_final_headway_m": {},
    }
    for vut, members in a.runs.items():
        for r in members:
            if r.outcome is None:
                continue
            for key in metrics:
                metrics[key].setdefault(vut, []).append(getattr(r.outcome, key).value)
    premise = premise_check(metrics, tolerances=options.premise_tolerances, level=options.level)
    premise_met = premise is None or not premise.metrics or premise.met
    verdict = paper_verdict(name, ranking, pairs, premise_met=premise_met)
    return PaperResult(verdict, indices, ranking, pairs, premise)


def paper_result(a: CaseAnalysis[Any], name: str = NAME) -> PaperResult:
    """The paper result of a case (that of the mode ``name``, built from this record)."""
    return mode_result(a, name, PaperResult)


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
        ranking = paper_result(a).ranking
        only = ranking[0].name if ranking else "?"
        text = f"No verdict yet: only {only} has AYSS samples; a verdict needs two VUTs."
    else:
        text = _NO_VERDICT.get(v.missing, _NO_VERDICT["not_comparable"])
    text = f"[{NAME} mode] {text}"
    return text + _CONFOUNDED if v.caveat == "premise_not_met" else text


def _standings(result: PaperResult) -> list[Standing]:
    pairs = {(p.verdict.name_a, p.verdict.name_b): p for p in result.pairs}
    order = [r.name for r in result.ranking]
    out = []
    for i, ranked in enumerate(result.ranking):
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


def _ends(result: PaperResult, safest: str, least: str) -> tuple[bool, float]:
    pair = next(
        (p for p in result.pairs if {p.verdict.name_a, p.verdict.name_b} == {safest, least}),
        None,
    )
    return pair is not None and pair.safer == safest, math.nan


def _score_text(a: CaseAnalysis[Any], s: Standing) -> str:
    ci = fmt_interval(s.lo, s.hi)
    return f"{fmt_num(s.score)} {a.info.indicator.unit}" + (f" ({ci})" if ci else "")


class PaperMode(Mode):
    """Paper mode: its ranking, verdict and words (see the module docstring)."""

    def compute(self, a: CaseAnalysis[Any]) -> PaperResult:
        return compute_paper(a, self.name)

    def available(self, a: CaseAnalysis[Any]) -> bool:
        # Ranked in paper mode only: the bootstrap is skipped in the other modes.
        return bool(paper_result(a, self.name).ranking) and a.mode == NAME

    def standings(self, a: CaseAnalysis[Any]) -> list[Standing]:
        return _standings(paper_result(a, self.name))

    def verdict(self, a: CaseAnalysis[Any]) -> CaseVerdict:
        return paper_result(a, self.name).verdict  # computed for every report

    def headline(self, a: CaseAnalysis[Any], v: CaseVerdict) -> str:
        return paper_headline(a, v)

    def unit(self, a: CaseAnalysis[Any]) -> str:
        return f"{a.info.indicator.unit} (higher = safer)"

    def ends(self, a: CaseAnalysis[Any], safest: str, least: str) -> tuple[bool, float]:
        return _ends(paper_result(a, self.name), safest, least)

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
