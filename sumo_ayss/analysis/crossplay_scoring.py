"""A case's cross-play tables, as stored, scored on its runs' harm scale: the analysis's
side of :func:`sumo_ayss.run_folder.load_crossplay` (the reader returns the stored columns;
the harm is computed here, not while reading).

Reads no file.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, Protocol

from sumo_ayss.analysis.crossplay import CrossplayInput, CrossplayMatrix, crossplay_matrix
from sumo_ayss.analysis.harm import (
    ColumnsLike,
    HarmScale,
    ScorableRun,
    episode_harm,
    harm_scale_of,
)
from sumo_ayss.analysis.hazards import VUT_HAZARD_COLUMNS, harm_crash
from sumo_ayss.util.errors import ConfigError, TableError

__all__ = ["CrossplayTablesLike", "case_matrix", "crossplay_input", "score_crossplay"]


class CrossplayTablesLike(Protocol):
    """A case's cross-play files as read (:class:`sumo_ayss.run_folder.CrossplayTables`)."""

    @property
    def case_dir(self) -> Path | None: ...
    @property
    def path(self) -> Path | None: ...
    @property
    def table(self) -> ColumnsLike | None: ...
    @property
    def missing(self) -> str: ...
    @property
    def problem(self) -> str: ...
    @property
    def vuts(self) -> tuple[str, ...] | None: ...
    @property
    def diagonal(self) -> tuple[tuple[str, int, int, int], ...]: ...
    @property
    def reference(self) -> ColumnsLike | None: ...
    @property
    def reference_problem(self) -> str: ...
    @property
    def inevitable(self) -> tuple[int, int, tuple[int, ...]] | None: ...
    @property
    def inevitable_problem(self) -> str: ...


def score_crossplay(columns: Mapping[str, Any], scale: HarmScale) -> CrossplayMatrix:
    """The :class:`~sumo_ayss.analysis.crossplay.CrossplayMatrix` of a cross-play table's
    columns, each episode's harm on ``scale`` (a table written before ``near_miss_pay``
    existed derives it from the return).

    Raises:
        ConfigError: If the design is not complete and balanced
            (:func:`~sumo_ayss.analysis.crossplay.crossplay_matrix`), or a pay does not fit
            the scale.
    """
    c = columns
    pay = scale.near_miss_pay(c["near_miss_pay"], c["episode_return"], c["collided"])
    # A rear-end the VUT caused by braking for nothing counts as a crash (issue 33).
    crash = harm_crash(c["collided"], c["rear_end_unjustified"])
    return crossplay_matrix(
        c["vut"],
        c["opponent_vut"],
        c["opponent_seed"],
        episode_harm(pay, crash, scale.max_episode_pay),
        c["collided"],
        episode_return=c["episode_return"],
        mobility=c["vut_mean_speed_mps"],
        preventable=c["crash_preventable"],
        hazards={name: c[name] for name in VUT_HAZARD_COLUMNS},
    )


def _scale(runs: Mapping[str, Sequence[ScorableRun]]) -> HarmScale | None:
    """The one harm scale of all ``runs``, or None (none, several or an invalid one)."""
    try:
        scales = {harm_scale_of(r) for rs in runs.values() for r in rs}
    except ConfigError:
        return None
    return next(iter(scales)) if len(scales) == 1 else None


def _stale(tables: CrossplayTablesLike, runs: Mapping[str, Sequence[object]]) -> bool:
    return tables.vuts is not None and sorted(tables.vuts) != sorted(runs)


def refusal(tables: CrossplayTablesLike, runs: Mapping[str, Sequence[object]]) -> str:
    """Why a case's stored cross-play table must not be ranked, or "": its record drove
    other VUTs than the runs' (a study whose VUTs changed and whose cross-play could not run
    yet), or its diagonal did not reproduce the outcome tables of some runs."""
    if tables.vuts is not None and _stale(tables, runs):
        return (
            f"the cross-play table is stale: it drove VUTs {', '.join(tables.vuts)}, the "
            f"runs are of {', '.join(runs)} (the pipeline drives the missing cells when "
            "every job of the case is done)"
        )
    bad = [(vut, seed, n - n_equal, n) for vut, seed, n, n_equal in tables.diagonal if n_equal != n]
    if not bad:
        return ""
    names = ", ".join(f"{vut} (seed {seed}: {differ}/{n})" for vut, seed, differ, n in bad)
    return (
        "the cross-play table is refused: its diagonal did not reproduce the outcome "
        f"tables of {names}; it would rank another vehicle than the one the opponents "
        "were trained against"
    )


def crossplay_input(
    tables: CrossplayTablesLike, runs: Mapping[str, Sequence[ScorableRun]]
) -> CrossplayInput:
    """The cross-play input of one case: its tables as read, scored on its runs' harm
    scale, or why there is none (:func:`refusal`: a table that must not be ranked); never
    raises.

    Args:
        tables: The case's files (:func:`sumo_ayss.run_folder.load_crossplay`).
        runs: ``{vut: runs}`` of the case.
    """
    path = tables.path
    if path is None:
        return CrossplayInput(missing=tables.missing)
    if _scale(runs) is None:
        return CrossplayInput(
            path=path,
            missing="the cross-play table cannot be scored: the runs' config.yaml files do "
            "not give one reward and episode length for all (harm scale)",
        )
    scale = _scale(runs)
    assert scale is not None
    if why := refusal(tables, runs):  # checked before the table, whether it reads or not
        diagonal = () if _stale(tables, runs) else tables.diagonal
        return CrossplayInput(path=path, missing=why, problem=f"{path}: {why}", diagonal=diagonal)
    if tables.table is None:
        return CrossplayInput(path=path, missing=tables.missing, problem=tables.problem)
    try:
        matrix = score_crossplay(tables.table.columns, scale)
    except ConfigError as exc:
        text = str(exc)
        problem = text if text.startswith(str(path)) else f"{path}: {text}"
        return CrossplayInput(
            path=path, missing=f"the cross-play table is unreadable ({problem})", problem=problem
        )
    diagonal = tables.diagonal
    if tables.reference_problem:
        return CrossplayInput(matrix, path, diagonal=diagonal, problem=tables.reference_problem)
    reference = None
    if tables.reference is not None:
        try:
            reference = score_crossplay(tables.reference.columns, scale)
        except ConfigError as exc:  # the ranking stands without it
            return CrossplayInput(
                matrix, path, diagonal=diagonal, problem=f"reference rows unreadable: {exc}"
            )
    if tables.inevitable_problem:
        return CrossplayInput(
            matrix, path, diagonal=diagonal, reference=reference, problem=tables.inevitable_problem
        )
    return CrossplayInput(
        matrix, path, diagonal=diagonal, reference=reference, inevitable=tables.inevitable
    )


def case_matrix(
    tables: CrossplayTablesLike, runs: Mapping[str, Sequence[ScorableRun]]
) -> CrossplayMatrix:
    """The cross-play matrix of one case (:func:`crossplay_input`).

    Raises:
        TableError: If there is no usable table (the message says why).
    """
    found = crossplay_input(tables, runs)
    if found.matrix is None:
        raise TableError(found.missing or f"no cross-play table in {tables.case_dir}")
    return found.matrix
