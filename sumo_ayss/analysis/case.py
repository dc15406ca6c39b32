"""Statistics of one case: safety indices, rankings and verdicts per mode.

:func:`analyse_case` turns the runs of one case (any objects shaped like :class:`RunLike`,
e.g. :class:`sumo_ayss.run_folder.RunRecord`) into a :class:`CaseAnalysis`: the paper mode (AYSS
safety index per VUT, hierarchical bootstrap, pairwise verdicts under
:func:`~.significance.pair_verdict`), the exposure mode (seed-level ranking of the mean harm
per episode of each VUT's own SPCPs, :mod:`.harm`), the cross-play mode (the case's
cross-play matrix, which its loader read from ``crossplay.csv``, :mod:`.crossplay`) and the
premise check; the verdict of the mode asked for (a :class:`~.case_verdict.CaseVerdict`)
is the mode's to give (:func:`sumo_ayss.modes.analyse_case` runs this and asks it). Both the
report and :mod:`sumo_ayss.rank` read it (the modes word its verdicts); the pipeline analyses
each case once and hands the analysis to both. Nothing here reads a file, draws, renders or
words a verdict, and nothing here imports the run folders or the modes.
"""

from __future__ import annotations

import logging
import zlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Generic, Protocol, TypeVar

import numpy as np
from numpy.typing import NDArray

from sumo_ayss.analysis.case_verdict import CaseVerdict, paper_verdict
from sumo_ayss.analysis.crossplay import (
    CrossplayGap,
    CrossplayInput,
    CrossplayMatrix,
    rank_crossplay,
)
from sumo_ayss.analysis.harm import (
    HARM_RANGE,
    ColumnsLike,
    RewardLike,
    VutOutcome,
    run_episodes,
    vut_outcomes,
)
from sumo_ayss.analysis.premise import Premise, premise_check
from sumo_ayss.analysis.ranking import RankedVut, SafetyIndex, rank, safety_index
from sumo_ayss.analysis.reference import (
    CAREFUL_HUMAN,
    ReferenceReading,
    ScenarioSet,
    read_against_reference,
)
from sumo_ayss.analysis.seeds import SeedComparison, SeedRankRow, SeedScores, rank_seeds
from sumo_ayss.analysis.significance import PairVerdict, family_adjusted, pair_verdict
from sumo_ayss.cases import Case, case_info
from sumo_ayss.util.errors import ConfigError

__all__ = [
    "CROSSPLAY_MODE",
    "EXPOSURE_MODE",
    "PAPER_MODE",
    "CaseAnalysis",
    "CaseOptions",
    "CaseVerdict",
    "RunLike",
    "analyse_case",
    "run_label",
    "vut_safety_index",
]

#: The built-in ranking modes' names (:mod:`sumo_ayss.modes` registers them under these):
#: the keys of :attr:`CaseAnalysis.outcomes` and the ``mode`` of the records computed here.
CROSSPLAY_MODE = "crossplay"
EXPOSURE_MODE = "exposure"
PAPER_MODE = "paper"

logger = logging.getLogger(__name__)


class CaseOptions(Protocol):
    """The statistical settings read here (e.g. :class:`sumo_ayss.config.report.ReportOptions`)."""

    @property
    def h_max_m(self) -> float: ...

    @property
    def h_range(self) -> tuple[float, float]: ...

    @property
    def index_bins(self) -> int: ...

    @property
    def level(self) -> float: ...

    @property
    def welch_alpha(self) -> float: ...

    @property
    def n_boot(self) -> int: ...

    @property
    def rng_seed(self) -> int: ...

    @property
    def mode(self) -> str: ...

    @property
    def crossplay_blocks(self) -> str: ...

    @property
    def premise_tolerances(self) -> Mapping[str, float]: ...


class _Estimate(Protocol):
    @property
    def value(self) -> float: ...


class OutcomeLike(Protocol):
    """A run's outcome summary, as far as the premise check reads it."""

    @property
    def mean_return(self) -> _Estimate: ...

    @property
    def crash_rate(self) -> _Estimate: ...

    @property
    def mean_final_headway_m(self) -> _Estimate: ...


class AyssLike(Protocol):
    """A run's AYSS samples: the indicator and the headway [m] of each."""

    @property
    def h(self) -> NDArray[np.float64]: ...

    @property
    def indicator(self) -> NDArray[np.float64]: ...

    def __len__(self) -> int: ...


class RunLike(Protocol):
    """What the analysis reads of a run (:class:`sumo_ayss.run_folder.RunRecord` is one, as
    :func:`sumo_ayss.run_folder.read_run` returns it): analysis imports no file reader, the
    loader hands it the records."""

    @property
    def case(self) -> str: ...

    @property
    def vut(self) -> str: ...

    @property
    def seed(self) -> int | None: ...

    @property
    def problems(self) -> Sequence[str]: ...

    @property
    def ayss(self) -> AyssLike | None: ...

    @property
    def outcome(self) -> OutcomeLike | None: ...

    @property
    def reward(self) -> RewardLike | None: ...

    @property
    def decisions_per_episode(self) -> int | None: ...

    @property
    def outcome_table(self) -> ColumnsLike | None: ...


R = TypeVar("R", bound=RunLike)


def run_label(run: RunLike) -> str:
    """``"<case>/<vut>/seed_<k>"`` of a run, for problem lists."""
    return f"{run.case}/{run.vut}/seed_{run.seed if run.seed is not None else '?'}"


def _vut_rng(options: CaseOptions, case: str, vut: str) -> np.random.Generator:
    """A bootstrap stream per (case, VUT), stable whatever other VUTs are in the report."""
    return np.random.default_rng([options.rng_seed, zlib.crc32(f"{case}/{vut}".encode())])


def vut_safety_index(
    runs: Sequence[RunLike], options: CaseOptions, rng: np.random.Generator | int | None = None
) -> SafetyIndex | None:
    """Safety index of one VUT from the AYSS samples of its runs (one seed per run).

    Args:
        runs: The VUT's runs; those without AYSS samples are skipped.
        options: Headway range, bins, level and bootstrap size.
        rng: Bootstrap generator or seed.

    Returns:
        The :class:`SafetyIndex`, or None if no run has a sample in the headway range.
    """
    seeds = [r.ayss for r in runs if r.ayss is not None and len(r.ayss) > 0]
    if not seeds:
        return None
    try:
        return safety_index(
            [s.indicator for s in seeds],
            [s.h for s in seeds],
            options.h_range,
            n_bins=options.index_bins,
            level=options.level,
            n_boot=options.n_boot,
            rng=rng,
        )
    except ConfigError as exc:  # e.g. no sample in the headway range
        logger.warning("no safety index: %s", exc)
        return None


@dataclass
class CaseAnalysis(Generic[R]):
    """Statistics of one case (of runs of type ``R``, e.g. a run folder's record).

    Attributes:
        case: Case name.
        info: The case's record (:func:`sumo_ayss.cases.case_info`): naming, units, wording.
        runs: ``{vut: runs sorted by seed}``.
        indices: ``{vut: safety index}`` for VUTs with AYSS samples.
        ranking: VUTs safest first (point estimate).
        pairs: Verdicts of every pair, in ranking order (A ranked above B).
        verdict: The verdict of the mode asked for (``mode``), or of the mode it fell
            back to (``verdict.mode``, :attr:`ranking_mode`); worded by ``mode``'s
            :attr:`~sumo_ayss.modes.Mode.headline`.
        paper_verdict: The paper mode's verdict (also when ``mode`` is another).
        problems: Missing or unreadable files, one line each.
        mode: The analysis mode asked for (``report.mode``).
        exposure_rows: Exposure-mode ranking, safest first.
        exposure_pairs: Exposure-mode comparisons of every pair (A ranked above B).
        exposure_scores: ``{vut: {seed: E}}``, the per-seed exposures behind the ranking.
        premise: Whether the SPCPs reached the same overall outcome, or None.
        crossplay: The case's cross-play matrix, or None (see ``crossplay_gap``).
        crossplay_rows: Cross-play ranking, safest first (empty without a table).
        crossplay_pairs: Cross-play comparisons of every pair (A ranked above B).
        crossplay_blocks: Block unit of the cross-play test (``"seed"`` or ``"opponent"``).
        crossplay_path: The ``crossplay.csv`` read, or None.
        crossplay_gap: Why there is no cross-play ranking; None when there is one.
        crossplay_diagonal: The table's diagonal check, ``(vut, seed, n, n_equal)`` per run
            (empty: the record predates the check).
        outcomes: ``{mode: {vut: VutOutcome}}`` for the modes that read outcomes
            (``"crossplay"``, ``"exposure"``): crashes with their interval and mobility,
            shown beside the harm score.
        references: ``{reference driver: its reading}``: every VUT against each reference
            driver that drove in cross-play (:mod:`.reference`), the careful human first.
        scenario_set: The share of the case's scenarios that are inevitable-collision
            states, or None (not computed for this table).
        results: ``{mode: its own result}`` for the modes that compute one from the data
            above (:meth:`sumo_ayss.modes.Mode.compute`); opaque here.
    """

    case: str
    info: Case
    runs: dict[str, list[R]]
    indices: dict[str, SafetyIndex] = field(default_factory=dict)
    ranking: list[RankedVut] = field(default_factory=list)
    pairs: list[PairVerdict] = field(default_factory=list)
    verdict: CaseVerdict = field(default_factory=lambda: CaseVerdict(EXPOSURE_MODE, "warning"))
    paper_verdict: CaseVerdict = field(default_factory=lambda: CaseVerdict(PAPER_MODE, "warning"))
    problems: list[str] = field(default_factory=list)
    mode: str = EXPOSURE_MODE
    exposure_rows: list[SeedRankRow] = field(default_factory=list)
    exposure_pairs: list[SeedComparison] = field(default_factory=list)
    exposure_scores: dict[str, dict[int, float]] = field(default_factory=dict)
    premise: Premise | None = None
    crossplay: CrossplayMatrix | None = None
    crossplay_rows: list[SeedRankRow] = field(default_factory=list)
    crossplay_pairs: list[SeedComparison] = field(default_factory=list)
    crossplay_blocks: str = "seed"
    crossplay_path: Path | None = None
    crossplay_gap: CrossplayGap | None = None
    crossplay_diagonal: tuple[tuple[str, int, int, int], ...] = ()
    outcomes: dict[str, dict[str, VutOutcome]] = field(default_factory=dict)
    references: dict[str, ReferenceReading] = field(default_factory=dict)
    scenario_set: ScenarioSet | None = None
    results: dict[str, object] = field(default_factory=dict)

    @property
    def ranking_mode(self) -> str:
        """The mode the verdict and its ranking come from: ``mode``, or ``"exposure"`` in
        cross-play mode without a cross-play table (the headline says so first)."""
        return self.verdict.mode


def _exposure(out: CaseAnalysis[R], options: CaseOptions) -> None:
    """Exposure-mode ranking (each VUT's own SPCPs: mean harm of their outcome episodes,
    per seed) and the premise check, from the runs' outcome tables and summaries."""
    scores = []
    counts: dict[str, tuple[int, int, float]] = {}
    for vut, members in out.runs.items():
        done = []
        for r in members:
            try:
                episodes = run_episodes(r)
            except ConfigError as exc:  # the table does not fit the run's scale
                out.problems.append(f"{run_label(r)}: outcome.csv unreadable ({exc})")
                continue
            if r.seed is not None and episodes is not None:
                done.append((r.seed, episodes))
        if done:
            scores.append(SeedScores(vut, {seed: e.mean_harm for seed, e in done}))
            counts[vut] = (
                sum(e.crashes for _, e in done),
                sum(e.n for _, e in done),
                float(np.mean([e.mobility for _, e in done])),
            )
        else:
            out.problems.append(f"{vut}: no outcome table with a seed, so no exposure")
    out.exposure_scores = {sc.name: dict(sc.values) for sc in scores}
    if counts:
        out.outcomes[EXPOSURE_MODE] = vut_outcomes(counts, options.level)
    if scores:
        out.exposure_rows, out.exposure_pairs = rank_seeds(
            scores,
            higher_is_safer=False,
            level=options.level,
            alpha=options.welch_alpha,
            bounds=HARM_RANGE,
        )
    metrics: dict[str, dict[str, list[float]]] = {
        "mean_return": {},
        "crash_rate": {},
        "mean_final_headway_m": {},
    }
    for vut, members in out.runs.items():
        for r in members:
            if r.outcome is None:
                continue
            for key in metrics:
                metrics[key].setdefault(vut, []).append(getattr(r.outcome, key).value)
    out.premise = premise_check(metrics, tolerances=options.premise_tolerances, level=options.level)


def _crossplay(out: CaseAnalysis[R], options: CaseOptions, found: CrossplayInput) -> None:
    """Cross-play ranking from the case's cross-play table as its loader found it, or why
    there is none; a table not of exactly these VUTs and runs is not used."""
    out.crossplay_blocks = options.crossplay_blocks
    if len(out.runs) < 2:
        out.crossplay_gap = CrossplayGap("one_vut", vut=next(iter(out.runs), "?"))
        return
    m = found.matrix
    if m is None:
        out.crossplay_gap = CrossplayGap("not_found", loader=found.missing)
        if found.problem:
            out.problems.append(found.problem)
        return
    opponents = {(v, int(r.seed)) for v, rs in out.runs.items() for r in rs if r.seed is not None}
    if set(m.vuts) != set(out.runs) or set(m.opponents) != opponents:
        lost = [f"VUT {v}" for v in out.runs if v not in m.vuts] + [
            f"opponent {v}/seed_{s}" for v, s in sorted(opponents - set(m.opponents))
        ]
        out.crossplay_gap = CrossplayGap(
            "not_these_runs",
            path=found.path,
            vuts=tuple(m.vuts),
            n_opponents=len(m.opponents),
            n_runs=len(opponents),
            lost="; ".join(lost),
        )
        if lost:  # a table that lost rows (or was never extended): a problem, named
            out.problems.append(
                f"{found.path}: no rows of {'; '.join(lost)} (the table holds VUTs "
                f"{', '.join(m.vuts)} and {len(m.opponents)} opponents; the case has "
                f"{len(out.runs)} VUTs and {len(opponents)} runs)"
            )
        return
    out.crossplay, out.crossplay_path = m, found.path
    out.crossplay_diagonal = found.diagonal
    out.outcomes[CROSSPLAY_MODE] = vut_outcomes(
        {v: (*m.crashes(v), m.vut_mobility(v)) for v in m.vuts}, options.level, m.hazards
    )
    out.crossplay_rows, out.crossplay_pairs = rank_crossplay(
        m, blocks=options.crossplay_blocks, level=options.level, alpha=options.welch_alpha
    )
    if found.inevitable is not None and found.inevitable[0] == m.n_scenarios:
        out.scenario_set = ScenarioSet.of(m.n_scenarios, len(found.inevitable[2]), options.level)
    if found.reference is not None:
        for name in sorted(found.reference.vuts, key=lambda v: (v != CAREFUL_HUMAN, v)):
            try:
                out.references[name] = read_against_reference(
                    m,
                    found.reference,
                    name,
                    blocks=options.crossplay_blocks,
                    level=options.level,
                    alpha=options.welch_alpha,
                )
            except ConfigError as exc:
                out.problems.append(f"{found.path}: reference {name}: {exc}")


def analyse_case(
    case: str,
    runs: dict[str, list[R]],
    options: CaseOptions,
    *,
    crossplay: CrossplayInput | None = None,
    paper: bool = True,
) -> CaseAnalysis[R]:
    """Safety index per VUT, ranking and pairwise verdicts of every mode of one case; its
    ``verdict`` is left to the mode asked for (:func:`sumo_ayss.modes.analyse_case`).

    Args:
        case: Case name.
        runs: ``{vut: runs}``.
        options: Statistical settings.
        crossplay: The case's cross-play table as its loader found it
            (:func:`sumo_ayss.run_folder.load_crossplay`); None: no table.
        paper: Compute the paper mode (AYSS safety indices and their bootstrap, the slow
            part); the report always does, a ranking in exposure mode need not.

    Returns:
        The :class:`CaseAnalysis`.
    """
    info = case_info(case)
    out: CaseAnalysis[R] = CaseAnalysis(case=case, info=info, runs=runs)
    for members in runs.values():
        for run in members:
            out.problems += [f"{run_label(run)}: {p}" for p in run.problems]
    for vut, members in runs.items() if paper else ():
        idx = vut_safety_index(members, options, _vut_rng(options, case, vut))
        if idx is not None:
            out.indices[vut] = idx
        else:
            out.problems.append(
                f"{vut}: no AYSS sample with h in [0, {options.h_max_m:g}] m, so no safety index"
            )
    if out.indices:
        out.ranking = rank(out.indices, level=options.level)
    order = [r.name for r in out.ranking]
    for i, a in enumerate(order):
        for b in order[i + 1 :]:
            try:
                out.pairs.append(
                    pair_verdict(
                        out.indices[a],
                        out.indices[b],
                        name_a=a,
                        name_b=b,
                        indicator=info.indicator,
                        level=options.level,
                        welch_alpha=options.welch_alpha,
                    )
                )
            except ConfigError as exc:
                out.problems.append(f"{a} vs {b}: not comparable ({exc})")
    out.pairs = family_adjusted(out.pairs, order)
    _exposure(out, options)
    premise_met = out.premise is None or not out.premise.metrics or out.premise.met
    out.paper_verdict = paper_verdict(PAPER_MODE, out.ranking, out.pairs, premise_met=premise_met)
    _crossplay(out, options, crossplay or CrossplayInput())
    out.mode = options.mode
    return out
