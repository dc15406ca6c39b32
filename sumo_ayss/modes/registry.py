"""The ranking-mode record, its registry and the uniform standing a mode ranks by (see
:mod:`sumo_ayss.modes`).

Standard library, :mod:`sumo_ayss.util.errors` and :mod:`sumo_ayss.util.validation` only: the
configuration validates ``report.mode`` against this registry without loading numpy.
"""

from __future__ import annotations

import abc
import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, TypeVar

from sumo_ayss.util.errors import ConfigError
from sumo_ayss.util.registry import Registry
from sumo_ayss.util.validation import check_choice, require

if TYPE_CHECKING:
    from sumo_ayss.analysis.case import CaseAnalysis
    from sumo_ayss.analysis.case_verdict import CaseVerdict
    from sumo_ayss.analysis.harm import VutOutcome

__all__ = [
    "Mode",
    "Standing",
    "check_mode",
    "get_mode",
    "headline_text",
    "missing_rows_line",
    "mode_names",
    "mode_result",
    "register_mode",
    "registered_modes",
    "unregister_mode",
]

_NAME = re.compile(r"[a-z][a-z0-9_]*")

T = TypeVar("T")


@dataclass(frozen=True)
class Standing:
    """One VUT's place in one mode's ranking of a case, the same shape in every mode.

    Attributes:
        rank: 1 for the safest.
        vut: VUT name.
        score: The mode's score (its unit: :attr:`Mode.unit`).
        lo: Lower bound of the score's interval (NaN where there is none).
        hi: Upper bound.
        n_seeds: Training seeds (or blocks) behind the score.
        next_vut: The VUT ranked next, None for the last.
        significant: The mode's verdict against ``next_vut`` (significantly safer or not);
            None for the last, or when the two are not comparable.
        ranked_apart: Whether the ranking itself separates this VUT from the next (the
            order check counts these adjacent pairs).
        p: Raw p-value of the mode's test against ``next_vut``; None without a test.
        p_adjusted: That p adjusted for the ranking's family of claims (Holm over the
            adjacent pairs, :mod:`sumo_ayss.analysis.multiplicity`), which decides
            ``significant``; None without a test.
        margin: How much safer this VUT is than ``next_vut``, in the score's unit and
            oriented so that positive = safer (the paired difference the test is about;
            NaN for the last or without one).
        margin_lo: Lower bound of its interval at the report's level (NaN where the seeds
            cannot support one, :mod:`sumo_ayss.analysis.seed_intervals`).
        margin_hi: Upper bound.
        test: The test's name (``"paired t"``, ``"Welch t"``, ``"none"``); "" without one.
        n_a: Seeds of this VUT in that test.
        n_b: Seeds of the next VUT in that test.
        vs_next: The verdict sentence against ``next_vut``; "" for the last.
    """

    rank: int
    vut: str
    score: float
    lo: float
    hi: float
    n_seeds: int
    next_vut: str | None
    significant: bool | None
    ranked_apart: bool
    p: float | None = None
    test: str = ""
    n_a: int = 0
    n_b: int = 0
    vs_next: str = ""
    p_adjusted: float | None = None
    margin: float = math.nan
    margin_lo: float = math.nan
    margin_hi: float = math.nan


@dataclass(frozen=True)
class Mode(abc.ABC):
    """A ranking mode: how a case's VUTs are scored, ranked and compared, and how that reads.

    A mode is an object: its data are the fields below, its behaviour the methods, which
    read a :class:`~sumo_ayss.analysis.case.CaseAnalysis`. A new mode subclasses this class
    in one module of :mod:`sumo_ayss.modes` (its methods import what they need when called,
    so that this module stays light) and registers an instance.

    Attributes:
        name: The mode's name in ``report.mode``, ``--mode`` and ``ranking.csv``.
        description: The paragraph the report writes about the mode.
        score_name: What the score is, with its orientation (leaderboard, terminal).
        interval_name: What the score's interval is (leaderboard footnote).
        digits: Decimals of the score in ``ranking.md``.
        runs_crossplay: The pipeline runs the cross-play stage before the report.
        needs_safety_index: Ranking in this mode needs the AYSS safety indices (the slow
            bootstrap); a ranking in another mode skips them.
    """

    name: str
    description: str
    score_name: str
    interval_name: str
    digits: int
    runs_crossplay: bool = False
    needs_safety_index: bool = False

    def __post_init__(self) -> None:
        require(
            isinstance(self.name, str) and _NAME.fullmatch(self.name) is not None,
            f"mode name must be lower-case letters, digits and '_', got {self.name!r}",
        )

    @abc.abstractmethod
    def available(self, a: CaseAnalysis[Any]) -> bool:
        """Whether the mode has a ranking of this case."""

    @abc.abstractmethod
    def standings(self, a: CaseAnalysis[Any]) -> list[Standing]:
        """The case's ranking in this mode, safest first."""

    @abc.abstractmethod
    def verdict(self, a: CaseAnalysis[Any]) -> CaseVerdict:
        """The case's verdict when this mode was asked for, as a record (called after every
        mode's data is computed); its ``mode`` is another mode's when this one has no
        ranking and falls back to it."""

    @abc.abstractmethod
    def headline(self, a: CaseAnalysis[Any], v: CaseVerdict) -> str:
        """The verdict record ``v`` in words, for a verdict this mode gave (or fell back
        from)."""

    @abc.abstractmethod
    def unit(self, a: CaseAnalysis[Any]) -> str:
        """The score's unit text in ``ranking.csv`` and ``ranking.md``."""

    @abc.abstractmethod
    def ends(self, a: CaseAnalysis[Any], safest: str, least: str) -> tuple[bool, float]:
        """``(found, p)`` for a known safest and least safe VUT: whether this mode finds the
        first significantly safer than the second, and the p-value (NaN when it has none)."""

    @abc.abstractmethod
    def score_text(self, a: CaseAnalysis[Any], s: Standing) -> str:
        """The score with its interval as the leaderboard writes it."""

    @abc.abstractmethod
    def interval_text(self, lo: float, hi: float, n_seeds: int, digits: int) -> str:
        """The interval as ``ranking.md`` writes it ("" without one)."""

    def companion_lines(self, a: CaseAnalysis[Any]) -> list[str]:
        """Verdict-callout lines after the ranking line, when this mode gave the headline
        (e.g. the other modes' rankings); none by default."""
        return []

    def closing_lines(self, a: CaseAnalysis[Any]) -> list[str]:
        """Verdict-callout lines after the premise check, when this mode was asked for;
        none by default."""
        return []

    def compute(self, a: CaseAnalysis[Any]) -> object | None:
        """The mode's own result from the case's data (its runs, tables and settings), kept
        in ``a.results[name]`` by :func:`~sumo_ayss.modes.analyse_case` (every registered
        mode's in registry order, then the verdict: a mode may read an earlier one's result
        in its methods, :func:`mode_result`); a line per missing or unreadable input goes
        into ``a.problems``. None (the default): no result of its own."""
        return None

    def outcomes(self, a: CaseAnalysis[Any]) -> Mapping[str, VutOutcome]:
        """``{vut: crashes, mobility, hazards}`` over the episodes this mode scores, shown
        beside its score (``ranking.csv``, the leaderboard); empty (the default): it reads
        no outcomes."""
        return {}

    def section(self, a: CaseAnalysis[Any]) -> tuple[str, list[str]] | None:
        """The report's section of this mode for a case, ``(title, paragraphs)``, after the
        built-in sections; None (the default): none of its own."""
        return None

    def gap_text(self, a: CaseAnalysis[Any]) -> str | None:
        """Why the mode has no ranking of a case, one sentence (:func:`missing_rows_line`);
        None (the default): a generic sentence."""
        return None


# --------------------------------------------------------------------------- the registry

_REGISTRY: Registry[Mode] = Registry("mode")


def register_mode(mode: Mode, *, replace: bool = False) -> Mode:
    """Add ``mode`` to the registry (in order: its rows follow the earlier modes') and
    return it. Registering the same record again is a no-op; another record under a known
    name needs ``replace=True``.

    Raises:
        ConfigError: If the name is taken by another record.
    """
    return _REGISTRY.register(mode.name, mode, replace=replace)


def unregister_mode(name: str) -> Mode:
    """Remove a registered mode (tests, plugins) and return its record."""
    return _REGISTRY.unregister(name)


def get_mode(name: str) -> Mode:
    """The registered mode ``name``.

    Raises:
        ConfigError: Naming the registered modes, if ``name`` is none of them.
    """
    return _REGISTRY.get(name)


def check_mode(name: str, where: str = "report.mode") -> Mode:
    """The registered mode ``name``, as the configuration field ``where`` names it (the
    stages check ``report.mode`` here when they start: the configuration imports no mode).

    Raises:
        ConfigError: ``"report.mode must be one of [...]"``, if ``name`` is none of them.
    """
    check_choice(where, name, mode_names())
    return get_mode(name)


def headline_text(a: CaseAnalysis[Any]) -> str:
    """The case's headline: its verdict (``a.verdict``) worded by the mode asked for."""
    return get_mode(a.mode).headline(a, a.verdict)


def missing_rows_line(a: CaseAnalysis[Any]) -> str | None:
    """One line saying why the mode asked for (``a.mode``) has no rows for the case and
    which mode's rows stand in their place, for ``ranking.md``, the report's leaderboard
    and the terminal; None when it has them."""
    mode = get_mode(a.mode)
    if mode.available(a):
        return None
    why = mode.gap_text(a) or "this mode has no ranking of it"
    why = why.rstrip(". ")
    instead = (
        f"; the {a.ranking_mode}-mode rows stand in their place" if a.ranking_mode != a.mode else ""
    )
    return f"No {a.mode}-mode rows for {a.case}: {why}{instead}."


def mode_result(a: CaseAnalysis[Any], name: str, kind: type[T]) -> T:
    """The result mode ``name`` computed for the case (``a.results[name]``), of type ``kind``.

    Raises:
        ConfigError: If the case holds no such result (an analysis not made by
            :func:`~sumo_ayss.modes.analyse_case`, or by another mode record of that name).
    """
    result = a.results.get(name)
    if not isinstance(result, kind):
        raise ConfigError(
            f"case {a.case}: no {name}-mode result of type {kind.__name__} (got "
            f"{type(result).__name__}; analyse it with sumo_ayss.modes.analyse_case)"
        )
    return result


def mode_names() -> tuple[str, ...]:
    """The registered modes' names, in registry order."""
    return _REGISTRY.names()


def registered_modes() -> tuple[Mode, ...]:
    """The registered modes, in registry order."""
    return _REGISTRY.records()
