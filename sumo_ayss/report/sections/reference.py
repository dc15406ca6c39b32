"""Blocks of (k), each VUT against the careful human, and the same as ``ranking.md`` lines."""

from __future__ import annotations

from collections.abc import Sequence

from sumo_ayss.analysis.case import CaseAnalysis
from sumo_ayss.analysis.reference import ReferenceComparison, ReferenceReading
from sumo_ayss.modes.crossplay import crossplay_result
from sumo_ayss.modes.formatting import fmt_num, fmt_prob
from sumo_ayss.report.blocks import Block, Heading, Paragraph, Table
from sumo_ayss.report.sections.common import crash_text
from sumo_ayss.run_folder import RunRecord

__all__ = [
    "EXPLANATION",
    "preventable_text",
    "reference_blocks",
    "reference_markdown",
    "scenario_set_line",
]

#: The paragraph a safety engineer can quote.
EXPLANATION = (
    "Would a competent and careful human driver have avoided these crashes? UN R157 sets "
    "that bar for an automated lane-keeping system. The reference driver (cc_driver: R157's "
    "careful human, reacting 0.75 s after a risk is perceived and braking to 0.774 g within "
    "0.6 s, with AEB) drives against the same trained opponents on the same scenarios as "
    "every VUT. Two readings follow. (1) Each VUT's harm against the reference's, paired by "
    "opponent block: 'safer than' or 'less safe than the careful human' where the "
    "Holm-adjusted p is at most the level, otherwise 'not distinguishable'. (2) Each VUT "
    "crash was replayed from the same start with the careful human in the VUT's place and "
    "the opponent repeating its recorded actions: a crash the careful human avoided is "
    "'preventable' and is the VUT's failure; one it could not avoid is not. The reference's "
    "own crash rate is the share of episodes no careful human survived against these "
    "opponents: a property of the scenario set, not of any VUT."
)

_REFERENCE_NAMES = {
    "cc_driver": "the careful human (cc_driver)",
    "fsm": "the Fuzzy Safety Model (fsm)",
    "rss": "RSS (rss)",
}


def _name(reference: str) -> str:
    return _REFERENCE_NAMES.get(reference, reference)


def _verdict(r: ReferenceComparison, reference: str) -> str:
    who = _name(reference)
    if r.verdict == "untested":
        return f"untested against {who}"
    if r.verdict == "not distinguishable":
        return f"not distinguishable from {who}"
    return f"{r.verdict} than {who}"


def preventable_text(r: ReferenceComparison) -> str:
    if r.labelled == 0 and r.crashes:
        return "not labelled"
    text = crash_text(r.preventable, r.episodes, r.preventable_lo, r.preventable_hi)
    if r.labelled < r.crashes:
        text += f" ({r.crashes - r.labelled} crashes not labelled)"
    return text


def _rows(reading: ReferenceReading) -> list[tuple[str, ...]]:
    rows: list[tuple[str, ...]] = []
    for r in reading.rows:
        t = r.test
        diff = f"{fmt_num(t.difference, 3)} ({fmt_num(t.lo, 3)} to {fmt_num(t.hi, 3)})"
        if t.lo != t.lo:  # NaN: too few blocks for an interval, or no spread at all
            why = f"with {t.n_a} blocks" if t.n_a < 3 else "identical in every block"
            diff = f"{fmt_num(t.difference, 3)} (no interval: {why})"
        rows.append(
            (
                r.vut,
                diff,
                fmt_prob(t.p),
                fmt_prob(r.p_adjusted),
                _verdict(r, reading.reference),
                crash_text(r.crashes, r.episodes, *_wilson(r)),
                preventable_text(r),
            )
        )
    return rows


def _wilson(r: ReferenceComparison) -> tuple[float, float]:
    from sumo_ayss.analysis.stats import wilson_interval

    return wilson_interval(r.crashes, r.episodes) if r.episodes else (float("nan"),) * 2


HEADERS = (
    "VUT",
    "harm − reference (95 % CI)",
    "p",
    "p (Holm)",
    "verdict",
    "crashes (95 % CI)",
    "preventable crashes (95 % CI)",
)


def _scenario_line(reading: ReferenceReading, case: str) -> str:
    # Where the reference's harm falls among the VUTs' (harm = reference + difference).
    harms = sorted((reading.harm + r.test.difference, r.vut) for r in reading.rows)
    safer = [v for h, v in harms if h < reading.harm]
    place = f"by harm it would rank {len(safer) + 1} of {len(harms) + 1}" + (
        f", after {', '.join(safer)}" if safer else ", first"
    )
    return (
        f"{_name(reading.reference)[:1].upper()}{_name(reading.reference)[1:]} crashed in "
        f"{crash_text(reading.crashes, reading.episodes, reading.crash_lo, reading.crash_hi)} "
        f"of the {case} episodes against this pool (its harm {fmt_num(reading.harm, 3)}; "
        f"{place}): episodes it could not survive, a property of the scenario set and the "
        "opponents."
    )


def scenario_set_line(a: CaseAnalysis[RunRecord]) -> str:
    """One sentence on the scenario set's inevitable-collision states ("" without them)."""
    ss = crossplay_result(a).scenario_set
    if ss is None:
        return ""
    return (
        f"{ss.ics} of the {ss.n} {a.case.replace('_', '-')} scenarios "
        f"({100 * ss.share:.1f} %, {100 * ss.lo:.1f}–{100 * ss.hi:.1f} %) are "
        "inevitable-collision states: a vehicle braking at 0.85 g from the first instant "
        "still touches a POV that brakes at once (or cuts in at once). Crashes drawn there "
        "are no driver's failure; the episodes start there because the ODD draws speeds and "
        "gaps independently."
    )


def reference_blocks(a: CaseAnalysis[RunRecord]) -> list[Block]:
    """(k) The case's VUTs against each reference driver that drove in cross-play, and the
    scenario set's inevitable-collision states."""
    result = crossplay_result(a)
    if not result.references and result.scenario_set is None:
        return []
    blocks: list[Block] = [Heading("(k) Against the careful human", 3), Paragraph(EXPLANATION)]
    if result.scenario_set is not None:
        blocks.append(Paragraph(scenario_set_line(a)))
    for reading in result.references.values():
        blocks.append(Paragraph(_scenario_line(reading, a.info.title)))
        blocks.append(
            Table(
                f"{a.info.title}: each VUT against {_name(reading.reference)} "
                f"(paired t over {reading.blocks} blocks; Holm over {len(reading.rows)} VUTs "
                f"at {reading.alpha:g})",
                HEADERS,
                tuple(_rows(reading)),
                (False, True, True, True, False, True, True),
                note="Harm difference < 0: the VUT suffered less harm than the reference "
                "under the same opponents. Preventable: crashes the careful human avoided "
                "when replaying the same start and opponent actions.",
            )
        )
    return blocks


def reference_markdown(analyses: Sequence[CaseAnalysis[RunRecord]]) -> list[str]:
    """``ranking.md`` lines: per case, the VUTs against each reference driver."""
    lines: list[str] = []
    for a in analyses:
        result = crossplay_result(a)
        if result.scenario_set is not None:
            lines += ["", f"Scenario set, {a.case}: {scenario_set_line(a)}"]
        for reading in result.references.values():
            lines += [
                "",
                f"Against {_name(reading.reference)}, {a.case}: {_scenario_line(reading, a.case)}",
                "",
                "| " + " | ".join(HEADERS) + " |",
                "|---|---|---:|---:|---|---|---|",
                *("| " + " | ".join(row) + " |" for row in _rows(reading)),
            ]
    return lines
