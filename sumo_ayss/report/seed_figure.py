"""Per-seed score figure of a seed-level ranking (exposure): seeds joined across VUTs."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path

from matplotlib.figure import Figure

from sumo_ayss.analysis.seeds import SeedRankRow
from sumo_ayss.report.figstyle import MANY_VUTS, MAX_WIDTH_IN, save, set_wrapped_title, style

__all__ = ["seed_scores_figure"]


def seed_scores_figure(
    rows: Sequence[SeedRankRow],
    scores: Mapping[str, Mapping[int, float]],
    colors: Mapping[str, str],
    path: Path,
    *,
    ylabel: str,
    title: str,
) -> Path:
    """Per-seed scores of every VUT, seeds joined across VUTs, with the seed mean and CI.

    VUTs are drawn left to right from the safest (rank 1) to the least safe. Each training
    seed is one grey line through its VUTs' scores: parallel lines show that seeds move all
    VUTs together (a block effect that the paired comparison removes).

    Args:
        rows: The seed-level ranking, safest first.
        scores: ``{vut: {seed: score}}``.
        colors: ``{vut: colour}``.
        path: PNG file to write.
        ylabel: Axis label of the score, with unit.
        title: Figure title.

    Returns:
        ``path``.
    """
    names = [r.name for r in rows]
    seeds = sorted({s for v in names for s in scores[v]})
    with style():
        many = len(names) > MANY_VUTS  # a leaderboard: bounded width, rotated labels
        width = min(2.2 + 1.6 * max(1, len(names)), MAX_WIDTH_IN)
        fig = Figure(figsize=(width, 4.6 + (1.2 if many else 0.0)), layout="constrained")
        ax = fig.subplots()
        for seed in seeds:
            xs = [i for i, v in enumerate(names) if seed in scores[v]]
            ys = [scores[names[i]][seed] for i in xs]
            ax.plot(xs, ys, color="0.6", lw=1.0, marker="o", ms=4, zorder=1)
            if xs:
                ax.annotate(
                    f"seed {seed}",
                    xy=(xs[-1], ys[-1]),
                    xytext=(6, 0),
                    textcoords="offset points",
                    va="center",
                    fontsize=8,
                    color="0.45",
                )
        for i, r in enumerate(rows):
            lo = r.mean - r.lo if math.isfinite(r.lo) else 0.0
            hi = r.hi - r.mean if math.isfinite(r.hi) else 0.0
            ax.errorbar(
                i + 0.12,
                r.mean,
                yerr=[[lo], [hi]],
                fmt="D",
                ms=8,
                color=colors.get(r.name, "C0"),
                capsize=5,
                lw=2.0,
                zorder=3,
            )
        ax.set_xticks(
            range(len(names)),
            [f"#{r.rank} {r.name}" for r in rows],
            rotation=60 if many else 0,
            ha="right" if many else "center",
            fontsize=7 if many else None,
        )
        ax.set_xlim(-0.4, len(names) - 0.4)
        ax.set_ylabel(ylabel)
        set_wrapped_title(ax, title, width)
        ax.grid(axis="y", alpha=0.3)
        return save(fig, path)
