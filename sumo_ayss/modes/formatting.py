"""How numbers, intervals, p-values and rankings read in verdict sentences and tables.

One formatter for every sentence and table cell, so a number reads the same in the modes'
verdicts, the report and ``rank``'s tables. Here (standard library only) rather than in
the report because the modes word their own verdicts and may not import the report.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

__all__ = [
    "MINUS",
    "crash_text",
    "fmt_interval",
    "fmt_num",
    "fmt_p",
    "fmt_p_family",
    "fmt_prob",
    "mobility_text",
    "rank_labels",
    "ranking_line",
    "seed_interval_text",
]

MINUS = "−"
"""The typographic minus sign (U+2212) of the report's numbers."""


def _finite(value: float | None) -> bool:
    return value is not None and math.isfinite(value)


def fmt_num(value: float | None, digits: int = 2, *, minus: str = MINUS, missing: str = "—") -> str:
    """``value`` with ``digits`` decimals and ``minus`` as the sign; ``missing`` for NaN/None.

    Examples: ``fmt_num(-1.234)`` is ``"−1.23"``; ``fmt_num(-1.234, minus="-")`` is ``"-1.23"``.
    """
    if not _finite(value):
        return missing
    return f"{value:.{digits}f}".replace("-", minus)


def fmt_interval(
    lo: float | None,
    hi: float | None,
    digits: int = 2,
    *,
    minus: str = MINUS,
    missing: str = "",
) -> str:
    """``"0.80–1.60"`` for non-negative bounds, ``"−0.30 to 0.40"`` otherwise.

    Args:
        lo: Lower bound.
        hi: Upper bound.
        digits: Decimals of each bound.
        minus: Sign of negative bounds.
        missing: The text when a bound is NaN or None.
    """
    if not (_finite(lo) and _finite(hi)):
        return missing
    assert lo is not None and hi is not None
    sep = "–" if lo >= 0 and hi >= 0 else " to "
    return f"{fmt_num(lo, digits, minus=minus)}{sep}{fmt_num(hi, digits, minus=minus)}"


def fmt_p(p: float | None, *, cap_high: bool = False, undefined: str = "n/a") -> str:
    """A p-value or probability after "p" or "P(…)": ``"= 0.012"``, ``"< 0.001"``.

    Args:
        p: The probability.
        cap_high: Write values above 0.999 as ``"> 0.999"``.
        undefined: The text for NaN or None.
    """
    if not _finite(p):
        return undefined
    assert p is not None
    if p < 0.001:
        return "< 0.001"
    if cap_high and p > 0.999:
        return "> 0.999"
    return f"= {p:.3f}"


def fmt_p_family(
    p: float | None, p_family: float | None, family_size: int, *, undefined: str = "n/a"
) -> str:
    """A raw p with its family-adjusted p beside it: ``"p = 0.017, adjusted p = 0.034 (Holm,
    2 adjacent claims)"``; the raw p alone where no adjustment applies (no family, or a
    family of one test whose adjusted p is the raw one).

    Args:
        p: The test's own p.
        p_family: Its p adjusted for the ranking's family of claims
            (:mod:`sumo_ayss.analysis.multiplicity`); None outside a family.
        family_size: Tests in the family.
        undefined: The text for an undefined p.
    """
    raw = f"p {fmt_p(p, undefined=undefined)}"
    if p_family is None or (family_size <= 1 and (p_family == p or not _finite(p))):
        return raw
    claims = f"{family_size} adjacent claim{'s' if family_size != 1 else ''}"
    return f"{raw}, adjusted p {fmt_p(p_family, undefined=undefined)} (Holm, {claims})"


def fmt_prob(p: float | None) -> str:
    """A probability for a table cell: ``"0.953"``, ``"< 0.001"``, ``"> 0.999"``, ``"—"``."""
    return fmt_p(p, cap_high=True, undefined="—").removeprefix("= ")


def seed_interval_text(lo: float, hi: float, n_seeds: int, digits: int = 2) -> str:
    """A seed-level interval for a table cell: ``"0.80–1.60"``, ``"2 seeds: no interval"``
    (:func:`sumo_ayss.analysis.seed_intervals.seed_mean_ci` gives none under three seeds).

    Args:
        lo: Lower bound (NaN when there is none).
        hi: Upper bound.
        n_seeds: Seeds behind the interval.
        digits: Decimals of each bound.
    """
    text = fmt_interval(lo, hi, digits)
    if text:
        return text
    return f"{n_seeds} seed{'s' if n_seeds != 1 else ''}: no interval"


def _tie_groups(n: int, significant_next: Sequence[bool]) -> list[list[int]]:
    """Positions 0..n-1 grouped where the ranking does not separate neighbours."""
    if n == 0:
        return []
    if len(significant_next) != n - 1:
        raise ValueError(f"{len(significant_next)} verdicts for {n} VUTs")
    groups: list[list[int]] = [[0]]
    for i, sig in enumerate(significant_next, start=1):
        if sig:
            groups.append([i])
        else:
            groups[-1].append(i)
    return groups


def ranking_line(names: Sequence[str], significant_next: Sequence[bool]) -> str:
    """``"a > b ≈ c"``: ``>`` where a VUT differs significantly from the next, ``≈`` where
    not. Names keep the ranking's order inside a tie too, so that the first VUT named is
    the leaderboard's first row everywhere (the order inside a tie is not a finding: the
    ``≈`` and the leaderboard's shared rank, :func:`rank_labels`, say so).

    Args:
        names: VUTs safest first.
        significant_next: Per VUT but the last, whether it differs significantly from the
            next one.
    """
    groups = _tie_groups(len(names), significant_next)
    return " > ".join(" ≈ ".join(names[i] for i in g) for g in groups)


def rank_labels(significant_next: Sequence[bool]) -> list[str]:
    """Each VUT's rank as a leaderboard shows it: ``"1"``, or ``"2–3"`` for every VUT of a
    tie (neighbours the ranking does not separate) spanning ranks 2 to 3.

    Args:
        significant_next: Per VUT but the last, whether it differs significantly from the
            next one (so ``len + 1`` VUTs).
    """
    n = len(significant_next) + 1
    labels = [""] * n
    for g in _tie_groups(n, significant_next):
        text = str(g[0] + 1) if len(g) == 1 else f"{g[0] + 1}–{g[-1] + 1}"
        for i in g:
            labels[i] = text
    return labels


def crash_text(crashes: int, episodes: int, lo: float, hi: float) -> str:
    """``"11.6 % (10.2–13.2 %), 209/1800"``: a crash rate with its interval (fractions)."""
    rate = crashes / episodes
    return f"{100 * rate:.1f} % ({100 * lo:.1f}–{100 * hi:.1f} %), {crashes}/{episodes}"


def mobility_text(mps: float, timid: bool) -> str:
    """``"21.3 m/s"``, ``"4.2 m/s (TIMID)"`` or "not recorded" (NaN)."""
    if not math.isfinite(mps):
        return "not recorded"
    return f"{mps:.1f} m/s" + (" (TIMID)" if timid else "")
