"""``ayss_bins.csv``: the AYSS samples of one run reduced to per-headway-cell moments.

``ayss.csv`` (one row per kept sample, ~80,000 per run at the paper budget) is kept out of
git; ``ayss_bins.csv`` is small (a few hundred rows) and committed beside the other run
files, so that a committed study's AYSS figures, table and paper mode can be drawn again
without the samples.

**Cells.** The headway axis is cut at every multiple of :data:`CELL_WIDTH_M` (1/32 m, a
binary fraction: every edge is exact in floating point, and so are the report's grids of
0.25 m and 0.5 m). A cell is either one such *open* interval ``(k/32, (k+1)/32)`` or one
*edge point* ``{k/32}`` (``h_low_m == h_high_m``; almost always empty and then not written),
so the samples of any bin of a grid whose edges lie on the 1/32 m lattice, half-open or
closed, are exactly a union of cells. Per non-empty cell the file holds the sample count
``n``, the mean of the indicator and ``m2``, the sum of squared deviations from that mean:
what a bin's count, mean and standard deviation (the figures' t-intervals), the safety
index's bin means and its seeds' own indices, and Cohen's d need, combined with Chan's
parallel formula (:mod:`sumo_ayss.analysis.ayss_cells`). What the cells cannot
give is the within-seed resampling of individual samples of the safety index's bootstrap;
from cells it is drawn from each bin's first two moments (documented there).

The samples are reduced to cells by the analysis (:func:`sumo_ayss.analysis.ayss_cells.cells_of`)
and written by the evaluate stage with ``ayss.csv`` (:func:`write_ayss_bins`; a run evaluated
before the file existed gets it from its ``ayss.csv``,
:func:`sumo_ayss.evaluate.backfill_ayss_bins`); :func:`read_ayss_bins` reads it into an
:class:`AyssCells`, checking the cells against the lattice. Imports neither SUMO nor torch,
nor the analysis.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from sumo_ayss.records.table import Table, read_table, write_table
from sumo_ayss.run_folder.schemas import AYSS_BINS_SCHEMA
from sumo_ayss.util.errors import AyssError

__all__ = ["CELL_WIDTH_M", "AyssCells", "read_ayss_bins", "write_ayss_bins"]

CELL_WIDTH_M = 1.0 / 32.0
"""Width of a headway cell [m]: a binary fraction, so every cell edge is exact (the
analysis's reduction uses the same, :data:`sumo_ayss.analysis.ayss_cells.CELL_WIDTH_M`)."""


@dataclass(frozen=True)
class AyssCells:
    """The AYSS samples of one run as per-cell moments (``ayss_bins.csv``), cells sorted by
    headway.

    Attributes:
        h_low_m: Lower end of each cell [m], shape ``(c,)``.
        h_high_m: Upper end [m]; equal to ``h_low_m`` for an edge-point cell.
        n: Samples in the cell, shape ``(c,)``, >= 1.
        mean: Mean indicator of the cell's samples (m/s² or m/s).
        m2: Sum of squared deviations of the cell's indicator from ``mean`` (unit²).
        indicator_name: The samples' ``indicator_name`` (most common), or None.
    """

    h_low_m: NDArray[np.float64]
    h_high_m: NDArray[np.float64]
    n: NDArray[np.int64]
    mean: NDArray[np.float64]
    m2: NDArray[np.float64]
    indicator_name: str | None

    def __len__(self) -> int:
        """Samples in all cells (the rows of the ``ayss.csv`` they summarise)."""
        return int(self.n.sum())


def write_ayss_bins(path: Path, cells: AyssCells) -> None:
    """Write ``cells`` as ``ayss_bins.csv`` (:data:`AYSS_BINS_SCHEMA`), atomically."""
    c = len(cells.n)
    table = Table(
        AYSS_BINS_SCHEMA,
        {
            "h_low_m": cells.h_low_m,
            "h_high_m": cells.h_high_m,
            "n": cells.n,
            "mean": cells.mean,
            "m2": cells.m2,
            "indicator_name": np.full(c, cells.indicator_name or ""),
        },
    )
    write_table(path, table)


def read_ayss_bins(path: Path) -> AyssCells:
    """Read ``ayss_bins.csv``.

    Raises:
        AyssError: A cell with no sample, a negative ``m2`` or an end not on the lattice.
    """
    table = read_table(path, AYSS_BINS_SCHEMA)
    names = Counter(str(v) for v in table["indicator_name"] if str(v))
    low = np.asarray(table["h_low_m"], dtype=np.float64)
    high = np.asarray(table["h_high_m"], dtype=np.float64)
    n = np.asarray(table["n"], dtype=np.int64)
    m2 = np.asarray(table["m2"], dtype=np.float64)
    width = high - low
    on_lattice = np.all(np.floor(low / CELL_WIDTH_M) == low / CELL_WIDTH_M)
    cell_sized = np.all((width == 0.0) | (width == CELL_WIDTH_M))
    if not (on_lattice and cell_sized) or np.any(n < 1) or np.any(m2 < 0):
        raise AyssError(
            f"{path.name}: expected cells of {CELL_WIDTH_M:g} m on its lattice (or edge "
            "points), each with n >= 1 and m2 >= 0"
        )
    mean = np.asarray(table["mean"], dtype=np.float64)
    if not all(math.isfinite(v) for v in (*mean.tolist(), *m2.tolist())):
        raise AyssError(f"{path.name}: a mean or m2 is not finite")
    return AyssCells(low, high, n, mean, m2, names.most_common(1)[0][0] if names else None)
