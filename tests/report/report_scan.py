"""Reading a generated ``summary.md`` back: its tables, and every interval in them against
what its quantity can take (shared by the report tests and the committed-reports test)."""

from __future__ import annotations

import re

NUM = r"[−-]?\d+(?:\.\d+)?"
INTERVAL = re.compile(rf"\(({NUM}) ?%?(?:–| to )({NUM}) ?%?\)")


def tables(md: str) -> list[tuple[str, list[str], list[list[str]]]]:
    """``(caption, header, rows)`` of every Markdown table (caption: the bold line above)."""
    out = []
    lines = md.splitlines()
    i = 0
    while i < len(lines):
        if lines[i].startswith("|") and i + 1 < len(lines) and lines[i + 1].startswith("|---"):
            caption = next(
                (lines[j] for j in range(i - 1, max(i - 4, -1), -1) if lines[j].startswith("**")),
                "",
            )
            header = [c.strip() for c in lines[i].strip("|").split(" | ")]
            rows = []
            i += 2
            while i < len(lines) and lines[i].startswith("|"):
                rows.append([c.strip() for c in lines[i].strip("|").split(" | ")])
                i += 1
            out.append((caption, header, rows))
        else:
            i += 1
    return out


def value(text: str) -> float:
    return float(text.replace("−", "-"))


def bounds(header: str, row_label: str) -> tuple[float, float] | None:
    """What the column's (or, in the premise table, the row's) quantity can take."""
    h = header.lower()
    if "crash rate" in h or row_label.startswith("crash rate"):
        return 0.0, 100.0
    if "−" in header and ("harm" in h or re.search(r"\bH_", header)):
        return -1.0, 1.0  # a difference of two harms in [0, 1]
    if "margin" in h:
        return -1.0, 1.0  # the leaderboard's margin: a difference of harms here
    if "harm" in h or re.match(r"H \(", header):
        return 0.0, 1.0
    # (a final headway can be negative: in cut-in the POV may end behind the VUT)
    return None


def seed_level(header: str, caption: str) -> bool:
    """Whether a column's intervals are over training seeds (none with two)."""
    h = header.lower()
    return (
        (
            ("harm" in h or bool(re.match(r"H \(", header)) or "margin" in h or "index" in h)
            and "crash" not in h
        )
        or "premise" in caption.lower()
        or "outcome of the spcps per vut" in caption.lower()
    )


def impossible_intervals(md: str) -> list[str]:
    """Every table cell whose interval is reversed or leaves its quantity's range
    (:func:`bounds`), as ``"caption / column: cell"``."""
    bad = []
    for caption, header, rows in tables(md):
        for row in rows:
            for col, cell in zip(header, row, strict=False):
                for lo, hi in INTERVAL.findall(cell):
                    lo_v, hi_v = value(lo), value(hi)
                    b = bounds(col, row[0])
                    if lo_v > hi_v or (b is not None and not (b[0] <= lo_v and hi_v <= b[1])):
                        bad.append(f"{caption} / {col}: {cell}")
    return bad
