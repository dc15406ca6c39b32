"""Cross-play figure: the harm each opponent SPCP brings about against every VUT."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import NDArray

from sumo_ayss.report.figstyle import (
    MANY_VUTS,
    MAX_WIDTH_IN,
    save,
    seed_style,
    set_wrapped_title,
    style,
)


def crossplay_lines(
    order: Sequence[str], harm: NDArray[np.float64], vuts: Sequence[str]
) -> NDArray[np.float64]:
    """The lines :func:`crossplay_figure` draws: ``lines[j, x]`` = the harm opponent j
    brings about against ``order[x]`` (x = 0 the safest VUT, drawn leftmost).

    Args:
        order: VUTs safest first.
        harm: ``harm[i, j]`` against VUT ``vuts[i]`` by opponent j.
        vuts: The VUTs of the rows of ``harm``.
    """
    rows = [list(vuts).index(v) for v in order]
    return np.asarray(harm, dtype=np.float64)[rows, :].T


def crossplay_figure(
    order: Sequence[str],
    opponents: Sequence[tuple[str, int]],
    harm: NDArray[np.float64],
    vuts: Sequence[str],
    colors: Mapping[str, str],
    path: Path,
    *,
    title: str,
) -> Path:
    """Cross-play: one line per opponent SPCP across the VUTs, in ranking order.

    Args:
        order: VUTs safest first (the x axis).
        opponents: ``(trained-against VUT, training seed)`` of each opponent (columns of
            ``harm``).
        harm: ``harm[i, j]`` = mean harm per episode opponent j brings about against VUT
            ``vuts[i]`` (:mod:`sumo_ayss.analysis.harm`).
        vuts: The VUTs of the rows of ``harm``.
        colors: ``{vut: colour}``; an opponent is drawn in its trained-against VUT's colour,
            one line style per seed.
        path: PNG file to write.
        title: Figure title.

    Returns:
        ``path``.
    """
    lines = crossplay_lines(order, harm, vuts)
    seeds = sorted({s for _, s in opponents})
    many = len(order) > MANY_VUTS  # a leaderboard: bounded width, no per-opponent legend
    width = min(5.0 + 1.6 * max(1, len(order)), MAX_WIDTH_IN)
    with style():
        fig = Figure(figsize=(width, 4.6 + (1.2 if many else 0.0)), layout="constrained")
        ax = fig.subplots()
        for j, (vut, seed) in enumerate(opponents):
            ls, marker = seed_style(seeds.index(seed))
            ax.plot(
                range(len(order)),
                lines[j],
                color=colors.get(vut, "C0"),
                ls=ls,
                marker=marker,
                ms=5,
                lw=1.4,
                label=f"SPCP of {vut}, seed {seed}",
            )
        labels = [f"#{k + 1} {v}" for k, v in enumerate(order)]
        ax.set_xticks(
            range(len(order)),
            labels,
            rotation=60 if many else 0,
            ha="right" if many else "center",
            fontsize=7 if many else None,
        )
        ax.set_xlim(-0.4, len(order) - 0.6 + 0.2)
        ax.set_xlabel("VUT driven against, safest first (cross-play ranking)")
        ax.set_ylabel("harm per episode (1 = collision)")
        set_wrapped_title(ax, title, width)
        ax.grid(axis="y", alpha=0.3)
        if not many:  # with many opponents a legend would be longer than the plot
            ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))
        return save(fig, path)
