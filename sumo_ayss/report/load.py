"""Hand the analysis the runs of each case: grouping and one analysis per case.

A run folder is read once into a :class:`~sumo_ayss.run_folder.RunRecord`
(:func:`~sumo_ayss.run_folder.read_run`, which tolerates missing and broken files and says
so in the record's ``problems``); a case's cross-play table is read by
:func:`~sumo_ayss.run_folder.load_crossplay`. :mod:`sumo_ayss.analysis` reads no file:
:func:`analyse_runs` hands it the records and each case's cross-play matrix, one analysis
per case for whoever needs it (the report, rank). This module imports neither SUMO nor
torch.
"""

from __future__ import annotations

from collections.abc import Sequence

from sumo_ayss.analysis.case import CaseAnalysis, CaseOptions
from sumo_ayss.cases import case_names
from sumo_ayss.modes import analyse_case
from sumo_ayss.run_folder import RunRecord, load_crossplay

__all__ = ["analyse_runs", "group_runs"]


def group_runs(runs: Sequence[RunRecord]) -> dict[str, dict[str, list[RunRecord]]]:
    """Runs grouped by case, then VUT; cases in registry order (:mod:`sumo_ayss.cases`),
    unknown ones last, VUTs and seeds sorted.

    Args:
        runs: Loaded runs.

    Returns:
        ``{case: {vut: [runs sorted by seed]}}``.
    """
    order = {name: i for i, name in enumerate(case_names())}
    out: dict[str, dict[str, list[RunRecord]]] = {}
    for case in sorted({r.case for r in runs}, key=lambda c: (order.get(c, len(order)), c)):
        by_vut: dict[str, list[RunRecord]] = {}
        for vut in sorted({r.vut for r in runs if r.case == case}):
            members = [r for r in runs if r.case == case and r.vut == vut]
            by_vut[vut] = sorted(members, key=lambda r: (r.seed is None, r.seed or 0, str(r.path)))
        out[case] = by_vut
    return out


def analyse_runs(
    runs: Sequence[RunRecord], options: CaseOptions, *, paper: bool = True
) -> list[CaseAnalysis]:
    """The analysis of every case among ``runs``, each computed once, in :func:`group_runs`
    order (:func:`~sumo_ayss.modes.analyse_case` on the case's runs and its
    cross-play table, :func:`~sumo_ayss.run_folder.load_crossplay`).

    Args:
        runs: Loaded runs (any cases and VUTs).
        options: Statistical settings.
        paper: Compute the paper mode (the AYSS bootstrap, the slow part).
    """
    return [
        analyse_case(case, by_vut, options, crossplay=load_crossplay(by_vut), paper=paper)
        for case, by_vut in group_runs(runs).items()
    ]
