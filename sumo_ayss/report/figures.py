"""Report figures: reward shapes, learning curves, indicator vs headway, safety index.

Drawn on bare matplotlib ``Figure`` objects rendered by Agg, so the report never touches
pyplot's global state or backend.

Every function draws one PNG file and returns its path. Colours are per VUT and the same in
every figure of a report (:func:`vut_colors`); seeds are told apart by line style and
marker. The statistics come from :mod:`sumo_ayss.analysis`; nothing here computes a verdict.
This module imports neither SUMO nor torch: the reward shapes come from
:mod:`sumo_ayss.envs.rewards`, which is pure numpy.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import FuncFormatter
from numpy.typing import NDArray

from sumo_ayss.analysis import binned_mean_ci
from sumo_ayss.analysis.ayss_cells import binned_stats_from_cells, run_cells
from sumo_ayss.analysis.ranking import SafetyIndex
from sumo_ayss.analysis.seed_intervals import (
    MIN_SEEDS_FOR_INTERVAL,
    SeedBands,
    binned_seed_means,
    seed_bands,
)
from sumo_ayss.analysis.stats import BinnedStats
from sumo_ayss.cases import case_info
from sumo_ayss.config import RewardConfig
from sumo_ayss.envs.rewards import adversarial_reward_array
from sumo_ayss.report.figstyle import (
    DPI,
    no_data,
    save,
    seed_style,
    style,
    vut_colors,
)
from sumo_ayss.run_folder import RunRecord

__all__ = [
    "DPI",
    "band_kind",
    "has_ayss",
    "indicator_figure",
    "learning_curves_figure",
    "reward_shapes_figure",
    "safety_index_figure",
    "seed_style",
    "vut_colors",
]

# --------------------------------------------------------------------------- reward shapes


def reward_shapes_figure(reward: RewardConfig, path: Path, *, styled: bool = True) -> Path:
    """Draws R = α_A·R_A(h) for the same-lane and the lane-change shapes of ``reward``.

    Args:
        reward: The runs' reward configuration.
        path: PNG file to write.
        styled: In the report's style (:func:`~.figstyle.style`); False: matplotlib's
            defaults (``docs/reward_shapes.png``, ``python -m sumo_ayss.report.reward_shapes``).

    Returns:
        ``path``.
    """
    if not styled:
        return _draw_reward_shapes(reward, path)
    with style():
        return _draw_reward_shapes(reward, path)


def _draw_reward_shapes(cfg: RewardConfig, path: Path) -> Path:
    fig = Figure(figsize=(10, 3.6), constrained_layout=True)
    axes = fig.subplots(1, 2)
    panels = [
        ("same lane (car-following; cut-in after the change)", cfg.same_lane, 25.0),
        ("while changing lanes (cut-in)", cfg.lane_change, 8.0),
    ]
    for ax, (title, shape, h_max) in zip(axes, panels, strict=True):
        h = np.linspace(0.0, h_max, 801)
        r = cfg.alpha_adversarial * adversarial_reward_array(h, shape)
        ax.plot(h, r, color="tab:blue", lw=2, label=f"R = α_A·R_A ({shape.kind})")
        ax.axvline(
            shape.peak_m, color="tab:green", ls="--", lw=1, label=f"peak h = {shape.peak_m} m"
        )
        ax.axvline(
            shape.zero_m, color="tab:gray", ls=":", lw=1, label=f"zero for h ≥ {shape.zero_m} m"
        )
        contact = cfg.alpha_adversarial * shape.value_at_contact
        ax.scatter([0.0], [contact], color="tab:blue", zorder=3, s=12)
        ax.set_title(title)
        ax.set_xlabel("headway h [m]")
        ax.set_ylabel("reward per step")
        ax.set_ylim(-0.05, cfg.alpha_adversarial * 1.05)
        ax.grid(alpha=0.3)
        ax.legend(loc="upper right", fontsize=8)
    fig.suptitle(
        f"Adversarial reward shapes; a collision step gets the minimum {cfg.min_reward:g} "
        "and ends the episode",
        fontsize=10,
    )
    from sumo_ayss.util.atomic import atomic_write_with

    atomic_write_with(path, lambda tmp: fig.savefig(tmp, dpi=120))
    return path


# --------------------------------------------------------------------------- learning curves


def _thousands(x: float, _pos: int) -> str:
    return f"{x / 1000:g}k" if x else "0"


def learning_curves_figure(
    runs_by_vut: Mapping[str, Sequence[RunRecord]],
    colors: Mapping[str, str],
    path: Path,
    *,
    title: str,
) -> Path:
    """Mean evaluation reward (and crash / lane-change rate) vs training steps, per run.

    One colour per VUT, one line style per seed; the selected SPCP is a large star on each
    curve. Panels: mean evaluation episode reward; crash rate in %; and, when any run has
    it, the lane-change rate in %.

    Args:
        runs_by_vut: ``{vut: runs}`` of one case.
        colors: ``{vut: colour}``.
        path: PNG file to write.
        title: Figure title.

    Returns:
        ``path``.
    """
    runs = [r for rs in runs_by_vut.values() for r in rs]
    has_lc = any(
        r.eval_curve is not None and np.isfinite(r.eval_curve["lane_change_rate"]).any()
        for r in runs
        if case_info(r.case).lane_change
    )
    panels: list[tuple[str, str, float]] = [
        ("mean_return", "mean evaluation episode reward", 1.0),
        ("crash_rate", "crash rate [%]", 100.0),
    ]
    if has_lc:
        panels.append(("lane_change_rate", "lane-change rate [%]", 100.0))
    widths = {2: 11.0, 3: 13.0}
    with style():
        fig = Figure(figsize=(widths[len(panels)], 4.4), layout="constrained")
        axes = fig.subplots(
            1,
            len(panels),
            gridspec_kw={"width_ratios": [1.6] + [1.0] * (len(panels) - 1)},
        )
        drawn = False
        for ax, (column, label, scale) in zip(axes, panels, strict=True):
            for vut, members in runs_by_vut.items():
                for pos, run in enumerate(members):
                    drawn |= _draw_curve(ax, run, column, scale, colors[vut], pos)
            ax.set_xlabel("training steps (transitions)")
            ax.set_ylabel(label)
            ax.xaxis.set_major_formatter(FuncFormatter(_thousands))
            if column == "lane_change_rate":
                ax.set_ylim(-2.0, 102.0)
            elif scale == 100.0:
                ax.set_ylim(bottom=-2.0)
        axes[0].set_title("Evaluation reward of every SPCP candidate")
        axes[1].set_title("Crash rate on the evaluation scenarios")
        if has_lc:
            axes[2].set_title("Lane-change rate")
        if not drawn:
            no_data(axes[0], "no eval.csv in these runs yet")
        axes[0].legend(handles=_run_legend(runs_by_vut, colors), loc="best", ncol=2)
        fig.suptitle(title, fontsize=12, fontweight="bold")
        return save(fig, path)


def _draw_curve(ax: Axes, run: RunRecord, column: str, scale: float, color: str, pos: int) -> bool:
    curve = run.eval_curve
    if curve is None or len(curve) == 0:
        return False
    y = curve[column] * scale
    if not np.isfinite(y).any():
        return False
    ls, marker = seed_style(pos)
    ax.plot(curve["step"], y, color=color, ls=ls, lw=1.6, marker=marker, ms=3.5, alpha=0.9)
    if run.spcp is not None:
        hit = np.flatnonzero(curve["step"] == run.spcp.step)
        if hit.size:
            ax.plot(
                curve["step"][hit[0]],
                y[hit[0]],
                marker="*",
                ms=17,
                color=color,
                mec="black",
                mew=1.0,
                ls="none",
                zorder=5,
            )
    return True


def _run_legend(
    runs_by_vut: Mapping[str, Sequence[RunRecord]], colors: Mapping[str, str]
) -> list[Any]:
    handles: list[Any] = []
    for vut, members in runs_by_vut.items():
        for pos, run in enumerate(members):
            ls, marker = seed_style(pos)
            handles.append(
                Line2D([], [], color=colors[vut], ls=ls, marker=marker, ms=4, label=run.label)
            )
    handles.append(
        Line2D(
            [], [], marker="*", ms=13, color="0.6", mec="black", ls="none", label="selected SPCP"
        )
    )
    return handles


# --------------------------------------------------------------------------- indicator vs headway


def has_ayss(run: RunRecord) -> bool:
    """Whether a run has AYSS samples: ``ayss.csv``, else ``ayss_bins.csv``."""
    read = run.ayss if run.ayss is not None else run.ayss_bins
    return read is not None and len(read) > 0


def _vut_bins(
    runs: Sequence[RunRecord], edges: NDArray[np.float64], level: float
) -> tuple[SeedBands, BinnedStats]:
    """The between-seed bands and the pooled per-bin stats of one VUT's runs: from the
    samples, or from every run's per-cell moments when one has only ``ayss_bins.csv``."""
    samples = [r.ayss for r in runs if r.ayss is not None and len(r.ayss) > 0]
    if len(samples) == len(runs):
        bands = binned_seed_means([(a.h, a.indicator) for a in samples], edges, level, 2)
        h = np.concatenate([a.h for a in samples])
        y = np.concatenate([a.indicator for a in samples])
        return bands, binned_mean_ci(h, y, edges, level=level, min_count=2)
    cells = [c for r in runs if (c := run_cells(r)) is not None]
    per_seed = [binned_stats_from_cells([c], edges, level, 2) for c in cells]
    return seed_bands(per_seed, edges, level), binned_stats_from_cells(cells, edges, level, 2)


def band_kind(bands: SeedBands) -> str:
    """What a between-seed band is, for a legend: t-interval, range of two seeds, or none."""
    most = int(bands.n_seeds.max()) if bands.n_seeds.size else 0
    if most >= MIN_SEEDS_FOR_INTERVAL:
        return "t-interval over seeds"
    return "range of the 2 seeds" if most == 2 else "one seed: no band"


def _band(
    ax: Axes,
    centers: NDArray[np.float64],
    means: NDArray[np.float64],
    lo: NDArray[np.float64],
    hi: NDArray[np.float64],
    color: str,
    label: str,
) -> None:
    ax.plot(centers, means, color=color, lw=2.2, marker="o", ms=4, label=label)
    ok = np.isfinite(lo) & np.isfinite(hi)
    ax.fill_between(centers, lo, hi, where=ok, color=color, alpha=0.22, lw=0, interpolate=False)


def indicator_figure(
    runs_by_vut: Mapping[str, Sequence[RunRecord]],
    colors: Mapping[str, str],
    path: Path,
    *,
    edges: NDArray[np.float64],
    axis_label: str,
    title: str,
    level: float = 0.95,
) -> Path:
    """Mean indicator vs headway with its uncertainty (the paper's Fig. 4 / Fig. 6).

    Left, the primary panel: per VUT and bin, the mean over seeds of each seed's bin mean,
    with the band between seeds (:func:`~sumo_ayss.analysis.seed_intervals.binned_seed_means`:
    a t-interval over three or more seeds, the range of two), and each seed's own line thin:
    the uncertainty the verdict uses. Right: the samples of all seeds pooled (per-bin
    Student t interval at ``level``), which ignores the seed-to-seed spread. Below: samples
    per bin and per SPCP. Bins with fewer than two samples of a seed are left out.

    Args:
        runs_by_vut: ``{vut: runs}`` of one case.
        colors: ``{vut: colour}``.
        path: PNG file to write.
        edges: Headway bin edges in m, shape ``(k + 1,)``.
        axis_label: Label of the indicator axis, with unit.
        title: Figure title.
        level: Confidence level of the intervals.

    Returns:
        ``path``.
    """
    centers = 0.5 * (edges[:-1] + edges[1:])
    width = float(np.min(np.diff(edges)))
    pct = f"{100 * level:g} %"
    in_range: list[tuple[str, str, int]] = []  # (vut, run label, samples in the bin range)
    kinds: set[str] = set()
    with style():
        fig = Figure(figsize=(12.0, 6.8), layout="constrained")
        grid = fig.add_gridspec(2, 2, height_ratios=[3.0, 1.0])
        ax_seeds = fig.add_subplot(grid[0, 0])
        ax_npool = fig.add_subplot(grid[1, 0], sharex=ax_seeds)
        ax_pool = fig.add_subplot(grid[0, 1], sharex=ax_seeds, sharey=ax_seeds)
        ax_nseed = fig.add_subplot(grid[1, 1])
        n_vut = max(1, len(runs_by_vut))
        for v, (vut, members) in enumerate(runs_by_vut.items()):
            color = colors[vut]
            with_data = [r for r in members if has_ayss(r)]
            in_range += [(vut, f"{r.label}\n(none)", 0) for r in members if not has_ayss(r)]
            if not with_data:
                continue
            bands, pooled = _vut_bins(with_data, edges, level)
            kinds.add(band_kind(bands))
            _band(
                ax_seeds,
                centers,
                bands.means,
                bands.lo,
                bands.hi,
                color,
                f"{vut} (mean of {len(with_data)} seeds)",
            )
            for pos, (run, stats) in enumerate(zip(with_data, bands.per_seed, strict=True)):
                ls, marker = seed_style(pos)
                ax_seeds.plot(
                    centers,
                    stats.means,
                    color=color,
                    ls=ls,
                    lw=0.9,
                    marker=marker,
                    ms=3,
                    alpha=0.8,
                    label=run.label,
                )
                in_range.append((vut, run.label, int(stats.counts.sum())))
            n_in = int(pooled.counts.sum())
            _band(
                ax_pool, centers, pooled.means, pooled.lo, pooled.hi, color, f"{vut} (n = {n_in})"
            )
            offset = (v - (n_vut - 1) / 2) * width / (n_vut + 1)
            ax_npool.bar(
                centers + offset, pooled.counts, width=width / (n_vut + 1), color=color, alpha=0.8
            )
        band = " / ".join(sorted(kinds)) or "band between seeds"
        ax_seeds.set_title(
            f"Primary, between seeds (what the verdict uses): mean of the seeds' means\n"
            f"band: {band}",
            fontsize=9.5,
        )
        ax_pool.set_title(
            f"Secondary: all samples pooled, {pct} CI per {width:g} m bin\n"
            "(ignores the seed-to-seed spread: tighter than the evidence)",
            fontsize=9.5,
        )
        ax_seeds.set_ylabel(f"{axis_label}\n(lower = more aggressive SPCP = safer VUT)")
        ax_npool.set_ylabel("samples / bin")
        ax_npool.set_xlabel("distance headway h [m]")
        ax_pool.set_xlabel("distance headway h [m]")
        ax_seeds.set_xlim(edges[0], edges[-1])
        if any(n for _, _, n in in_range):
            ax_seeds.legend(loc="best", fontsize=7, ncol=2)
            ax_pool.legend(loc="best", fontsize=7)
            xs = np.arange(len(in_range))
            ax_nseed.bar(xs, [n for _, _, n in in_range], color=[colors[v] for v, _, _ in in_range])
            ax_nseed.set_xticks(xs, [lab.replace(" seed ", "\ns") for _, lab, _ in in_range])
            ax_nseed.tick_params(axis="x", labelsize=8)
            ax_nseed.set_ylabel("samples")
            ax_nseed.set_title(
                f"AYSS samples per SPCP with {edges[0]:g} ≤ h ≤ {edges[-1]:g} m", fontsize=9.5
            )
            ax_nseed.grid(axis="x", visible=False)
        else:
            no_data(ax_seeds, "no AYSS samples (ayss.csv) in these runs yet")
            ax_nseed.set_axis_off()
        fig.suptitle(title, fontsize=12, fontweight="bold")
        return save(fig, path)


# --------------------------------------------------------------------------- safety index


def safety_index_figure(
    indices: Mapping[str, SafetyIndex],
    colors: Mapping[str, str],
    path: Path,
    *,
    unit: str,
    what: str,
    title: str,
) -> Path:
    """Safety index per VUT with its interval, safest on top, per-seed indices as dots.

    Args:
        indices: ``{vut: index}``, any order (drawn sorted by point estimate).
        colors: ``{vut: colour}``.
        path: PNG file to write.
        unit: Unit of the index, e.g. ``"m/s²"``.
        what: What the index is minus the mean of, e.g. ``"POV acceleration"``.
        title: Figure title.

    Returns:
        ``path``.
    """
    order = sorted(indices, key=lambda v: (indices[v].point, v))  # bottom to top
    with style():
        fig = Figure(figsize=(10.0, 1.6 + 0.75 * max(1, len(order))), layout="constrained")
        ax = fig.subplots()
        rng = np.random.default_rng(0)
        for y, vut in enumerate(order):
            idx = indices[vut]
            color = colors[vut]
            err = [[idx.point - idx.lo], [idx.hi - idx.point]]
            ax.errorbar(
                idx.point,
                y,
                xerr=err,
                fmt="o",
                ms=9,
                color=color,
                capsize=6,
                lw=2.2,
                label=f"{vut}: {idx.point:.2f} [{idx.lo:.2f}, {idx.hi:.2f}] {unit}",
            )
            if idx.seed_points:
                jitter = rng.uniform(-0.12, 0.12, len(idx.seed_points))
                ax.scatter(
                    idx.seed_points,
                    y + 0.25 + jitter * 0.5,
                    s=28,
                    facecolors="none",
                    edgecolors=color,
                    lw=1.2,
                    zorder=3,
                )
            rank = len(order) - y
            ax.annotate(
                f"#{rank}",
                xy=(idx.hi, y),
                xytext=(8, 0),
                textcoords="offset points",
                va="center",
                fontsize=9,
                color="0.25",
            )
        ax.set_yticks(range(len(order)), order)
        ax.set_ylim(-0.6, len(order) - 0.3)
        level = next(iter(indices.values())).level if indices else 0.95
        lo_h, hi_h = next(iter(indices.values())).h_range if indices else (0.0, 5.0)
        ax.set_xlabel(
            f"safety index = −mean {what} over AYSS with {lo_h:g} ≤ h ≤ {hi_h:g} m [{unit}]"
            "   (larger = safer VUT)"
        )
        ax.set_title(
            f"dot and bar: index with {100 * level:g} % hierarchical-bootstrap CI; "
            "circles: each seed's own index",
            fontsize=9.5,
            fontweight="normal",
            color="0.3",
        )
        fig.suptitle(title, fontsize=12, fontweight="bold")
        if not order:
            no_data(ax, "no safety index: no AYSS samples yet")
        else:
            ax.legend(loc="lower right", fontsize=8.5)
            xmin, xmax = ax.get_xlim()
            pad = 0.08 * (xmax - xmin) if math.isfinite(xmax - xmin) else 0.0
            ax.set_xlim(xmin - pad, xmax + pad)
        ax.grid(axis="y", visible=False)
        return save(fig, path)
