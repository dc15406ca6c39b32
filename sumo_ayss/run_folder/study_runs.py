"""A study's runs, read: found under paths, checked to be poolable (the check is
:func:`sumo_ayss.training.trust.mixing_problems`), grouped by case and VUT, each case with its
cross-play table (:func:`load_runs`, :func:`group_runs`, :func:`case_runs`). Analysing them is
:func:`sumo_ayss.modes.analyse_cases`'s."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from sumo_ayss.cases import case_names
from sumo_ayss.run_folder.crossplay import CrossplayTables, load_crossplay
from sumo_ayss.run_folder.layout import RunFolder, find_run_dirs
from sumo_ayss.run_folder.record import RunRecord, read_run
from sumo_ayss.training.trust import mixing_problems
from sumo_ayss.util.errors import ConfigError
from sumo_ayss.util.paths import display_path

__all__ = [
    "CaseRuns",
    "case_of",
    "case_runs",
    "group_runs",
    "load_runs",
]


@dataclass(frozen=True)
class CaseRuns:
    """One case of a study as read: its runs by VUT and its cross-play table.

    Attributes:
        case: Case name.
        runs: ``{vut: runs sorted by seed}`` (:func:`group_runs`).
        crossplay: The case's cross-play files as :func:`~.crossplay.load_crossplay` found
            them (or why there are none); the analysis scores them.
    """

    case: str
    runs: dict[str, list[RunRecord]]
    crossplay: CrossplayTables


def load_runs(paths: Sequence[str | Path]) -> list[RunRecord]:
    """The run folders among ``paths`` (and below them), loaded, checked to be poolable.

    Args:
        paths: Run folders ``<out>/<case>/<vut>/seed_<k>`` and/or roots to search.

    Returns:
        The loaded runs (:func:`~.record.read_run`), in :func:`~.layout.find_run_dirs` order.

    Raises:
        ConfigError: If ``paths`` is empty, a path is not a folder, no run folder is found,
            or the runs must not be pooled into one report
            (:func:`sumo_ayss.training.trust.mixing_problems`).
    """
    if not paths:
        raise ConfigError("paths: expected at least one run folder or root")
    run_dirs = find_run_dirs(paths)
    if not run_dirs:
        raise ConfigError(
            f"no run folder (with {RunFolder.config.name}) under {list(map(str, paths))}"
        )
    runs = [read_run(d) for d in run_dirs]
    problems = mixing_problems(
        [(r.case, r.vut, r.seed, display_path(r.path, Path.cwd()), r.training) for r in runs]
    )
    if problems:
        raise ConfigError(
            "these runs must not be pooled into one report (report each group separately, "
            "e.g. one pipeline output folder at a time):\n  " + "\n  ".join(problems)
        )
    return runs


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


def case_runs(runs: Sequence[RunRecord]) -> list[CaseRuns]:
    """Every case among ``runs`` in :func:`group_runs` order, each with its cross-play table
    (:func:`~.crossplay.load_crossplay`)."""
    return [
        CaseRuns(case, by_vut, load_crossplay(by_vut)) for case, by_vut in group_runs(runs).items()
    ]


def case_of(runs: Sequence[RunRecord]) -> CaseRuns:
    """The first case among ``runs`` (:func:`group_runs` order) with its cross-play files;
    its matrix is :func:`sumo_ayss.analysis.crossplay_scoring.case_matrix`'s."""
    case, by_vut = next(iter(group_runs(runs).items()))
    return CaseRuns(case, by_vut, load_crossplay(by_vut))
