"""Blocks of (i), the cross-play ranking: every SPCP of the case against every VUT."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from sumo_ayss.analysis.case import CaseAnalysis
from sumo_ayss.analysis.crossplay import crossplay_sentence
from sumo_ayss.analysis.formatting import fmt_interval, fmt_num, fmt_p
from sumo_ayss.config.report import ReportOptions
from sumo_ayss.report.blocks import (
    Block,
    BulletList,
    Callout,
    FigureBlock,
    Heading,
    Paragraph,
    Table,
)
from sumo_ayss.report.crossplay_figure import crossplay_figure
from sumo_ayss.report.sections.common import display_path, pairs_table

__all__ = ["crossplay_blocks"]

BLOCK_WORDS = {
    "seed": "training-seed blocks (block s = the mean over the opponents of seed s)",
    "opponent": "opponent blocks (every opponent SPCP its own block)",
}


def crossplay_blocks(
    a: CaseAnalysis, colors: Mapping[str, str], out_dir: Path, options: ReportOptions
) -> list[Block]:
    """(i) Explanation, ranking table, pairwise comparisons and the per-opponent figure."""
    blocks: list[Block] = [Heading("(i) Cross-play ranking", 3)]
    blocks.append(
        Paragraph(
            "Each SPCP of this case (one per VUT and training seed) drives against every VUT "
            "of the case on the same outcome scenarios. A VUT's cross-play exposure X is the "
            "mean episode reward this pool of opponents extracts from it; lower X is safer. "
            "Because every opponent meets every VUT, a difference between two VUTs is read "
            "within each opponent. Two VUTs are compared by a paired t-test over "
            f"{BLOCK_WORDS.get(a.crossplay_blocks, a.crossplay_blocks)}."
        )
    )
    m = a.crossplay
    if m is None or not a.crossplay_rows:
        reason = a.crossplay_missing or "no cross-play ranking"
        return [
            *blocks,
            Callout(
                "Cross-play table missing", (reason[:1].upper() + reason[1:] + ".",), "warning"
            ),
        ]
    pct = f"{100 * options.level:g} %"
    order = [r.name for r in a.crossplay_rows]
    path = crossplay_figure(
        order,
        m.opponents,
        m.returns,
        m.vuts,
        colors,
        out_dir / f"{a.case}_crossplay_by_opponent.png",
        title=f"{a.info.title}: cross-play, reward per opponent (lower = safer)",
    )
    where = display_path(a.crossplay_path, out_dir) if a.crossplay_path is not None else ""
    blocks.append(
        FigureBlock(
            path,
            "Mean episode reward (reward/episode, over "
            f"{m.n_scenarios} scenarios) that each opponent SPCP extracts from each VUT, VUTs "
            "in cross-play ranking order (safest left); colour: the VUT the opponent was "
            "trained against, line style: its training seed. Lines that fall from left to "
            f"right agree with the ranking. Table: {where}.",
        )
    )
    rows = []
    for r in a.crossplay_rows:
        nxt = r.vs_next
        ci = fmt_interval(r.lo, r.hi)
        rows.append(
            (
                str(r.rank),
                r.name,
                f"{fmt_num(r.mean)} ({ci})" if ci else fmt_num(r.mean),
                str(r.n_seeds),
                f"{nxt.test}, p {fmt_p(nxt.p)}" if nxt else "—",
                ("yes" if nxt.significant else "no") if nxt else "—",
            )
        )
    blocks.append(
        Table(
            "Ranking by cross-play exposure X (mean episode reward of the pooled SPCPs), "
            "safest first",
            ("rank", "VUT", f"X ({pct} CI)", "blocks", "test vs next", "significant vs next"),
            tuple(rows),
            (True, False, True, True, False, False),
        )
    )
    blocks.append(pairs_table(a.crossplay_pairs, "X", pct, options.welch_alpha))
    blocks.append(
        BulletList(tuple(crossplay_sentence(c, a.crossplay_blocks) for c in a.crossplay_pairs))
    )
    return blocks
