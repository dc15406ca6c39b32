"""The look shared by every report figure: colours per VUT, seed styles, rc settings, PNG output."""

from __future__ import annotations

import textwrap
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

import matplotlib as mpl
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.text import Text

__all__ = [
    "DPI",
    "LINESTYLES",
    "MANY_VUTS",
    "MAX_WIDTH_IN",
    "no_data",
    "save",
    "seed_style",
    "set_wrapped_title",
    "style",
    "vut_colors",
]

#: Above this many VUTs a figure with one x position per VUT is a leaderboard: its width is
#: capped at :data:`MAX_WIDTH_IN` [in], its VUT labels rotated, and a legend with one entry
#: per opponent left out (the caption says how lines are coloured and styled).
MANY_VUTS = 8
MAX_WIDTH_IN = 16.0

DPI = 100
"""Resolution of every PNG: 100 dpi makes a 11-inch-wide figure 1100 px, i.e. 100 % zoom."""

#: VUT colours in order of first use: the paper draws π1 green and π2 orange.
_PALETTE = (
    "#2ca02c",
    "#ff7f0e",
    "#1f77b4",
    "#d62728",
    "#9467bd",
    "#8c564b",
    "#e377c2",
    "#17becf",
    "#bcbd22",
    "#7f7f7f",
)
LINESTYLES = ("-", "--", ":", "-.")
_MARKERS = ("o", "s", "^", "D", "v", "P", "X")


def vut_colors(vuts: Sequence[str]) -> dict[str, str]:
    """One colour per VUT, in the order given (the report passes all VUTs sorted).

    Args:
        vuts: VUT names; duplicates keep their first colour.

    Returns:
        ``{vut: hex colour}``; the palette repeats after ten VUTs.
    """
    colors: dict[str, str] = {}
    for vut in vuts:
        if vut not in colors:
            colors[vut] = _PALETTE[len(colors) % len(_PALETTE)]
    return colors


def seed_style(position: int) -> tuple[str, str]:
    """``(linestyle, marker)`` of the ``position``-th seed of a VUT (0-based)."""
    return LINESTYLES[position % len(LINESTYLES)], _MARKERS[position % len(_MARKERS)]


@contextmanager
def style() -> Iterator[None]:
    """Readable defaults for every report figure."""
    with mpl.rc_context(
        {
            "font.size": 10,
            "axes.titlesize": 11,
            "axes.titleweight": "bold",
            "axes.labelsize": 10,
            "legend.fontsize": 8.5,
            "axes.grid": True,
            "grid.alpha": 0.3,
            "axes.spines.top": False,
            "axes.spines.right": False,
            "figure.facecolor": "white",
            "savefig.facecolor": "white",
        }
    ):
        yield


def save(fig: Figure, path: Path) -> Path:
    from sumo_ayss.util.atomic import atomic_write_with

    # A bare Figure renders PNG with Agg; no pyplot state. Atomic: a reader never sees half.
    atomic_write_with(path, lambda tmp: fig.savefig(tmp, dpi=DPI))
    return path


def no_data(ax: Axes, text: str) -> None:
    ax.text(0.5, 0.5, text, ha="center", va="center", transform=ax.transAxes, color="0.4")


#: Width of an average bold title character, as a fraction of the font size: DejaVu Sans
#: Bold runs at about 0.62 em per character in mixed text; 0.7 leaves a margin.
_TITLE_EM_PER_CHAR = 0.7


def set_wrapped_title(ax: Axes, title: str, width_in: float) -> Text:
    """Sets ``ax``'s title, wrapped onto as many lines as a figure ``width_in`` inches
    wide needs (a long title on a narrow figure was cut off at both ends).

    Args:
        ax: The axes.
        title: The title.
        width_in: Width the title may take [in] (the figure's width, for a single axes).

    Returns:
        The title's Text.
    """
    size_pt = (
        float(mpl.rcParams["axes.titlesize"])
        if isinstance(mpl.rcParams["axes.titlesize"], (int, float))
        else 11.0
    )
    chars = max(20, int(width_in * 72.0 / (_TITLE_EM_PER_CHAR * size_pt)))
    return ax.set_title(textwrap.fill(title, chars))
