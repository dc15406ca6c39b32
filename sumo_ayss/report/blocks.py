"""The report's document model: a list of blocks that HTML and Markdown both render.

:class:`Heading`, :class:`Paragraph`, :class:`Callout`, :class:`FigureBlock`, :class:`Table`
and :class:`BulletList` hold plain text only (no markup), so the two renderings
(:mod:`.render`) cannot disagree.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Literal

__all__ = [
    "Block",
    "BulletList",
    "Callout",
    "FigureBlock",
    "Heading",
    "Paragraph",
    "Report",
    "Table",
]


@dataclass(frozen=True)
class Heading:
    """A section heading; ``anchor`` is its in-page id."""

    text: str
    level: int = 2
    anchor: str = ""


@dataclass(frozen=True)
class Paragraph:
    """Plain text (no markup)."""

    text: str


@dataclass(frozen=True)
class Callout:
    """A highlighted box: a verdict (``safer`` / ``none``), a ``warning`` or ``info``."""

    title: str
    lines: tuple[str, ...]
    kind: Literal["safer", "none", "warning", "info"] = "info"


@dataclass(frozen=True)
class FigureBlock:
    """A PNG figure with its caption."""

    path: Path
    caption: str


@dataclass(frozen=True)
class Table:
    """A table of plain-text cells; ``numeric`` marks right-aligned columns."""

    caption: str
    headers: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    numeric: tuple[bool, ...] = ()
    note: str = ""


@dataclass(frozen=True)
class BulletList:
    """A bulleted list of plain-text items; with a ``summary`` HTML folds it (no script)."""

    items: tuple[str, ...]
    summary: str = ""


Block = Heading | Paragraph | Callout | FigureBlock | Table | BulletList


@dataclass(frozen=True)
class Report:
    """A whole report: title, a subtitle line and the blocks, in order."""

    title: str
    subtitle: str
    blocks: tuple[Block, ...]
