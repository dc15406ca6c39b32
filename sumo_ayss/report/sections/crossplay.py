"""Blocks of (i), the cross-play ranking: every SPCP of the case against every VUT."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from sumo_ayss.analysis.case import CaseAnalysis
from sumo_ayss.config.report import ReportOptions
from sumo_ayss.modes.crossplay import crossplay_gap_text, crossplay_result, crossplay_sentence
from sumo_ayss.modes.formatting import fmt_num, fmt_p, seed_interval_text
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
from sumo_ayss.report.sections.common import (
    TIMID_NOTE,
    crash_cell,
    display_path,
    mobility_cell,
    pairs_table,
    test_cell,
)
from sumo_ayss.run_folder import CaseFolder, RunRecord, read_adaptive
from sumo_ayss.util.errors import TableError

__all__ = ["crossplay_blocks"]

BLOCK_WORDS = {
    "seed": "training-seed blocks (block s = the mean over the opponents of seed s)",
    "opponent": "opponent blocks (every opponent SPCP its own block)",
}


def crossplay_blocks(
    a: CaseAnalysis[RunRecord], colors: Mapping[str, str], out_dir: Path, options: ReportOptions
) -> list[Block]:
    """(i) Explanation, ranking table, pairwise comparisons and the per-opponent figure."""
    result = crossplay_result(a)
    blocks: list[Block] = [Heading("(i) Cross-play ranking", 3)]
    blocks.append(
        Paragraph(
            "Each SPCP of this case (one per VUT and training seed) drives against every VUT "
            "of the case on the same outcome scenarios, exactly as the outcome stage drives "
            "it. A VUT's cross-play harm H is the mean harm per episode this pool of opponents "
            "brings about against it: 1 for an episode that ends in a collision, else the "
            "near-miss reward paid over the most an episode can pay. Lower H is safer; a "
            "collision is never the VUT's gain. Because every opponent meets every VUT, a "
            "difference between two VUTs is read within each opponent. Two VUTs are compared "
            "by a paired t-test over "
            f"{BLOCK_WORDS.get(result.blocks, result.blocks)}."
        )
    )
    blocks.append(_diagonal_block(a))
    blocks += _adaptive_blocks(a)
    m = result.matrix
    if m is None or not result.rows:
        gap = result.gap
        reason = crossplay_gap_text(gap) if gap is not None else "no cross-play ranking"
        return [
            *blocks,
            Callout(
                "Cross-play table missing", (reason[:1].upper() + reason[1:] + ".",), "warning"
            ),
        ]
    pct = f"{100 * options.level:g} %"
    order = [r.name for r in result.rows]
    path = crossplay_figure(
        order,
        m.opponents,
        m.harm,
        m.vuts,
        colors,
        out_dir / f"{a.case}_crossplay_by_opponent.png",
        title=f"{a.info.title}: cross-play, harm per opponent (lower = safer)",
    )
    where = display_path(result.path, out_dir) if result.path is not None else ""
    blocks.append(
        FigureBlock(
            path,
            f"Mean harm per episode (over {m.n_scenarios} scenarios) that each opponent SPCP "
            "brings about against each VUT, VUTs in cross-play ranking order (safest left); "
            "colour: the VUT the opponent was trained against, line style: its training "
            "seed. Lower is safer, so lines that rise from left to right agree with the "
            f"ranking. Table: {where}.",
        )
    )
    outcomes = result.outcomes
    rows = []
    for r in result.rows:
        nxt = r.vs_next
        ci = seed_interval_text(r.lo, r.hi, r.n_seeds, 3)
        o = outcomes.get(r.name)
        rows.append(
            (
                str(r.rank),
                r.name,
                f"{fmt_num(r.mean, 3)} ({ci})",
                str(r.n_seeds),
                test_cell(nxt),
                ("yes" if nxt.significant else "no") if nxt else "—",
                crash_cell(o),
                mobility_cell(o),
            )
        )
    blocks.append(
        Table(
            "Ranking by cross-play harm H (mean harm per episode of the pooled SPCPs), "
            "safest first; crash rate and mean VUT speed over the same episodes",
            (
                "rank",
                "VUT",
                f"H ({pct} CI)",
                "blocks",
                "test vs next",
                "significant vs next",
                "crash rate (Wilson 95 % CI, episodes pooled)",
                "mean speed",
            ),
            tuple(rows),
            (True, False, True, True, False, False, True, True),
        )
    )
    if any(o.timid for o in outcomes.values()):
        blocks.append(Callout("Timid VUT", (TIMID_NOTE,), "warning"))
    blocks.append(pairs_table(result.pairs, "H", pct, options.welch_alpha))
    blocks.append(
        BulletList(
            tuple(
                crossplay_sentence(r.vs_next, result.blocks)
                for r in result.rows
                if r.vs_next is not None
            ),
        )
    )
    return blocks


def _diagonal_block(a: CaseAnalysis[RunRecord]) -> Block:
    """The diagonal check: every SPCP against its own VUT reproduced its outcome table."""
    checks = crossplay_result(a).diagonal
    if not checks:
        return Callout(
            "Diagonal not checked",
            (
                "This cross-play table predates the check that each SPCP, driven against its "
                "own VUT, reproduces its run's outcome table episode for episode (run "
                "python -m sumo_ayss.crossplay <config> --force to check it).",
            ),
            "warning",
        )
    equal = sum(c[3] for c in checks)
    total = sum(c[2] for c in checks)
    return Paragraph(
        f"Diagonal check: each of the {len(checks)} SPCPs, driven against its own VUT, "
        f"reproduced its run's outcome table episode for episode ({equal} of {total} "
        "episodes equal): cross-play drove the same vehicles the SPCPs were trained and "
        "scored against."
    )


def _adaptive_blocks(a: CaseAnalysis[RunRecord]) -> list[Block]:
    """Adaptive seeding's looks at this case (``adaptive.json`` beside the cross-play table),
    when the pipeline added seeds adaptively; nothing for a fixed grid."""
    table = crossplay_result(a).path
    if table is None:
        return []
    path = CaseFolder(table.parent).adaptive_json
    if not path.is_file():
        return []
    try:
        record = read_adaptive(path)
    except TableError as exc:
        return [Callout("Adaptive seeding record unreadable", (str(exc),), "warning")]
    if not record.looks:
        return []
    looked = [name for name, _ in record.vuts]
    if looked and sorted(looked) != sorted(a.runs):
        why = (
            f"{path} looked at VUTs {', '.join(looked)}; this case ranks "
            f"{', '.join(a.runs)}: the record is stale (a VUT was added, dropped or renamed "
            "since) and is not shown"
        )
        return [Callout("Adaptive seeding record ignored", (why,), "warning")]
    rows = tuple(
        (
            str(x.n_seeds),
            fmt_p(x.omnibus_p),
            f"{x.gate_level:.3g}",
            f"{x.safest} vs {x.least_safe}",
            fmt_p(x.ends_p),
            "settled" if x.settled else "not settled",
        )
        for x in record.looks
    )
    last = record.looks[-1]
    if last.settled:
        end = f"The ranking settled at {last.n_seeds} seeds per VUT."
    elif last.n_seeds >= record.max_seeds:
        end = (
            f"The ranking had not settled at the cap of {record.max_seeds} seeds per VUT: "
            "its ends are not established at the procedure's level."
        )
    else:
        end = "Adaptive seeding stopped before the cap (a job or the cross-play stage failed)."
    return [
        Paragraph(
            f"Adaptive seeding: the grid started with {len(record.first_seeds)} seeds per VUT "
            f"and adds one at a time, up to {record.max_seeds}, while the ranking has not "
            "settled: settled means the F test over all VUTs (VUT × seed block) is below a "
            "level calibrated so that the sequence of looks claims a settled ranking in "
            f"{100 * record.alpha:g} % of grids of equally safe VUTs, and the paired t of the "
            f"current ends is below {record.alpha:g}. {end}"
        ),
        Table(
            "Adaptive seeding: each look at this case",
            ("seeds per VUT", "F gate p", "gate level", "ends", "ends p", "verdict"),
            rows,
            (True, True, True, False, True, False),
        ),
    ]
