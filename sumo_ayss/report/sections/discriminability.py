"""Report section "Discriminability before training": figure and tables of a case's VUTs.

Reads the record ``discriminability.json`` written by :mod:`sumo_ayss.discriminability`
(the pipeline writes one per case into ``<out>/<case>/`` before the report). The report
imports neither SUMO nor torch, so it never measures responses itself: without a record it
says how to make one.

The figure: share of the AYSS box where two VUTs' one-step responses differ by more than the
threshold, vs headway (left) and vs VUT speed (middle), one line per VUT pair; right, each
VUT's mean response vs headway.
"""

from __future__ import annotations

import logging
import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from sumo_ayss.analysis.discriminability import PairDiscriminability
from sumo_ayss.cases import case_info
from sumo_ayss.modes.formatting import fmt_num
from sumo_ayss.report import figstyle
from sumo_ayss.report.blocks import Block, FigureBlock, Heading, Paragraph, Table
from sumo_ayss.run_folder import CaseFolder, read_discriminability_json
from sumo_ayss.util.errors import TableError

logger = logging.getLogger(__name__)

__all__ = ["discriminability_blocks", "discriminability_figure", "pair_summary", "read_record"]

_MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*")


def pair_summary(
    pair: PairDiscriminability, threshold_mps2: float, h_step_m: float | None = None
) -> str:
    """One line a user reads in seconds, e.g. ``pi1 vs pi2 differ in 11.9 % of the AYSS
    box; none below h ≈ 2.95 m`` (the record's ``summary`` lines).

    Args:
        pair: How the two VUTs' responses differ.
        threshold_mps2: The difference that counts [m/s²].
        h_step_m: The smallest headway of the grid [m]; a pair that differs there differs
            "down to the smallest headway".
    """
    label = f"{pair.a} vs {pair.b}"
    if pair.lowest_h_m is None:
        return (
            f"{label}: no difference anywhere in the AYSS box "
            f"(|Δa| <= {threshold_mps2:g} m/s² at all {pair.n_states:,} states)"
        )
    head = f"{label} differ in {100 * pair.share:.1f} % of the AYSS box"
    if h_step_m is not None and pair.lowest_h_m <= h_step_m + 1e-9:
        return f"{head}; down to the smallest headway (h = {pair.lowest_h_m:g} m)"
    return f"{head}; none below h ≈ {pair.lowest_h_m:.2f} m"


def read_record(path: Path) -> dict[str, Any] | None:
    """The record at ``path`` (:func:`~sumo_ayss.run_folder.read_discriminability_json`),
    or None if missing or unreadable (logged)."""
    if not path.is_file():
        return None
    try:
        return read_discriminability_json(path)
    except TableError as e:  # names the file
        logger.warning("%s", e)
        return None


def _series(values: Sequence[float | None]) -> np.ndarray:
    return np.array([math.nan if v is None else float(v) for v in values], dtype=float)


def discriminability_figure(
    record: Mapping[str, Any], path: Path, colors: Mapping[str, str] | None = None
) -> Path | None:
    """Draw the record's figure into ``path`` (PNG); None if it has no pair.

    Args:
        record: A record as written by :mod:`sumo_ayss.discriminability`.
        path: PNG file.
        colors: ``{vut: colour}`` for the mean-response panel (default: the report palette).
    """
    pairs = record["pairs"]
    if not pairs:
        return None
    he = np.asarray(record["h_edges_m"], dtype=float)
    ve = np.asarray(record["v_edges_mps"], dtype=float)
    hc, vc = 0.5 * (he[:-1] + he[1:]), 0.5 * (ve[:-1] + ve[1:])
    thr = record.get("threshold_mps2", 0.1)
    colors = {**figstyle.vut_colors(list(record["vuts"])), **(colors or {})}
    with figstyle.style():
        fig = Figure(figsize=(15, 4.4), layout="constrained")
        ax_h, ax_v, ax_m = fig.subplots(1, 3)
        # Pairs (and VUTs) that coincide draw on top of each other: earlier lines are drawn
        # wider and with other markers, so that a covered line still shows at its edges.
        n = len(pairs)
        for i, p in enumerate(pairs):
            label = f"{p['a']} vs {p['b']} ({100 * p['share']:.1f} %)"
            style: dict[str, Any] = {
                "marker": _MARKERS[i % len(_MARKERS)],
                "ms": 3 + 3 * (n - i) / n,
                "lw": 1.2 + 2.8 * (n - 1 - i) / max(1, n - 1),
                "ls": figstyle.LINESTYLES[(i // len(_MARKERS)) % len(figstyle.LINESTYLES)],
                "alpha": 0.85,
            }
            ax_h.plot(hc, 100 * _series(p["share_by_h"]), label=label, **style)
            ax_v.plot(vc, 100 * _series(p["share_by_v_vut"]), label=label, **style)
        for ax, xlabel in ((ax_h, "headway h [m] (bin centre)"), (ax_v, "VUT speed [m/s]")):
            ax.set_xlabel(xlabel)
            ax.set_ylabel(f"states where |Δa| > {thr:g} m/s² [%]")
            ax.set_ylim(-3, 103)
        ax_h.set_title("Where the VUTs' responses differ: by headway")
        ax_v.set_title("... by VUT speed")
        ax_h.legend(loc="upper left", title="pair (share of the box)")
        by_h = record.get("mean_response_by_h_mps2", {})
        names = [v for v in record["vuts"] if v in by_h]
        for i, vut in enumerate(names):
            ax_m.plot(
                hc,
                _series(by_h[vut]),
                marker=_MARKERS[i % len(_MARKERS)],
                ms=3 + 3 * (len(names) - i) / len(names),
                lw=1.2 + 2.8 * (len(names) - 1 - i) / max(1, len(names) - 1),
                alpha=0.85,
                color=colors.get(vut),
                label=f"{vut} ({fmt_num(record['mean_response_mps2'][vut])})",
            )
        ax_m.set_xlabel("headway h [m] (bin centre)")
        ax_m.set_ylabel("mean VUT acceleration [m/s²]")
        ax_m.set_title("Mean one-step response per VUT")
        ax_m.legend(loc="best", title="VUT (box mean, m/s²)")
        return figstyle.save(fig, path)


def _pct(x: float | None) -> str:
    return "—" if x is None or not math.isfinite(x) else f"{100 * x:.1f}"


def _rel(path: Path, base: Path) -> str:
    """``path`` relative to ``base`` (the report folder): reports carry no machine paths."""
    return Path(os.path.relpath(Path(path).resolve(), Path(base).resolve())).as_posix()


def _command(config: Path | str, vuts: Sequence[str], case_dir: Path, out_dir: Path) -> str:
    config = _rel(config, out_dir) if isinstance(config, Path) else config
    return (
        f"python -m sumo_ayss.discriminability {config} --vuts {' '.join(vuts)} "
        f"--out {_rel(case_dir, out_dir)}"
    )


def discriminability_blocks(
    case: str,
    vuts: Sequence[str],
    case_dirs: Sequence[Path],
    out_dir: Path,
    colors: Mapping[str, str] | None = None,
) -> list[Block]:
    """The report blocks of the section, for a case with >= 2 VUTs (else none).

    Args:
        case: Case name.
        vuts: The case's VUTs in the report.
        case_dirs: Folders that may hold the record (``<out>/<case>/`` of the runs); the
            first readable record that covers at least 2 of ``vuts`` is used.
        out_dir: The report folder (the figure is drawn there).
        colors: ``{vut: colour}`` of the report.

    Returns:
        Heading, paragraph(s), figure and tables (:mod:`sumo_ayss.report.blocks`).
    """

    if len(vuts) < 2:
        return []
    heading = Heading("(h) Discriminability before training: where the VUTs' responses differ", 3)
    record, where = None, None
    for d in case_dirs:
        rec = read_record(CaseFolder(d).discriminability_json)
        if (
            rec is not None
            and len(set(rec["vuts"]) & set(vuts)) >= 2
            and rec.get("case", case) == case
        ):
            record, where = rec, _rel(CaseFolder(d).discriminability_json, out_dir)
            break
    if record is None:
        target = case_dirs[0] if case_dirs else Path(f"<out>/{case}")
        configs = sorted(target.glob("*/seed_*/config.yaml"))
        config = configs[0] if configs else f"<experiment YAML of {case}>"
        return [
            heading,
            Paragraph(
                "Not computed for these VUTs (no discriminability.json beside the runs; "
                "the pipeline writes one). Make it with (paths relative to this report's "
                f"folder): {_command(config, vuts, target, out_dir)}"
            ),
        ]
    missing = sorted(set(vuts) - set(record["vuts"]))
    path = discriminability_figure(record, out_dir / f"{case}_discriminability.png", colors)
    settings = record.get("settings", {})
    grid = settings.get("grid", {})
    thr = record.get("threshold_mps2", 0.1)
    text = (
        "Before any training: each VUT's one-step response (its acceleration over "
        f"{settings.get('decisions', 1)} decision(s), measured in SUMO) at every state of a "
        f"grid over the AYSS box (speeds {grid.get('v_vut_mps', '?')} m/s every "
        f"{grid.get('speed_step_mps', '?')} m/s, h every {grid.get('headway_step_m', '?')} m up "
        f"to {grid.get('max_headway_m', '?')} m, TTC ≥ {grid.get('min_ttc_s', '?')} s: "
        f"{record.get('n_states', 0):,} states). An SPCP can only adapt to a VUT where the VUT "
        "reacts differently: where two VUTs' responses coincide, the AYSS indicator has "
        "nothing to separate them by."
    )
    blocks: list[Any] = [heading, Paragraph(text)]
    blocks += [Paragraph(line) for line in record.get("summary", [])]
    note = case_info(case).one_decision_note
    if note and settings.get("decisions", 1) == 1:
        blocks.append(Paragraph(note))
    if missing:
        blocks.append(Paragraph(f"Not in the record ({where}): {', '.join(missing)}."))
    if path is not None:
        blocks.append(
            FigureBlock(
                path,
                f"Share of AYSS states where two VUTs' responses differ by more than {thr:g} "
                "m/s², per headway bin (left) and per VUT-speed bin (middle), one line per "
                "pair; right: each VUT's mean response per headway bin. "
                f"Source: {where}.",
            )
        )
    rows = []
    for p in record["pairs"]:
        low = p.get("lowest_h_m")
        rows.append(
            (
                f"{p['a']} vs {p['b']}",
                _pct(p["share"]),
                "never" if low is None else f"{low:.2f}",
                f"{p['mean_abs_diff_mps2']:.3f}",
                f"{p['max_abs_diff_mps2']:.2f}",
            )
        )
    blocks.append(
        Table(
            "Pairwise discriminability over the AYSS box",
            ("pair", f"states with |Δa| > {thr:g} m/s² [%]", "lowest h where they differ [m]",
             "mean |Δa| [m/s²]", "max |Δa| [m/s²]"),
            tuple(rows),
            (False, True, True, True, True),
        )
    )  # fmt: skip
    collisions = record.get("collisions", {})
    blocks.append(
        Table(
            "Mean one-step response per VUT",
            ("VUT", "mean acceleration [m/s²]", "collisions in the measured step(s)"),
            tuple(
                (v, fmt_num(a, 3), str(collisions.get(v, "—")))
                for v, a in record["mean_response_mps2"].items()
            ),
            (False, True, True),
        )
    )
    return blocks
