"""A case's analysis: its data (:func:`sumo_ayss.analysis.case.analyse_case`), every
registered mode's own result (:meth:`~sumo_ayss.modes.registry.Mode.compute`) and the
verdict of the mode asked for (:meth:`~sumo_ayss.modes.registry.Mode.verdict`)."""

from __future__ import annotations

import contextlib
import os
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, Protocol, TypeVar

from sumo_ayss.modes.registry import get_mode, registered_modes

if TYPE_CHECKING:
    from sumo_ayss.analysis.case import CaseAnalysis, CaseOptions, RunLike
    from sumo_ayss.analysis.crossplay import CrossplayInput
    from sumo_ayss.analysis.crossplay_scoring import CrossplayTablesLike

__all__ = ["CaseInput", "analyse_case", "analyse_cases", "input_problems"]

R = TypeVar("R", bound="RunLike")


class CaseInput(Protocol[R]):
    """One case of a study as read (:class:`sumo_ayss.run_folder.CaseRuns`): its runs by VUT
    and its cross-play table."""

    @property
    def case(self) -> str: ...

    @property
    def runs(self) -> dict[str, list[R]]: ...

    @property
    def crossplay(self) -> CrossplayTablesLike: ...


def analyse_case(
    case: str,
    runs: dict[str, list[R]],
    options: CaseOptions,
    *,
    crossplay: CrossplayInput | None = None,
    paper: bool = True,
) -> CaseAnalysis[R]:
    """:func:`sumo_ayss.analysis.case.analyse_case` (same arguments: the case's data), then
    every registered mode's own result in registry order
    (:meth:`~sumo_ayss.modes.registry.Mode.compute`, in ``results``; the built-in modes'
    :class:`~sumo_ayss.modes.crossplay.CrossplayResult`,
    :class:`~sumo_ayss.modes.exposure.ExposureResult`,
    :class:`~sumo_ayss.modes.paper.PaperResult`), and the ``verdict`` given by the mode
    ``options.mode``.

    Raises:
        ConfigError: If ``options.mode`` is not a registered mode.
    """
    from sumo_ayss.analysis.case import analyse_case as analyse

    mode = get_mode(options.mode)
    a = analyse(case, runs, options, crossplay=crossplay, paper=paper)
    for each in registered_modes():
        result = each.compute(a)
        if result is not None:
            a.results[each.name] = result
    a.verdict = mode.verdict(a)
    return a


def analyse_cases(
    cases: Sequence[CaseInput[R]], options: CaseOptions, *, paper: bool = True
) -> list[CaseAnalysis[R]]:
    """The analysis of every case of a study (:func:`sumo_ayss.run_folder.case_runs`), each
    computed once, in order.

    Args:
        cases: The study's cases as read.
        options: Statistical settings.
        paper: Compute the paper mode (the AYSS bootstrap, the slow part).
    """
    from sumo_ayss.analysis.crossplay_scoring import crossplay_input

    return [
        analyse_case(
            c.case, c.runs, options, crossplay=crossplay_input(c.crossplay, c.runs), paper=paper
        )
        for c in cases
    ]


def input_problems(analyses: Sequence[CaseAnalysis[Any]]) -> list[str]:
    """The problems of the analysed cases' input files, one console line each (the report,
    ``rank`` and the pipeline print them; ``--strict`` makes them an error).

    They are the lines of the report's "Missing or incomplete data" callouts
    (:attr:`~sumo_ayss.analysis.case.CaseAnalysis.problems`), each naming its file: a run's
    problem starts with the file's name (``eval.csv missing``) and is joined to the run
    folder's path (its ``path``); a case's own problem (an unreadable cross-play table, which
    names its file) is prefixed with the case.
    """
    from sumo_ayss.analysis.case import run_label

    lines = []
    for a in analyses:
        own = list(a.problems)
        for members in a.runs.values():
            for run in members:
                for problem in run.problems:
                    lines.append(f"{run.path}{os.sep}{problem}")
                    with contextlib.suppress(ValueError):
                        own.remove(f"{run_label(run)}: {problem}")
        lines += [p if p.startswith(os.sep) else f"{a.case}: {p}" for p in own]
    return lines
