"""The report: run folders in, ``report.html`` + ``summary.md`` + PNG figures out.

:func:`write_report` reads run folders (:func:`~sumo_ayss.run_folder.load_runs`, which
checks that they may be pooled), analyses each case
(:func:`~sumo_ayss.modes.analyse_cases`: safety indices, verdicts, exposure and cross-play
rankings, premise) unless its caller hands the analyses in (the pipeline, which passes them
on to rank), composes the sections (:mod:`.sections`) into one list of blocks
(:mod:`.blocks`) and renders it twice
(:mod:`.render`):

* ``report.html`` — one self-contained file: figures embedded as base64 PNG, inline CSS, no
  JavaScript, no network; it opens offline;
* ``summary.md`` — the same tables and verdicts, figures linked by relative path;
* the PNG figures themselves (:mod:`.figures`).

Nothing here computes a number that a verdict rests on: the statistics and the significance
rule (:mod:`sumo_ayss.analysis.significance`) live in :mod:`sumo_ayss.analysis`, which
returns numbers and verdict records; the ranking modes (:mod:`sumo_ayss.modes`) word the
verdicts, and the sections here the rest.
"""

from __future__ import annotations

import datetime as dt
import logging
from collections.abc import Sequence
from pathlib import Path

from sumo_ayss.analysis.case import CaseAnalysis, vut_safety_index
from sumo_ayss.analysis.significance import PairVerdict, pair_verdict
from sumo_ayss.config.report import ReportOptions
from sumo_ayss.modes import analyse_case, analyse_cases, get_mode
from sumo_ayss.modes.paper import significance_rule
from sumo_ayss.report.blocks import (
    Block,
    BulletList,
    Callout,
    FigureBlock,
    Heading,
    Paragraph,
    Report,
    Table,
)
from sumo_ayss.report.figstyle import vut_colors
from sumo_ayss.report.leaderboard import leaderboard_table
from sumo_ayss.report.render import render_html, render_markdown
from sumo_ayss.report.sections.case import case_blocks, verdict_lines
from sumo_ayss.report.sections.hazards import hazard_callout
from sumo_ayss.report.sections.inputs import inputs_blocks
from sumo_ayss.run_folder import RunRecord, case_runs, group_runs, load_runs
from sumo_ayss.training.trust import budget_note, fewest_seeds, trust_warnings

__all__ = [
    "DEFAULT_TITLE",
    "HTML_NAME",
    "MARKDOWN_NAME",
    "BulletList",
    "Callout",
    "CaseAnalysis",
    "FigureBlock",
    "Heading",
    "PairVerdict",
    "Paragraph",
    "Report",
    "ReportOptions",
    "Table",
    "analyse_case",
    "build_report",
    "pair_verdict",
    "render_html",
    "render_markdown",
    "significance_rule",
    "vut_safety_index",
    "write_report",
    "write_report_for",
]

logger = logging.getLogger(__name__)

DEFAULT_TITLE = "Safety ranking of vehicles under test by adversarial-yet-safe scenarios"
HTML_NAME = "report.html"
MARKDOWN_NAME = "summary.md"


def build_report(
    runs: Sequence[RunRecord],
    out_dir: Path,
    *,
    title: str = DEFAULT_TITLE,
    options: ReportOptions | None = None,
    analyses: Sequence[CaseAnalysis[RunRecord]] | None = None,
) -> Report:
    """Computes the statistics, draws the figures into ``out_dir`` and assembles the blocks.

    Args:
        runs: Loaded runs (any cases and VUTs).
        out_dir: Folder for the PNG figures (created).
        title: Report title.
        options: Statistical settings; defaults if None.
        analyses: The analyses of ``runs`` (:func:`~sumo_ayss.modes.analyse_cases` with ``options``
            and the paper mode), when the caller already has them; computed here if None.

    Returns:
        The :class:`Report`.
    """
    options = options or ReportOptions()
    out_dir.mkdir(parents=True, exist_ok=True)
    groups = group_runs(runs)
    colors = vut_colors(sorted({r.vut for r in runs}))
    if analyses is None:
        analyses = analyse_cases(case_runs(runs), options)
    now = dt.datetime.now().astimezone().strftime("%Y-%m-%d %H:%M %Z")
    n_seeds = ", ".join(
        f"{case}: " + ", ".join(f"{vut} × {len(m)}" for vut, m in by_vut.items())
        for case, by_vut in groups.items()
    )
    budgets = sorted({r.training.total_timesteps or 0 for r in runs})
    budget = ", ".join(f"{b:,}" if b else "unknown" for b in budgets)
    subtitle = (
        f"Generated {now} from {len(runs)} run folder{'' if len(runs) == 1 else 's'} "
        f"({n_seeds or 'none'}); training budget "
        f"{budget or 'none'} transitions per run."
    )
    blocks: list[Block] = []
    warnings = trust_warnings(
        [(f"{r.case} {r.label}", r.training) for r in runs],
        fewest_seeds((r.case, r.vut) for r in runs),
    )
    if warnings:
        blocks.append(Callout("Read the verdicts with care", tuple(warnings), "warning"))
    elif (
        note := budget_note(
            [(f"{r.case} {r.label}", r.training) for r in runs],
            fewest_seeds((r.case, r.vut) for r in runs),
        )
    ) is not None:
        blocks.append(Callout("What this budget's evidence covers", (note,), "info"))
    tables = [t for t in (leaderboard_table(a, options.level) for a in analyses) if t]
    if tables:
        blocks.append(Heading("Leaderboard", 2, "leaderboard"))
        blocks += tables
        if (callout := hazard_callout(analyses)) is not None:
            blocks.append(callout)
    blocks.append(Heading("Verdicts", 2, "verdicts"))
    if not analyses:
        blocks.append(Callout("No runs", ("No run folder was found.",), "warning"))
    for a in analyses:
        blocks.append(Callout(a.info.title, verdict_lines(a, options), a.verdict.kind))
    blocks.append(Paragraph(modes_paragraph(analyses, options.mode)))
    blocks.append(Paragraph(significance_rule(options)))
    blocks.append(
        Paragraph(
            "How to read this report: against each VUT an adversarial-yet-safe opponent (POV) "
            "was trained with the same reward; its best checkpoint is the VUT's SPCP. Exposure "
            "mode ranks VUTs by the harm their SPCPs bring about (sections d and f): a "
            "collision counts as the worst episode, otherwise the near-miss reward paid, so "
            "less means fewer collisions and fewer, less close near-misses. Cross-play "
            "mode (section i) lets every SPCP of a case drive against every VUT and ranks the "
            "VUTs by the harm the pooled SPCPs bring about, so one SPCP's search noise "
            "cancels. The paper's reading (sections c and g) assumes that all SPCPs reached "
            "the same overall outcome (checked in section e) and then reveals a safer VUT by "
            "a more aggressive SPCP: harder braking (car-following) or a smaller Δv̄ (cut-in) "
            "at the same headway."
        )
    )
    blocks += inputs_blocks(runs, groups, out_dir)
    for a in analyses:
        blocks += case_blocks(a, colors, out_dir, options)
    return Report(title, subtitle, tuple(blocks))


def modes_paragraph(analyses: Sequence[CaseAnalysis[RunRecord]], mode: str) -> str:
    """Which mode the verdicts above are in, as it happened: the mode asked for, the one a
    case fell back to, or that no case had a verdict (fewer than two VUTs)."""
    with_verdict = [a for a in analyses if len(a.runs) >= 2]
    if not with_verdict:
        return (
            "No verdict: every case of this report has fewer than two VUTs, and a verdict "
            f"compares two. Mode asked for: {mode}."
        )
    used = list(dict.fromkeys(a.ranking_mode for a in with_verdict))
    text = " ".join(get_mode(m).description for m in used)
    if used == [mode]:
        return f"Verdicts above are in {mode} mode. {text}"
    fell_back = ", ".join(a.case for a in with_verdict if a.ranking_mode != mode)
    return (
        f"Verdicts above: {mode} mode was asked for; {fell_back} fell back to "
        f"{' / '.join(m for m in used if m != mode)} mode (the verdict says why). {text}"
    )


def write_report(
    paths: Sequence[str | Path],
    out_dir: str | Path | None = None,
    *,
    title: str = DEFAULT_TITLE,
    options: ReportOptions | None = None,
) -> Path:
    """Reads run folders and writes ``report.html``, ``summary.md`` and the PNGs.

    Args:
        paths: Run folders ``<out>/<case>/<vut>/seed_<k>`` and/or roots to search.
        out_dir: Output folder; default ``<first path>/report``.
        title: Report title.
        options: Statistical settings; defaults if None.

    Returns:
        The path of ``report.html``.

    Raises:
        ConfigError: As :func:`~sumo_ayss.run_folder.load_runs`.
    """
    runs = load_runs(paths)
    target = Path(out_dir) if out_dir is not None else Path(paths[0]) / "report"
    return write_report_for(runs, target, title=title, options=options)


def write_report_for(
    runs: Sequence[RunRecord],
    out_dir: Path,
    *,
    analyses: Sequence[CaseAnalysis[RunRecord]] | None = None,
    title: str = DEFAULT_TITLE,
    options: ReportOptions | None = None,
) -> Path:
    """Writes ``report.html``, ``summary.md`` and the PNGs of loaded runs into ``out_dir``.

    Args:
        runs: Loaded runs (:func:`~sumo_ayss.run_folder.load_runs`).
        out_dir: Output folder.
        analyses: Their analyses, when the caller has them (see :func:`build_report`).
        title: Report title.
        options: Statistical settings; defaults if None.

    Returns:
        The path of ``report.html``.
    """
    for warning in trust_warnings(
        [(f"{r.case} {r.label}", r.training) for r in runs],
        fewest_seeds((r.case, r.vut) for r in runs),
    ):
        logger.warning("%s", warning)
    report = build_report(runs, out_dir, title=title, options=options, analyses=analyses)
    html_path = out_dir / HTML_NAME
    from sumo_ayss.util.atomic import atomic_write_text

    atomic_write_text(html_path, render_html(report))
    atomic_write_text(out_dir / MARKDOWN_NAME, render_markdown(report, out_dir))
    logger.info("report written to %s", html_path)
    return html_path
