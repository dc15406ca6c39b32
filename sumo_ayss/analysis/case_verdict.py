"""The verdict on one case, as a record: which mode ranks, the ranking, the test of the top
pair and what kind of headline it makes (numpy-free, the stdlib only).

:func:`paper_verdict` builds the paper mode's from its safety-index ranking and pairwise
verdicts, :func:`seed_verdict` a seed-level mode's (exposure, cross-play) from its ranking
rows. Nothing here words a verdict: the ranking modes do (``Mode.headline``, reached by
:func:`sumo_ayss.modes.headline_text`), and the report and ``rank`` show their words.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

from sumo_ayss.analysis.ranking import RankedVut
from sumo_ayss.analysis.seeds import SeedComparison, SeedRankRow
from sumo_ayss.analysis.significance import PairVerdict

__all__ = ["CaseVerdict", "Caveat", "HeadlineKind", "NoVerdict", "paper_verdict", "seed_verdict"]

HeadlineKind = Literal["safer", "none", "warning"]
"""``"safer"``: the top VUT is significantly safer than the next; ``"none"``: no significant
difference; ``"warning"``: no verdict, or one to read with care (see :attr:`CaseVerdict.caveat`)."""

NoVerdict = Literal["", "no_samples", "one_vut", "not_comparable", "too_few"]
"""Why a mode has no verdict: ``""`` (it has one); ``"no_samples"`` (no VUT has AYSS
samples); ``"one_vut"`` (only one VUT has them); ``"not_comparable"`` (the top two safety
indices cannot be compared); ``"too_few"`` (outcomes of fewer than two VUTs)."""

Caveat = Literal["", "premise_not_met", "case_caution"]
"""What to read a verdict with: ``"premise_not_met"`` (paper mode: the SPCPs did not reach the
same overall outcome, :mod:`.premise`); ``"case_caution"`` (exposure mode: the case's own
caution, :attr:`sumo_ayss.cases.Case.exposure_caution`)."""


@dataclass(frozen=True)
class CaseVerdict:
    """One mode's verdict on a case, as data (the modes word it).

    Attributes:
        mode: The mode whose ranking and test this is; another than the mode asked for
            when that one had no ranking (cross-play without a table: exposure's).
        kind: What kind of headline it makes (:data:`HeadlineKind`).
        order: VUTs safest first, as the verdict ranks them; empty when it ranks none (the
            paper mode without a comparable top pair).
        apart: Per adjacent pair of ``order``, whether the two differ significantly.
        top: The test of the top two VUTs: a :class:`~.significance.PairVerdict` (paper
            mode, with the bootstrap interval and the seed-level Welch p-value) or a
            :class:`~.seeds.SeedComparison` (seed-level modes, with its t-test's p); None
            without a verdict.
        pairs: Every comparison of the mode, each pair once (A ranked above B).
        missing: Why there is no verdict (:data:`NoVerdict`); "" when there is one.
        caveat: What to read the verdict with (:data:`Caveat`); "" for nothing.
    """

    mode: str
    kind: HeadlineKind
    order: tuple[str, ...] = ()
    apart: tuple[bool, ...] = ()
    top: PairVerdict | SeedComparison | None = None
    pairs: tuple[PairVerdict | SeedComparison, ...] = ()
    missing: NoVerdict = ""
    caveat: Caveat = ""


def paper_verdict(
    mode: str,
    ranking: Sequence[RankedVut],
    pairs: Sequence[PairVerdict],
    *,
    premise_met: bool = True,
) -> CaseVerdict:
    """The paper mode's verdict: the top pair of the safety-index ranking under the
    report's significance rule.

    Args:
        mode: The paper mode's name.
        ranking: VUTs safest first (:func:`~.ranking.rank`).
        pairs: Their pairwise verdicts, A ranked above B (a pair that is not comparable is
            absent).
        premise_met: Whether the premise check passed (or could not be made); if not, the
            verdict carries ``caveat="premise_not_met"`` and a "safer" one is a warning.
    """
    caveat: Caveat = "" if premise_met else "premise_not_met"
    order = tuple(r.name for r in ranking)
    top = next((p for p in pairs if order and p.verdict.name_a == order[0]), None)
    if len(order) < 2 or top is None:
        missing: NoVerdict = (
            "no_samples" if not order else "one_vut" if len(order) == 1 else "not_comparable"
        )
        return CaseVerdict(mode, "warning", pairs=tuple(pairs), missing=missing, caveat=caveat)
    by_pair = {(p.verdict.name_a, p.verdict.name_b): p for p in pairs}
    apart = []
    for a, b in itertools.pairwise(order):
        pair = by_pair.get((a, b))
        apart.append(pair is not None and pair.significant)
    kind: HeadlineKind = "safer" if top.significant else "none"
    if kind == "safer" and not premise_met:
        kind = "warning"
    return CaseVerdict(mode, kind, order, tuple(apart), top, tuple(pairs), caveat=caveat)


def seed_verdict(
    mode: str,
    rows: Sequence[SeedRankRow],
    pairs: Sequence[SeedComparison],
    *,
    caution: bool = False,
) -> CaseVerdict:
    """A seed-level mode's verdict: its ranking and the test of its top two VUTs.

    Args:
        mode: The mode's name.
        rows: Its ranking, safest first (:func:`~.seeds.rank_seeds`).
        pairs: Its comparisons of every pair.
        caution: The case asks for caution in this mode (``caveat="case_caution"``): the
            verdict is a warning.
    """
    order = tuple(r.name for r in rows)
    apart = tuple(bool(r.significant_vs_next) for r in rows[:-1])
    top = rows[0].vs_next if len(rows) >= 2 else None
    if top is None:
        return CaseVerdict(mode, "warning", order, apart, pairs=tuple(pairs), missing="too_few")
    kind: HeadlineKind = "warning" if caution else "safer" if top.significant else "none"
    caveat: Caveat = "case_caution" if caution else ""
    return CaseVerdict(mode, kind, order, apart, top, tuple(pairs), caveat=caveat)
