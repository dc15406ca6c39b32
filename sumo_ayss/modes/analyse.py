"""A case's analysis with the verdict of the mode asked for (the analysis computes every
mode's data; the mode gives the verdict, :attr:`~sumo_ayss.modes.registry.Mode.verdict`)."""

from __future__ import annotations

from typing import TYPE_CHECKING, TypeVar

from sumo_ayss.modes.registry import get_mode

if TYPE_CHECKING:
    from sumo_ayss.analysis.case import CaseAnalysis, CaseOptions, RunLike
    from sumo_ayss.analysis.crossplay import CrossplayInput

__all__ = ["analyse_case"]

R = TypeVar("R", bound="RunLike")


def analyse_case(
    case: str,
    runs: dict[str, list[R]],
    options: CaseOptions,
    *,
    crossplay: CrossplayInput | None = None,
    paper: bool = True,
) -> CaseAnalysis[R]:
    """:func:`sumo_ayss.analysis.case.analyse_case` (same arguments), its ``verdict`` given
    by the mode ``options.mode``.

    Raises:
        ConfigError: If ``options.mode`` is not a registered mode.
    """
    from sumo_ayss.analysis.case import analyse_case as analyse

    mode = get_mode(options.mode)
    a = analyse(case, runs, options, crossplay=crossplay, paper=paper)
    a.verdict = mode.verdict(a)
    return a
