"""Report stage: figures, tables and verdicts from run folders, as HTML and Markdown.

    python -m sumo_ayss.report runs/ --out runs/report

From a pipeline::

    from sumo_ayss.report import write_report

    html_path = write_report([Path("runs")], Path("runs/report"))

Imports neither SUMO nor torch (the reward-shape figure loads :mod:`sumo_ayss.plots` lazily).
"""

from __future__ import annotations

from sumo_ayss.report.document import (
    DEFAULT_TITLE,
    HTML_NAME,
    MARKDOWN_NAME,
    PairVerdict,
    Report,
    ReportOptions,
    analyse_case,
    build_report,
    pair_verdict,
    render_html,
    render_markdown,
    significance_rule,
    vut_safety_index,
    write_report,
)
from sumo_ayss.report.load import (
    AYSS_COLUMNS,
    OUTCOME_KEYS,
    RUN_FILES,
    Run,
    find_run_dirs,
    group_runs,
    load_run,
)

__all__ = [
    "AYSS_COLUMNS",
    "DEFAULT_TITLE",
    "HTML_NAME",
    "MARKDOWN_NAME",
    "OUTCOME_KEYS",
    "RUN_FILES",
    "PairVerdict",
    "Report",
    "ReportOptions",
    "Run",
    "analyse_case",
    "build_report",
    "find_run_dirs",
    "group_runs",
    "load_run",
    "pair_verdict",
    "render_html",
    "render_markdown",
    "significance_rule",
    "vut_safety_index",
    "write_report",
]
