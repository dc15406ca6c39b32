"""Every committed report is the current renderer's, and none prints an impossible interval
(issue 35: 18 committed summaries still showed crash-rate intervals outside [0, 100] %)."""

from __future__ import annotations

from pathlib import Path

import pytest

from sumo_ayss.config import PROJECT_ROOT
from sumo_ayss.report.render import RENDERER_VERSION, renderer_stamp
from tests.report.report_scan import impossible_intervals

COMMITTED = sorted((PROJECT_ROOT / "results").glob("**/report/summary.md"))


def test_there_are_committed_reports() -> None:
    assert len(COMMITTED) >= 10


@pytest.mark.parametrize("path", COMMITTED, ids=lambda p: str(p.relative_to(PROJECT_ROOT)))
def test_committed_report_is_the_current_renderers(path: Path) -> None:
    md = path.read_text(encoding="utf-8")
    assert md.splitlines()[1] == renderer_stamp(), (
        f"{path} was not written by renderer {RENDERER_VERSION}: run scripts/regenerate_reports.sh"
    )
    html = (path.parent / "report.html").read_text(encoding="utf-8")
    assert f'content="sumo_ayss report renderer {RENDERER_VERSION}"' in html
    assert not impossible_intervals(md), impossible_intervals(md)[:5]


def test_the_stamp_is_written(tmp_path: Path) -> None:
    from sumo_ayss.report.blocks import Paragraph, Report
    from sumo_ayss.report.render import render_html, render_markdown

    report = Report("t", "s", (Paragraph("x"),))
    assert render_markdown(report, tmp_path).splitlines()[1] == renderer_stamp()
    assert f"renderer {RENDERER_VERSION}" in render_html(report)
