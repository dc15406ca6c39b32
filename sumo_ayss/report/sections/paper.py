"""Block of the paper mode: (g) safety index from the AYSS and pairwise verdicts."""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path

from sumo_ayss.analysis.case import CaseAnalysis
from sumo_ayss.analysis.verdict import Verdict
from sumo_ayss.config.report import ReportOptions
from sumo_ayss.modes.formatting import fmt_interval, fmt_num, fmt_prob, seed_interval_text
from sumo_ayss.modes.paper import (
    MIN_SEEDS_FOR_INTERVAL,
    diff_interval,
    pair_sentence,
    paper_result,
    significance_rule,
)
from sumo_ayss.report import figures
from sumo_ayss.report.blocks import Block, BulletList, FigureBlock, Heading, Paragraph, Table
from sumo_ayss.report.sections.common import seed_points_text
from sumo_ayss.run_folder import RunRecord

__all__ = ["paper_blocks"]


def _difference(v: Verdict) -> str:
    """``"0.42 (0.10–0.80)"``: index A − B with its interval (none under three seeds)."""
    return f"{fmt_num(v.difference)} ({diff_interval(v)})"


def _index_interval(lo: float, hi: float, n_seeds: int) -> str:
    """A safety index's bootstrap interval, or none under three seeds (as the seed-level
    intervals: :func:`sumo_ayss.modes.formatting.seed_interval_text`)."""
    if n_seeds < MIN_SEEDS_FOR_INTERVAL:
        return seed_interval_text(math.nan, math.nan, n_seeds)
    return fmt_interval(lo, hi)


def paper_blocks(
    a: CaseAnalysis[RunRecord], colors: Mapping[str, str], out_dir: Path, options: ReportOptions
) -> list[Block]:
    info = a.info
    unit = info.indicator.unit
    blocks: list[Block] = [
        Heading("(g) Paper mode: safety index from the AYSS and pairwise verdicts", 3)
    ]
    pct = f"{100 * options.level:g} %"
    blocks.append(
        Paragraph(
            f"Safety index = − mean over {options.index_bins} equal headway bins on "
            f"[0, {options.h_max_m:g}] m of the per-bin mean {info.symbol} of the AYSS "
            f"(larger = safer VUT), with a {pct} hierarchical-bootstrap interval "
            f"({options.n_boot} replicates: seeds, then samples within a seed)."
        )
    )
    result = paper_result(a)
    if not result.indices:
        return [*blocks, Paragraph("No safety index: no AYSS samples in this case yet.")]
    if any(i.indicator_moments is not None for i in result.indices.values()):
        blocks.append(
            Paragraph(
                "Read from each run's ayss_bins.csv (the samples' moments per 1/32 m headway "
                "cell; ayss.csv is not kept): the indices, per-seed indices and sample counts "
                "are the samples' own; the interval resamples the seeds and each bin's count "
                "as the samples' bootstrap does, but draws each resampled bin sum from the "
                "bin's mean and variance rather than from its samples."
            )
        )
    path = figures.safety_index_figure(
        result.indices,
        colors,
        out_dir / f"{a.case}_safety_index.png",
        unit=unit,
        what=info.symbol,
        title=f"{info.title}: safety index",
    )
    blocks.append(
        FigureBlock(path, f"Safety index per VUT with its {pct} interval; safest on top.")
    )
    by_pair = {(p.verdict.name_a, p.verdict.name_b): p for p in result.pairs}
    rows = []
    for r in result.ranking:
        idx = result.indices[r.name]
        nxt = result.ranking[r.rank].name if r.rank < len(result.ranking) else None
        pair = by_pair.get((r.name, nxt)) if nxt else None
        rows.append(
            (
                str(r.rank),
                r.name,
                f"{fmt_num(r.point)} ({_index_interval(r.lo, r.hi, r.n_seeds)})",
                seed_points_text(a.runs[r.name], idx),
                str(r.n_seeds),
                str(idx.n_samples),
                fmt_prob(pair.verdict.p_a_safer) if pair else "—",
                ("yes" if pair.significant else "no") if pair else "—",
            )
        )
    blocks.append(
        Table(
            f"Ranking by safety index [{unit}], safest first",
            (
                "rank",
                "VUT",
                f"index ({pct} CI)",
                "per-seed index",
                "seeds",
                "samples",
                "P(safer than next)",
                "significant vs next",
            ),
            tuple(rows),
            (True, False, True, True, True, True, True, False),
        )
    )
    if result.pairs:
        p_rows = tuple(
            (
                p.verdict.name_a,
                p.verdict.name_b,
                _difference(p.verdict),
                fmt_prob(p.verdict.p_a_safer),
                fmt_num(p.verdict.cohens_d),
                fmt_prob(p.verdict.p_seed_welch),
                fmt_prob(p.p_family),
                "yes" if p.verdict.significant else "no",
                "yes" if p.significant else "no",
                p.safer or "no significant difference",
            )
            for p in result.pairs
        )
        blocks.append(
            Table(
                "Pairwise verdicts (A ranked above B)",
                (
                    "A",
                    "B",
                    f"index A − B [{unit}] ({pct} CI)",
                    "P(A safer)",
                    "Cohen's d",
                    "Welch p (seeds)",
                    "Welch p, Holm-adjusted",
                    "bootstrap CI excludes 0",
                    "significant (both)",
                    "safer",
                ),
                p_rows,
                (False, False, True, True, True, True, True, False, False, False),
                significance_rule(options),
            )
        )
        blocks.append(BulletList(tuple(pair_sentence(p) for p in result.pairs)))
    return blocks
