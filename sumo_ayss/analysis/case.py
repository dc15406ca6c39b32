"""One case's data for the ranking modes, and what the analysis reads of a run.

:func:`analyse_case` gathers the runs of one case (any objects shaped like :class:`RunLike`,
e.g. :class:`sumo_ayss.run_folder.RunRecord`), the statistical settings and the case's
cross-play tables as their loader found them into a :class:`CaseAnalysis`; each ranking mode
then computes its own result from it (:meth:`sumo_ayss.modes.Mode.compute`: the paper mode
its AYSS safety indices, pairwise verdicts and the premise check, the exposure mode its
seed-level ranking of each VUT's own SPCPs, the cross-play mode its ranking of the case's
cross-play matrix) and the mode asked for gives the verdict
(:func:`sumo_ayss.modes.analyse_case` runs both). Both the report and :mod:`sumo_ayss.rank`
read it; the pipeline analyses each case once and hands the analysis to both. Nothing here
reads a file, draws, renders or words a verdict, and nothing here imports the run folders or
the modes.
"""

from __future__ import annotations

import logging
import zlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Generic, Protocol, TypeVar

import numpy as np

from sumo_ayss.analysis.ayss_cells import (
    AyssLike,
    CellsLike,
    run_cells,
    safety_index_from_cells,
)
from sumo_ayss.analysis.case_verdict import CaseVerdict
from sumo_ayss.analysis.crossplay import CrossplayInput
from sumo_ayss.analysis.harm import ColumnsLike, RewardLike
from sumo_ayss.analysis.ranking import SafetyIndex, safety_index
from sumo_ayss.cases import Case, case_info
from sumo_ayss.util.errors import ConfigError

__all__ = [
    "AyssLike",
    "CaseAnalysis",
    "CaseOptions",
    "CaseVerdict",
    "OutcomeLike",
    "RunLike",
    "analyse_case",
    "bootstrap_rng",
    "run_label",
    "vut_safety_index",
]

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
    def ayss_bins(self) -> CellsLike | None: ...

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


def bootstrap_rng(options: CaseOptions, case: str, vut: str) -> np.random.Generator:
    """A bootstrap stream per (case, VUT), stable whatever other VUTs are in the report."""
    return np.random.default_rng([options.rng_seed, zlib.crc32(f"{case}/{vut}".encode())])


def vut_safety_index(
    runs: Sequence[RunLike], options: CaseOptions, rng: np.random.Generator | int | None = None
) -> SafetyIndex | None:
    """Safety index of one VUT from the AYSS samples of its runs (one seed per run); from
    their per-cell moments (:func:`~.ayss_cells.safety_index_from_cells`) when a run has
    only those (``ayss_bins.csv`` without ``ayss.csv``).

    Args:
        runs: The VUT's runs; those without AYSS samples are skipped.
        options: Headway range, bins, level and bootstrap size.
        rng: Bootstrap generator or seed.

    Returns:
        The :class:`SafetyIndex`, or None if no run has a sample in the headway range.
    """
    seeds = [r.ayss for r in runs if r.ayss is not None and len(r.ayss) > 0]
    bins_only = [
        c for r in runs if r.ayss is None and (c := r.ayss_bins) is not None and int(c.n.sum())
    ]
    if not seeds and not bins_only:
        return None
    try:
        if bins_only:  # a run without ayss.csv: its ayss_bins.csv, the others' samples as cells
            cells = [c for r in runs if (c := run_cells(r)) is not None and int(c.n.sum()) > 0]
            return safety_index_from_cells(
                cells,
                options.h_range,
                n_bins=options.index_bins,
                level=options.level,
                n_boot=options.n_boot,
                rng=rng,
            )
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
    """One case's data (of runs of type ``R``, e.g. a run folder's record) and one result
    per ranking mode.

    Nothing here is one mode's: each registered mode computes its own result from the
    fields below (:meth:`sumo_ayss.modes.Mode.compute`, kept in ``results`` by
    :func:`sumo_ayss.modes.analyse_case`) and reads it back when it ranks, gives its verdict
    and words it.

    Attributes:
        case: Case name.
        info: The case's record (:func:`sumo_ayss.cases.case_info`): naming, units, wording.
        runs: ``{vut: runs sorted by seed}``.
        options: The statistical settings the modes compute with.
        tables: The case's study tables as their loader found them (the cross-play table,
            the reference drivers' rows, the inevitable-collision states), or an empty
            :class:`~.crossplay.CrossplayInput` (none found or handed in).
        bootstrap: Whether a mode that needs the AYSS bootstrap (the slow part) computes
            it; the report does, a ranking in a mode that needs none does not.
        verdict: The verdict of the mode asked for (``mode``), or of the mode it fell
            back to (``verdict.mode``, :attr:`ranking_mode`); worded by ``mode``'s
            :attr:`~sumo_ayss.modes.Mode.headline`. A placeholder warning until the mode
            gives it.
        problems: Missing or unreadable files, one line each (the runs' own, then each
            mode's, in registry order).
        mode: The analysis mode asked for (``report.mode``).
        results: ``{mode: its own result}`` (:meth:`sumo_ayss.modes.Mode.compute`); opaque
            here, typed by each mode (e.g. :func:`sumo_ayss.modes.exposure.exposure_result`).
    """

    case: str
    info: Case
    runs: dict[str, list[R]]
    options: CaseOptions
    verdict: CaseVerdict
    tables: CrossplayInput = field(default_factory=CrossplayInput)
    bootstrap: bool = True
    problems: list[str] = field(default_factory=list)
    mode: str = ""
    results: dict[str, object] = field(default_factory=dict)

    @property
    def ranking_mode(self) -> str:
        """The mode the verdict and its ranking come from: ``mode``, or the mode it fell
        back to (cross-play mode without a cross-play table: the exposure mode; the
        headline says so first)."""
        return self.verdict.mode


def analyse_case(
    case: str,
    runs: dict[str, list[R]],
    options: CaseOptions,
    *,
    crossplay: CrossplayInput | None = None,
    paper: bool = True,
) -> CaseAnalysis[R]:
    """The case's data, ready for the modes (:func:`sumo_ayss.modes.analyse_case` runs this,
    then each mode's :meth:`~sumo_ayss.modes.Mode.compute` and the verdict).

    Args:
        case: Case name.
        runs: ``{vut: runs}``.
        options: Statistical settings.
        crossplay: The case's cross-play table as its loader found it
            (:func:`sumo_ayss.analysis.crossplay_scoring.crossplay_input`); None: no table.
        paper: Let the modes draw the AYSS bootstrap (:attr:`CaseAnalysis.bootstrap`; the
            slow part): the report always does, a ranking in a mode that needs none does not.

    Returns:
        The :class:`CaseAnalysis`, with the runs' own problems and no mode's result yet.
    """
    out: CaseAnalysis[R] = CaseAnalysis(
        case=case,
        info=case_info(case),
        runs=runs,
        options=options,
        verdict=CaseVerdict(options.mode, "warning"),
        tables=crossplay or CrossplayInput(),
        bootstrap=paper,
        mode=options.mode,
    )
    for members in runs.values():
        for run in members:
            out.problems += [f"{run_label(run)}: {p}" for p in run.problems]
    return out
