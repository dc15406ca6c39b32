"""Report stage: figures, tables and verdicts from run folders, as HTML and Markdown.

    python -m sumo_ayss.report runs/ --out runs/report

From a pipeline::

    from sumo_ayss.report import write_report

    html_path = write_report([Path("runs")], Path("runs/report"))

Imports neither SUMO nor torch. The statistics live in :mod:`sumo_ayss.analysis`
(:mod:`sumo_ayss.analysis.case`); this package composes sections and renders them.
"""

from __future__ import annotations

import importlib
from typing import Any

_LAZY = {
    "DEFAULT_TITLE": "sumo_ayss.report.document",
    "HTML_NAME": "sumo_ayss.report.document",
    "MARKDOWN_NAME": "sumo_ayss.report.document",
    "PairVerdict": "sumo_ayss.analysis.significance",
    "Report": "sumo_ayss.report.document",
    "analyse_case": "sumo_ayss.modes",
    "build_report": "sumo_ayss.report.document",
    "load_runs": "sumo_ayss.run_folder",
    "pair_verdict": "sumo_ayss.analysis.significance",
    "render_html": "sumo_ayss.report.render",
    "render_markdown": "sumo_ayss.report.render",
    "significance_rule": "sumo_ayss.modes.paper",
    "vut_safety_index": "sumo_ayss.analysis.case",
    "write_report": "sumo_ayss.report.document",
    "write_report_for": "sumo_ayss.report.document",
    "group_runs": "sumo_ayss.run_folder",
    "case_runs": "sumo_ayss.run_folder",
    "analyse_cases": "sumo_ayss.modes",
    "ReportOptions": "sumo_ayss.config.report",
}
"""Public names and their modules, imported on first use: importing the package loads
neither matplotlib nor the document."""

__all__ = sorted(_LAZY)


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
