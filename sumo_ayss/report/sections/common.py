"""Text helpers shared by the report's sections: estimates, seed lists, relative paths."""

from __future__ import annotations

import math
from collections.abc import Sequence

from sumo_ayss.analysis.harm import VutOutcome
from sumo_ayss.analysis.ranking import SafetyIndex
from sumo_ayss.analysis.seeds import SeedComparison
from sumo_ayss.modes.formatting import (
    crash_text,
    fmt_interval,
    fmt_num,
    fmt_p,
    fmt_prob,
    mobility_text,
)
from sumo_ayss.report.blocks import Table
from sumo_ayss.run_folder import Estimate, RunRecord
from sumo_ayss.util.paths import display_path

__all__ = [
    "TIMID_NOTE",
    "crash_cell",
    "crash_text",
    "display_path",
    "fmt_est",
    "hazards_cell",
    "mobility_cell",
    "mobility_text",
    "seed_points_text",
    "seeds_text",
    "unjustified_cell",
]


def fmt_est(e: Estimate | None, digits: int = 2, scale: float = 1.0, unit: str = "") -> str:
    """``"19.48 (19.30–19.66)"``, ``"1.0 % (0.3–3.6)"``; ``—`` when unknown."""
    if e is None or not e.known:
        return "—"
    ci = fmt_interval(e.lo * scale, e.hi * scale, digits)
    value = fmt_num(e.value * scale, digits) + (f" {unit}" if unit else "")
    return f"{value} ({ci})" if ci else value


def seed_points_text(members: Sequence[RunRecord], idx: SafetyIndex) -> str:
    """Per-seed indices, labelled by seed when every seed with samples entered the index."""
    seeds = [
        r.seed for r in members if len(r.ayss if r.ayss is not None else r.ayss_bins or ()) > 0
    ]
    if len(seeds) != len(idx.seed_points):
        return ", ".join(fmt_num(p) for p in idx.seed_points)
    return ", ".join(f"s{s}: {fmt_num(p)}" for s, p in zip(seeds, idx.seed_points, strict=True))


def seeds_text(members: Sequence[RunRecord]) -> str:
    return ", ".join(str(r.seed) if r.seed is not None else "?" for r in members)


def test_cell(c: SeedComparison | None) -> str:
    """A comparison's test for a table cell: ``"paired t, p = 0.012, Holm p = 0.024"`` (the
    raw p, then the family-adjusted p that decides, where they differ); "—" without one."""
    if c is None:
        return "—"
    text = f"{c.test}, p {fmt_p(c.p)}"
    if c.p_family is not None and c.p_family != c.p and math.isfinite(c.p):
        text += f", Holm p {fmt_p(c.p_family)}"
    return text


def difference_cell(c: SeedComparison, digits: int = 2) -> str:
    """``B − A`` with its interval, or why there is none (too few seeds)."""
    ci = fmt_interval(-c.hi, -c.lo, digits)
    if not ci:
        n = min(c.n_a, c.n_b)
        ci = f"no interval with {n} seed{'s' if n != 1 else ''}"
    return f"{fmt_num(-c.difference, digits)} ({ci})"


def pairs_table(pairs: Sequence[SeedComparison], score: str, pct: str, alpha: float) -> Table:
    """The pairwise comparisons of a seed-level ranking (A ranked above B), ``score`` naming
    the score (``"H"``, ``"harm"``), its difference stated as B minus A, with the raw p and
    the family-adjusted p that decides (Holm over the adjacent pairs; a pair further apart
    takes the largest along the chain between them)."""
    rows = tuple(
        (
            c.name_a,
            c.name_b,
            difference_cell(c),
            c.test,
            fmt_prob(c.p),
            fmt_prob(c.p_decision),
            "yes" if c.significant else "no",
        )
        for c in pairs
    )
    head = (
        "A",
        "B",
        f"{score}_B − {score}_A ({pct} CI)",
        "test",
        "raw p",
        "adjusted p (Holm, adjacent claims)",
        f"significant (adjusted p < {alpha:g})",
    )
    numeric = (False, False, True, False, True, True, False)
    return Table("Pairwise comparisons (A ranked above B)", head, rows, numeric)


TIMID_NOTE = (
    "A VUT marked TIMID drove at a mean speed below 80 % of the median VUT's over the same "
    "episodes: it may owe its low harm to standing still rather than to driving safely."
)
"""What a TIMID flag means (:data:`sumo_ayss.analysis.harm.MOBILITY_FLOOR`)."""


def hazards_cell(o: VutOutcome | None) -> str:
    """The hazards a VUT caused to the follower behind it, or "—" (not recorded)."""
    h = None if o is None else o.hazards
    if h is None or not math.isfinite(h.get("rear_end", math.nan)):
        return "—"
    return (
        f"rear-ends {100 * h['rear_end']:.1f} % (caused {100 * h['rear_end_unjustified']:.1f} %), "
        f"follower braking {h['follower_max_braking_mps2']:.1f} m/s²"
    )


def unjustified_cell(o: VutOutcome | None) -> str:
    """The VUT's unjustified hard braking (rate, speed shed), flagged, or "—"."""
    h = None if o is None else o.hazards
    if o is None or h is None or not math.isfinite(h.get("unjustified_braking", math.nan)):
        return "—"
    flag = " (OVER-BRAKING)" if o.overbraking else ""
    return (
        f"{100 * h['unjustified_braking']:.0f} % of episodes, "
        f"{h['unjustified_dv_mps']:.1f} m/s shed{flag}"
    )


def crash_cell(o: VutOutcome | None) -> str:
    """:func:`crash_text` of a VUT's outcome, or "—"."""
    if o is None or not o.episodes:
        return "—"
    return crash_text(o.crashes, o.episodes, o.crash_lo, o.crash_hi)


def mobility_cell(o: VutOutcome | None) -> str:
    """:func:`mobility_text` of a VUT's outcome, or "—"."""
    return "—" if o is None else mobility_text(o.mobility, o.timid)
