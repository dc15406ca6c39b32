"""Each VUT against the careful human: the reference driver's row of cross-play, and the
preventable crashes.

Two readings, both from cross-play (the pooled opponents on the common scenarios):

* **Against the reference driver** (default ``cc_driver``, R157's competent and careful
  human). The reference drives against every opponent of the pool like any VUT
  (``crossplay_reference.csv``), so each VUT's harm and the reference's are paired by
  opponent block exactly as two VUTs are (:func:`~.seeds.compare_seeds`, blocks = training
  seeds by default). The verdict per VUT: *safer than*, *not distinguishable from* or
  *less safe than* the careful human. There is one such test per VUT, so the p values are
  Holm-adjusted over the case's VUTs (family-wise error at ``alpha``); the raw p is kept.
* **Preventable crashes**: of a VUT's cross-play collisions, those that the reference,
  replaying the same opponent actions open loop from the same start, avoided
  (:mod:`sumo_ayss.scenarios.preventability`). Shown with a Wilson interval of their rate
  over all the VUT's episodes. The reference's own collision rate against the pool is a
  property of the scenario set and the opponents: episodes no careful human survived.

Why the harm score itself is not changed by the labels (docs/ranking.md, "Preventable
crashes"): a crash the careful human could not avoid is still a crash, and scoring it below
1 would rank a VUT that crashed above one that survived the same episode with any near
miss worse than that value — turning an episode into a collision would then *lower* a VUT's
harm. The harm ranking stays monotone; the fault reading is this second axis, and the
verdict against the reference says whether a VUT is below the careful human's bar.

Imports neither SUMO nor torch; reads no file.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

from sumo_ayss.analysis.crossplay import CrossplayMatrix
from sumo_ayss.analysis.harm import HARM_RANGE
from sumo_ayss.analysis.multiplicity import holm
from sumo_ayss.analysis.seeds import SeedComparison, compare_seeds
from sumo_ayss.analysis.stats import wilson_interval
from sumo_ayss.util.errors import ConfigError

__all__ = [
    "CAREFUL_HUMAN",
    "ReferenceComparison",
    "ReferenceReading",
    "ScenarioSet",
    "holm_adjust",
    "read_against_reference",
]

#: The careful-human reference's catalog name
#: (:data:`sumo_ayss.vuts.reference_types.REFERENCE_VUTS`), listed first wherever several
#: references are read.
CAREFUL_HUMAN = "cc_driver"

Verdict = Literal["safer", "not distinguishable", "less safe", "untested"]


def holm_adjust(p_values: list[float]) -> list[float]:
    """Holm's step-down adjusted p values (same order; NaN stays NaN and is not counted):
    the ranking's own procedure, :func:`sumo_ayss.analysis.multiplicity.holm`."""
    return holm(p_values)


@dataclass(frozen=True)
class ReferenceComparison:
    """One VUT against the reference driver.

    Attributes:
        vut: The VUT.
        test: VUT minus reference harm, paired over blocks (``difference`` < 0: the VUT
            suffered less harm than the careful human under the same opponents).
        p_adjusted: Holm-adjusted p over the case's VUTs (NaN: no test).
        verdict: ``safer`` / ``less safe`` (adjusted p <= alpha, by the sign),
            ``not distinguishable`` (also: identical in every block), or ``untested`` (too
            few blocks, or no spread around a non-zero difference).
        crashes: The VUT's cross-play collisions.
        episodes: Its cross-play episodes.
        preventable: Collisions labelled preventable.
        labelled: Collisions that carry a label (< ``crashes``: part of the table is older
            than the labels).
        preventable_lo: Lower end of the Wilson interval of ``preventable / episodes``.
        preventable_hi: Upper end.
    """

    vut: str
    test: SeedComparison
    p_adjusted: float
    verdict: Verdict
    crashes: int
    episodes: int
    preventable: int
    labelled: int
    preventable_lo: float
    preventable_hi: float

    @property
    def preventable_rate(self) -> float:
        return self.preventable / self.episodes if self.episodes else math.nan


@dataclass(frozen=True)
class ReferenceReading:
    """A case's VUTs against a reference driver.

    Attributes:
        reference: The reference driver's name.
        harm: Its cross-play harm (mean over blocks).
        crashes: Its collisions against the pool; ``crashes / episodes`` is the share of
            episodes no careful human survived: a property of the scenario set and the
            opponents.
        episodes: Its episodes.
        crash_lo: Lower end of the Wilson interval of its crash rate.
        crash_hi: Upper end.
        rows: One comparison per VUT, in the matrix's VUT order.
        alpha: Family-wise error rate of the verdicts.
        blocks: Block unit of the tests.
    """

    reference: str
    harm: float
    crashes: int
    episodes: int
    crash_lo: float
    crash_hi: float
    rows: tuple[ReferenceComparison, ...]
    alpha: float
    blocks: str

    @property
    def crash_rate(self) -> float:
        return self.crashes / self.episodes if self.episodes else math.nan


@dataclass(frozen=True)
class ScenarioSet:
    """How much of a case's scenario set no braking survives.

    Attributes:
        n: Scenarios (the outcome / cross-play set).
        ics: Of those, inevitable-collision states
            (:mod:`sumo_ayss.scenarios.inevitable`): a VUT braking at 0.85 g from the
            first step still touches a POV that brakes (or cuts in) at once.
        lo: Lower end of the Wilson interval of ``ics / n``.
        hi: Upper end.
    """

    n: int
    ics: int
    lo: float
    hi: float

    @property
    def share(self) -> float:
        return self.ics / self.n if self.n else math.nan

    @classmethod
    def of(cls, n: int, ics: int, level: float = 0.95) -> ScenarioSet:
        lo, hi = wilson_interval(ics, n, level) if n else (math.nan, math.nan)
        return cls(n, ics, lo, hi)


def read_against_reference(
    m: CrossplayMatrix,
    ref: CrossplayMatrix,
    reference: str,
    *,
    blocks: str = "seed",
    level: float = 0.95,
    alpha: float = 0.05,
) -> ReferenceReading:
    """Every VUT of ``m`` against the reference row ``reference`` of ``ref``.

    Raises:
        ConfigError: If ``ref`` has no row ``reference`` or was not driven against the same
            opponents on as many scenarios.
    """
    if reference not in ref.vuts:
        raise ConfigError(f"reference rows: no {reference!r} among {list(ref.vuts)}")
    if set(ref.opponents) != set(m.opponents) or ref.n_scenarios != m.n_scenarios:
        raise ConfigError(
            "reference rows: driven against other opponents or scenarios than the cross-play "
            "table (rerun cross-play)"
        )
    order = [ref.opponents.index(o) for o in m.opponents]
    aligned = CrossplayMatrix(
        ref.vuts,
        m.opponents,
        ref.harm[:, order],
        ref.collisions[:, order],
        ref.n_scenarios,
        ref.returns[:, order],
        ref.mobility[:, order],
    )
    ref_scores = {s.name: s for s in aligned.scores(blocks)}[reference]
    tests = [
        compare_seeds(s, ref_scores, level=level, alpha=alpha, bounds=HARM_RANGE)
        for s in m.scores(blocks)
        if s.name != reference
    ]
    adjusted = holm_adjust([t.p for t in tests])
    rows = []
    for t, p_adj in zip(tests, adjusted, strict=True):
        crashes, n = m.crashes(t.name_a)
        prev, lab = m.preventable_crashes(t.name_a)
        lo, hi = wilson_interval(prev, n, level) if n else (math.nan, math.nan)
        if math.isnan(p_adj) and t.test == "paired t" and t.difference == 0.0:
            verdict: Verdict = "not distinguishable"  # identical in every block
        elif math.isnan(p_adj):
            verdict = "untested"
        elif p_adj <= alpha:
            verdict = "safer" if t.difference < 0 else "less safe"
        else:
            verdict = "not distinguishable"
        rows.append(ReferenceComparison(t.name_a, t, p_adj, verdict, crashes, n, prev, lab, lo, hi))
    crashes, n = aligned.crashes(reference)
    lo, hi = wilson_interval(crashes, n, level)
    return ReferenceReading(
        reference,
        float(ref_scores.array.mean()),
        crashes,
        n,
        lo,
        hi,
        tuple(rows),
        alpha,
        blocks,
    )
