"""HTML and Markdown renderings of a :class:`~.blocks.Report`.

* :func:`render_html` — one self-contained file: figures embedded as base64 PNG, inline CSS,
  no JavaScript, no network; it opens offline.
* :func:`render_markdown` — the same blocks, figures linked by relative path.

Both carry :data:`RENDERER_VERSION` (``summary.md`` as a comment under the title, the HTML as
a ``generator`` meta tag), so a committed report can be checked to be the current renderer's
(``tests/report/test_committed_reports.py``).
"""

from __future__ import annotations

import base64
import html
from pathlib import Path

from sumo_ayss.report.blocks import (
    Block,
    Callout,
    FigureBlock,
    Heading,
    Paragraph,
    Report,
    Table,
)

__all__ = ["RENDERER_VERSION", "render_html", "render_markdown", "renderer_stamp"]

RENDERER_VERSION = 4
"""The report's renderer version. Bump it whenever what a report says or shows changes (a
statistic, a table, a sentence), then regenerate the committed reports
(``scripts/regenerate_reports.sh``): a test fails while a committed ``summary.md`` carries
another version. 1: every report before issue 35 (unstamped); 2: issue 35 (family-wise
claims, paired margins, one banner); 3: issue 33 session 10 (the revised unjustified-braking
rule in the caption, the callout on OVER-BRAKING and cases that disagree)."""


def renderer_stamp() -> str:
    """The stamp line of ``summary.md``: ``<!-- sumo_ayss report renderer 2 -->``."""
    return f"<!-- sumo_ayss report renderer {RENDERER_VERSION} -->"


_CSS = """
:root { --ink:#1d2433; --muted:#5b6474; --line:#d9dee7; --bg:#f6f8fb; --accent:#2457a6; }
* { box-sizing: border-box; }
body { margin:0; background:var(--bg); color:var(--ink);
  font: 15px/1.5 "DejaVu Sans", "Segoe UI", Helvetica, Arial, sans-serif; }
main { max-width: 1240px; margin: 0 auto; padding: 24px 28px 60px; background:#fff;
  box-shadow: 0 0 0 1px var(--line); }
h1 { font-size: 26px; margin: 8px 0 4px; }
h2 { font-size: 21px; margin: 40px 0 12px; padding-bottom: 6px;
  border-bottom: 2px solid var(--accent); }
h3 { font-size: 17px; margin: 28px 0 8px; color: var(--accent); }
p.sub { color: var(--muted); margin: 0 0 16px; }
nav { font-size: 14px; margin: 8px 0 20px; }
nav a { margin-right: 16px; color: var(--accent); }
.callout { border-left: 6px solid #8a94a6; background:#f2f4f8; padding: 12px 16px;
  margin: 12px 0; border-radius: 4px; }
.callout .t { font-weight: 700; font-size: 13px; text-transform: uppercase;
  letter-spacing: .04em; color: var(--muted); margin-bottom: 4px; }
.callout p { margin: 4px 0; }
.callout.safer { border-color:#1f8a4c; background:#eaf7ef; }
.callout.safer p:first-of-type, .callout.none p:first-of-type { font-size: 17px; font-weight: 600; }
.callout.none { border-color:#6c7a92; background:#eef1f6; }
.callout.warning { border-color:#d08a00; background:#fff6e0; }
.callout.warning p { font-size: 14px; margin: 2px 0; }
figure { margin: 12px 0 18px; }
figure img { display:block; max-width:100%; height:auto; border:1px solid var(--line); }
figcaption { color: var(--muted); font-size: 13.5px; margin-top: 6px; }
div.table { overflow-x: auto; margin: 14px 0 10px; }
table { border-collapse: collapse; margin: 0 0 4px; font-size: 13.5px; }
p.tcap { font-weight: 600; margin: 0 0 6px; }
details { margin: 8px 0; font-size: 14px; }
summary { cursor: pointer; color: var(--accent); }
th, td { border: 1px solid var(--line); padding: 4px 9px; vertical-align: top; }
th { background: #eef2f8; text-align: left; }
td.n { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
tbody tr:nth-child(even) { background: #fafbfd; }
.note { color: var(--muted); font-size: 13px; margin: 2px 0 14px; max-width: 1100px; }
ul.plain { font-size: 14px; }
code, .path { font-family: "DejaVu Sans Mono", Consolas, monospace; font-size: 12.5px; }
"""


def _e(text: str) -> str:
    return html.escape(text, quote=True)


def _html_block(block: Block) -> str:
    if isinstance(block, Heading):
        tag = f"h{min(max(block.level, 1), 6)}"
        anchor = f' id="{_e(block.anchor)}"' if block.anchor else ""
        return f"<{tag}{anchor}>{_e(block.text)}</{tag}>"
    if isinstance(block, Paragraph):
        return f"<p>{_e(block.text)}</p>"
    if isinstance(block, Callout):
        body = "".join(f"<p>{_e(line)}</p>" for line in block.lines)
        return (
            f'<div class="callout {block.kind}"><div class="t">{_e(block.title)}</div>{body}</div>'
        )
    if isinstance(block, FigureBlock):
        data = base64.b64encode(block.path.read_bytes()).decode("ascii")
        return (
            f'<figure><img alt="{_e(block.caption)}" src="data:image/png;base64,{data}">'
            f"<figcaption>{_e(block.caption)}</figcaption></figure>"
        )
    if isinstance(block, Table):
        return _html_table(block)
    items = '<ul class="plain">' + "".join(f"<li>{_e(i)}</li>" for i in block.items) + "</ul>"
    if block.summary:
        return f"<details><summary>{_e(block.summary)}</summary>{items}</details>"
    return items


def _html_table(t: Table) -> str:
    numeric = t.numeric or (False,) * len(t.headers)
    head = "".join(f"<th>{_e(h)}</th>" for h in t.headers)
    body = []
    for row in t.rows:
        cells = "".join(
            f'<td class="n">{_e(c)}</td>' if numeric[i] else f"<td>{_e(c)}</td>"
            for i, c in enumerate(row)
        )
        body.append(f"<tr>{cells}</tr>")
    note = f'<p class="note">{_e(t.note)}</p>' if t.note else ""
    return (
        f'<div class="table"><p class="tcap">{_e(t.caption)}</p><table><thead><tr>{head}</tr>'
        f"</thead><tbody>{''.join(body)}</tbody></table>{note}</div>"
    )


def render_html(report: Report) -> str:
    """The report as one self-contained HTML document (inline CSS and images, no script).

    Args:
        report: The report.

    Returns:
        The HTML text.
    """
    anchors = [b for b in report.blocks if isinstance(b, Heading) and b.anchor]
    nav = " ".join(f'<a href="#{_e(b.anchor)}">{_e(b.text)}</a>' for b in anchors)
    body = "\n".join(_html_block(b) for b in report.blocks)
    return (
        "<!DOCTYPE html>\n"
        '<html lang="en"><head><meta charset="utf-8">'
        '<meta name="viewport" content="width=device-width, initial-scale=1">'
        f'<meta name="generator" content="sumo_ayss report renderer {RENDERER_VERSION}">'
        f"<title>{_e(report.title)}</title><style>{_CSS}</style></head>\n"
        f"<body><main><h1>{_e(report.title)}</h1>"
        f'<p class="sub">{_e(report.subtitle)}</p><nav>{nav}</nav>\n{body}\n'
        "</main></body></html>\n"
    )


# --------------------------------------------------------------------------- Markdown


def _md_cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def _md_block(block: Block, base: Path) -> str:
    if isinstance(block, Heading):
        return f"{'#' * min(max(block.level, 1), 6)} {block.text}"
    if isinstance(block, Paragraph):
        return block.text
    if isinstance(block, Callout):
        lines = [f"> **{block.title}**", ">"]
        for i, line in enumerate(block.lines):
            strong = i == 0 and block.kind in ("safer", "none")
            lines += [f"> **{line}**" if strong else f"> {line}", ">"]
        return "\n".join(lines[:-1])
    if isinstance(block, FigureBlock):
        try:
            rel = block.path.relative_to(base).as_posix()
        except ValueError:
            rel = block.path.as_posix()
        return f"![{_md_cell(block.caption)}]({rel})\n\n*{block.caption}*"
    if isinstance(block, Table):
        numeric = block.numeric or (False,) * len(block.headers)
        out = [f"**{block.caption}**", ""]
        out.append("| " + " | ".join(_md_cell(h) for h in block.headers) + " |")
        out.append("|" + "|".join("---:" if n else "---" for n in numeric) + "|")
        out += ["| " + " | ".join(_md_cell(c) for c in row) + " |" for row in block.rows]
        if block.note:
            out += ["", f"*{block.note}*"]
        return "\n".join(out)
    items = "\n".join(f"- {item}" for item in block.items)
    return f"{block.summary}:\n\n{items}" if block.summary else items


def render_markdown(report: Report, base: Path) -> str:
    """The report as Markdown; figures are linked relative to ``base`` (the output folder).

    Args:
        report: The report.
        base: Folder the Markdown file is written to.

    Returns:
        The Markdown text.
    """
    parts = [f"# {report.title}\n{renderer_stamp()}", f"*{report.subtitle}*"]
    parts += [_md_block(b, base) for b in report.blocks]
    return "\n\n".join(parts) + "\n"
