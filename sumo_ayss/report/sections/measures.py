"""Blocks of (j), the surrogate safety measures of the opponent pool (issue 27)."""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from sumo_ayss.analysis.case import CaseAnalysis
from sumo_ayss.analysis.measure_ranking import MeasureRanking, R157Row
from sumo_ayss.analysis.r157 import (
    R157_DECEL_MPS2,
    R157_INTRUSION_DEPTH_M,
    R157_TIME_MARGIN_S,
    R157_TIME_S,
)
from sumo_ayss.config.report import ReportOptions
from sumo_ayss.modes.formatting import fmt_num, ranking_line
from sumo_ayss.report.blocks import Block, FigureBlock, Heading, Paragraph, Table
from sumo_ayss.report.figstyle import save, style
from sumo_ayss.report.measures import CaseMeasures, case_measures
from sumo_ayss.run_folder import RunRecord

__all__ = ["measures_blocks", "with_ceiling"]


def _cell(x: float, digits: int = 2) -> str:
    return "∞" if x == math.inf else fmt_num(x, digits)


def measures_blocks(
    a: CaseAnalysis[RunRecord], colors: Mapping[str, str], out_dir: Path, options: ReportOptions
) -> list[Block]:
    """(j) Distribution table and figure per measure, the per-measure rankings, R157."""
    blocks: list[Block] = [Heading("(j) Surrogate safety measures", 3)]
    m = case_measures(a, level=options.level, r157_time_s=options.r157_time_s)
    if not isinstance(m, CaseMeasures):
        return [*blocks, Paragraph(f"No safety measures: {m}.")]
    unit = "opponent SPCP" if m.pool == "cross-play" else "training seed"
    blocks.append(
        Paragraph(
            f"Every episode of the {m.pool} pool reduced to surrogate safety measures "
            "(definitions, units and references: sumo_ayss.analysis.safety_measures). Per "
            f"VUT: the median over the episodes where a measure is defined, with a "
            f"{100 * options.level:g} % bootstrap interval (the {unit} resampled, then its "
            "episodes), and the 10th–90th percentiles; ∞ = nobody closed in. Each measure "
            f"alone ranks the VUTs by that median; τ is Kendall's τ of that order against "
            f"the primary ({m.primary_mode}) ranking. Braking and jerk are the VUT's own "
            "response, not only the situation's severity: a VUT that can brake harder may "
            "brake harder and still be safer. The relative speed at impact is read over the "
            "crashes only: a VUT crashed into more often, also at low speed, can show a "
            "lower median; read it with the crash counts of (i)."
        )
    )
    blocks.append(FigureBlock(_figure(m, colors, out_dir), _caption(m)))
    blocks.append(_table(m))
    blocks.append(_agreement(m))
    if m.r157:
        blocks.append(_r157_table(m, options))
    return blocks


def _table(m: CaseMeasures) -> Table:
    rows = []
    for r in m.rankings:
        for s in r.rows:
            if s.n == 0:
                continue
            rows.append(
                (
                    f"{r.spec.label} [{r.spec.unit}]",
                    s.vut,
                    f"{_cell(s.median)} ({_cell(s.lo)} to {_cell(s.hi)})",
                    f"{_cell(s.p10)} to {_cell(s.p90)}",
                    f"{s.n} / {s.n_total}",
                    str(s.rank) if s.rank else "—",
                )
            )
    return Table(
        "Per-VUT distribution of each measure under the pool",
        ("measure", "VUT", "median (interval)", "10th–90th pct", "defined / episodes", "rank"),
        tuple(rows),
        (False, False, True, True, True, True),
    )


def _agreement(m: CaseMeasures) -> Table:
    apart = m.primary_apart if len(m.primary_apart) + 1 == len(m.primary_order) else ()
    primary = ranking_line(m.primary_order, apart or [True] * (len(m.primary_order) - 1))
    rows = [("primary", m.primary_mode, primary or "—", "1")]
    for r in m.rankings:
        if not r.order:
            continue
        better = "higher" if r.spec.higher_is_safer else "lower"
        order = _order_text(r)
        rows.append((r.spec.label, f"{better} = safer", order, fmt_num(r.tau, 2)))
    return Table(
        "The ranking each measure alone gives, beside the primary one (safest first)",
        ("measure", "direction", "order", "τ vs primary"),
        tuple(rows),
        (False, False, False, True),
        "Primary row: “>” where the primary mode's test (Holm-adjusted) separates two VUTs, "
        "“≈” where it does not. Measure rows: “>” where the two medians' intervals are "
        "disjoint; “≈” where they overlap (or the medians tie), so that step of the order "
        "is not resolved by this measure. τ counts every step.",
    )


def _order_text(r: MeasureRanking) -> str:
    """The order, ``>`` between neighbours with disjoint intervals, ``≈`` otherwise."""
    by_vut = {s.vut: s for s in r.rows}
    parts = [r.order[0]]
    for prev, cur in itertools.pairwise(r.order):
        a, b = by_vut[prev], by_vut[cur]
        disjoint = a.lo > b.hi or b.lo > a.hi
        tied = math.isclose(a.median, b.median, rel_tol=1e-9, abs_tol=1e-12)
        parts += [" > " if disjoint and not tied else " ≈ ", cur]
    return "".join(parts)


def _r157_table(m: CaseMeasures, options: ReportOptions) -> Table:
    alt = {q.vut: q for q in m.r157_alt}

    def share(q: R157Row | None) -> str:
        if q is None:
            return "—"
        return f"{fmt_num(q.share, 3)} ({fmt_num(q.lo, 3)} to {fmt_num(q.hi, 3)})"

    rows = tuple(
        (
            q.vut,
            str(q.n_intrusions),
            str(q.n_required),
            str(q.n_handled),
            share(q),
            str(alt[q.vut].n_required) if q.vut in alt else "—",
            share(alt.get(q.vut)),
        )
        for q in m.r157
    )
    note = (
        f"UN R157 §5.2.5.2 cut-in condition: TTC at lane intrusion > v_rel / (2 · "
        f"{R157_DECEL_MPS2:g} m/s²) + c, read when the POV is "
        f"{R157_INTRUSION_DEPTH_M:g} m inside the VUT's lane, with c = {m.r157_time_s:g} s "
        f"(report.r157_time_s) and, beside it, c = {m.r157_alt_s:g} s "
        f"({R157_TIME_S:g} s is the regulation as its implementations' comments quote it; "
        f"{R157_TIME_MARGIN_S:g} s adds the 0.1 s margin of their code). The formula is taken "
        "from two implementations that cite the regulation (esmini's ALKS R157 controller, "
        "the EC JRC's JRC-FSM); the regulation's text itself was not retrieved and its other "
        "conditions on the cut-in are not applied (sumo_ayss.analysis.r157). — : the tables "
        "predate the closing-speed column, so the other constant cannot be read."
    )
    return Table(
        f"Cut-ins R157 says must be handled, and the share handled without a collision "
        f"({100 * options.level:g} % Wilson interval)",
        (
            "VUT",
            "intrusions ≥ 0.3 m",
            f"must be handled (c = {m.r157_time_s:g} s)",
            "handled",
            "share handled",
            f"must be handled (c = {m.r157_alt_s:g} s)",
            f"share handled (c = {m.r157_alt_s:g} s)",
        ),
        rows,
        (False, True, True, True, True, True, True),
        note,
    )


def _caption(m: CaseMeasures) -> str:
    return (
        f"Each measure's episodes under the {m.pool} pool, one box per VUT (median, quartiles, "
        "whiskers at the 5th and 95th percentiles; ∞, where nobody closed in, is drawn at "
        "the dashed line above every finite value, so each box's median is the table's; "
        "the share of ∞ is printed above each box). VUTs in the primary order, safest left."
    )


def with_ceiling(data: list[np.ndarray]) -> tuple[list[np.ndarray], float | None]:
    """The values a box plot draws: ∞ (nobody closed in) at a ceiling above every finite
    value of every VUT, so that each box's median is the table's, which counts ∞ too.

    Args:
        data: Per VUT, the measure's defined values (finite or +∞).

    Returns:
        ``(finite data, ceiling)``; ceiling None where no VUT has both kinds.
    """
    finite = np.concatenate([d[np.isfinite(d)] for d in data] or [np.zeros(0)])
    if not finite.size or not any(np.isposinf(d).any() for d in data):
        return [d[np.isfinite(d)] for d in data], None
    top = float(finite.max())
    ceiling = top + max(0.1 * abs(top), 0.5)
    return [np.where(np.isposinf(d), ceiling, d) for d in data], ceiling


def _figure(m: CaseMeasures, colors: Mapping[str, str], out_dir: Path) -> Path:
    shown = [r for r in m.rankings if any(s.n for s in r.rows)]
    ncols = min(5, max(1, len(shown)))
    nrows = max(1, math.ceil(len(shown) / ncols))
    with style():
        fig = Figure(figsize=(3.0 * ncols, 2.9 * nrows), layout="constrained")
        axes = np.atleast_1d(fig.subplots(nrows, ncols)).ravel()
        for ax, r in zip(axes, shown, strict=False):
            data = [m.values[r.spec.column][v] for v in m.vuts]
            data, ceiling = with_ceiling(data)
            if ceiling is not None:
                ax.axhline(ceiling, color="0.5", lw=0.8, ls="--")
                ax.annotate("∞", (1.0, ceiling), xycoords=("axes fraction", "data"), fontsize=8)
            keep = [i for i, d in enumerate(data) if d.size]
            if keep:
                box = ax.boxplot(
                    [data[i] for i in keep],
                    positions=keep,
                    whis=(5, 95),
                    showfliers=False,
                    patch_artist=True,
                    widths=0.6,
                )
                for patch, i in zip(box["boxes"], keep, strict=True):
                    patch.set_facecolor(colors.get(m.vuts[i], "C0"))
                    patch.set_alpha(0.6)
            for i, s in enumerate(r.rows):
                if s.n and s.share_inf > 0:
                    ax.annotate(
                        f"∞ {100 * s.share_inf:.0f}%",
                        (i, 1.0),
                        xycoords=("data", "axes fraction"),
                        ha="center",
                        va="top",
                        fontsize=7,
                    )
            ax.set_xticks(range(len(m.vuts)), m.vuts, rotation=30 if len(m.vuts) > 4 else 0)
            ax.set_title(f"{r.spec.label} [{r.spec.unit}]", fontsize=9)
        for ax in axes[len(shown) :]:
            ax.set_visible(False)
        fig.suptitle(f"{m.case}: surrogate safety measures under the {m.pool} pool")
        return save(fig, out_dir / f"{m.case}_safety_measures.png")
