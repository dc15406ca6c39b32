"""Blocks of one case: verdict callout, reward shapes, learning curves, indicator vs headway.

:func:`case_blocks` assembles the whole case section, (a) to (h), from the other section
modules.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from sumo_ayss.analysis.ayss_cells import inside_moments
from sumo_ayss.analysis.case import CaseAnalysis
from sumo_ayss.config.report import ReportOptions
from sumo_ayss.modes import get_mode, headline_text, registered_modes
from sumo_ayss.modes.formatting import fmt_num, ranking_line
from sumo_ayss.modes.paper import paper_result
from sumo_ayss.report import figures
from sumo_ayss.report.blocks import Block, Callout, FigureBlock, Heading, Paragraph, Table
from sumo_ayss.report.sections.common import display_path
from sumo_ayss.report.sections.crossplay import crossplay_blocks
from sumo_ayss.report.sections.discriminability import discriminability_blocks
from sumo_ayss.report.sections.measures import measures_blocks
from sumo_ayss.report.sections.outcome import (
    exposure_blocks,
    outcome_blocks,
    premise_blocks,
    premise_sentence,
)
from sumo_ayss.report.sections.paper import paper_blocks
from sumo_ayss.report.sections.reference import reference_blocks
from sumo_ayss.run_folder import RunRecord
from sumo_ayss.training.trust import training_status

__all__ = ["case_blocks", "verdict_lines"]


def case_blocks(
    a: CaseAnalysis[RunRecord], colors: Mapping[str, str], out_dir: Path, options: ReportOptions
) -> list[Block]:
    info, case = a.info, a.case
    anchor = f"case-{case}"
    blocks: list[Block] = [Heading(f"{info.title} ({case})", 2, anchor)]
    blocks.append(Callout(f"Verdict — {info.title}", verdict_lines(a, options), a.verdict.kind))
    if a.problems:
        blocks.append(
            Callout("Missing or incomplete data in this case", tuple(a.problems), "warning")
        )
    blocks += reward_blocks(a, out_dir)
    blocks += learning_blocks(a, colors, out_dir)
    blocks += indicator_blocks(a, colors, out_dir, options)
    blocks += outcome_blocks(a)
    blocks += premise_blocks(a, options)
    blocks += exposure_blocks(a, colors, out_dir, options)
    blocks += paper_blocks(a, colors, out_dir, options)
    case_dirs = list(dict.fromkeys(r.path.parent.parent for rs in a.runs.values() for r in rs))
    blocks += discriminability_blocks(case, list(a.runs), case_dirs, out_dir, colors)
    blocks += crossplay_blocks(a, colors, out_dir, options)
    blocks += measures_blocks(a, colors, out_dir, options)
    blocks += reference_blocks(a)
    for mode in registered_modes():  # a mode's own section (none for the built-in ones)
        section = mode.section(a)
        if section is not None:
            blocks += [Heading(section[0], 3), *(Paragraph(p) for p in section[1])]
    return blocks


def verdict_lines(a: CaseAnalysis[RunRecord], options: ReportOptions) -> tuple[str, ...]:
    """The verdict callout: the mode's headline and ranking, the premise, the other modes."""
    v = a.verdict
    lines = [headline_text(a)]
    if v.order:
        lines.append(f"Ranking ({v.mode} mode), safest first: {ranking_line(v.order, v.apart)}")
    lines += get_mode(a.ranking_mode).companion_lines(a)
    lines.append(premise_sentence(paper_result(a).premise, options))
    lines += get_mode(a.mode).closing_lines(a)
    return tuple(lines)


def reward_blocks(a: CaseAnalysis[RunRecord], out_dir: Path) -> list[Block]:
    blocks: list[Block] = [Heading("(a) Reward shapes", 3)]
    rewards = [r.reward for rs in a.runs.values() for r in rs if r.reward is not None]
    if not rewards:
        return [*blocks, Paragraph("No readable config.yaml: the reward shapes are unknown.")]
    path = figures.reward_shapes_figure(rewards[0], out_dir / f"{a.case}_reward_shapes.png")
    caption = (
        "Adversarial reward R = α_A·R_A as a function of the distance headway h, as configured "
        "in the runs' config.yaml (same-lane shape; the lane-change shape applies to cut-in)."
    )
    if any(r != rewards[0] for r in rewards[1:]):
        caption += (
            " Caution: the runs of this case do not all use the same reward; shown: the first."
        )
    return [*blocks, FigureBlock(path, caption)]


def learning_blocks(
    a: CaseAnalysis[RunRecord], colors: Mapping[str, str], out_dir: Path
) -> list[Block]:
    path = figures.learning_curves_figure(
        a.runs,
        colors,
        out_dir / f"{a.case}_learning_curves.png",
        title=f"{a.info.title}: learning curves (evaluation on the fixed scenarios)",
    )
    rows = []
    for vut, members in a.runs.items():
        for run in members:
            n_cand = str(len(run.eval_curve)) if run.eval_curve is not None else "—"
            step = f"{run.spcp.step:,}" if run.spcp is not None else "—"
            score = fmt_num(run.spcp.score, 3) if run.spcp is not None else "—"
            crit = run.spcp.criterion if run.spcp is not None and run.spcp.criterion else "—"
            rows.append(
                (
                    vut,
                    str(run.seed),
                    n_cand,
                    step,
                    score,
                    crit,
                    training_status(run.training),
                    display_path(run.path, out_dir),
                )
            )
    table = Table(
        "SPCP selection: the candidate with the best score on the fixed evaluation scenarios",
        ("VUT", "seed", "candidates", "SPCP step", "score", "criterion", "SPCP", "run folder"),
        tuple(rows),
        (False, True, True, True, True, False, False, False),
    )
    caption = (
        "Mean evaluation episode reward of every SPCP candidate vs training steps; one colour "
        "per VUT, one line style per seed; the star marks the selected SPCP."
    )
    return [Heading("(b) Learning curves and SPCP selection", 3), FigureBlock(path, caption), table]


def indicator_blocks(
    a: CaseAnalysis[RunRecord], colors: Mapping[str, str], out_dir: Path, options: ReportOptions
) -> list[Block]:
    info = a.info
    edges = options.figure_edges
    path = figures.indicator_figure(
        a.runs,
        colors,
        out_dir / f"{a.case}_indicator_vs_headway.png",
        edges=edges,
        axis_label=info.axis_label,
        level=options.level,
        title=f"{info.title}: {info.symbol} of the AYSS vs headway (paper {info.paper_figure})",
    )
    caption = (
        f"Mean {info.symbol} of the adversarial-yet-safe states (AYSS) per "
        f"{options.bin_width_m:g} m headway bin. More negative = a more aggressive SPCP = a "
        "safer VUT. Left (read this one): per VUT the mean of its seeds' bin means, with "
        f"the band between seeds that the verdict rests on ({100 * options.level:g} % "
        "t-interval over three or more seeds; with two seeds the range between them), and "
        "each seed's SPCP as a thin line. Right: all samples pooled over seeds with a "
        "Student t interval per bin; it ignores the seed-to-seed spread, so its band is "
        "narrower than the evidence. Bottom: samples per bin and per SPCP; bins with fewer "
        "than two samples of a seed are not drawn."
    )
    rows = []
    for vut, members in a.runs.items():
        for run in members:
            if run.ayss is None and run.ayss_bins is None:
                rows.append((vut, str(run.seed), "missing", "—", "—"))
                continue
            if run.ayss is not None:
                h, y = run.ayss.h, run.ayss.indicator
                inside = (h >= 0) & (h <= options.h_max_m)
                n_in, mean = (
                    int(inside.sum()),
                    float(np.mean(y[inside])) if inside.any() else math.nan,
                )
                n_all = len(run.ayss)
            else:  # ayss_bins.csv only (ayss.csv is not committed)
                cells = run.ayss_bins
                assert cells is not None
                n_in, mean = inside_moments(cells, 0.0, options.h_max_m)
                n_all = len(cells)
            rows.append((vut, str(run.seed), str(n_all), str(n_in), fmt_num(mean)))
    table = Table(
        "AYSS samples per SPCP",
        ("VUT", "seed", "samples", f"with h ≤ {options.h_max_m:g} m", f"mean {info.symbol}"),
        tuple(rows),
        (False, True, True, True, True),
    )
    heading = f"(c) Aggressiveness vs headway ({info.paper_figure} equivalent)"
    return [Heading(heading, 3), FigureBlock(path, caption), table]
