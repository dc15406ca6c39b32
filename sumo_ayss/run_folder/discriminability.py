"""``discriminability.json`` and ``discriminability.csv``: one writer and one reader.

They lie in the case folder ``<out>/<case>/`` (:class:`~.layout.CaseFolder`; the
discriminability CLI writes them into its ``--out``). The JSON record is what
:func:`sumo_ayss.discriminability.compute` returns: the case, the VUTs, the settings, the
fingerprint of the inputs (the stage's done marker, :mod:`sumo_ayss.stages.contract`), and the
comparison (``pairs`` with their shares by bin, ``h_edges_m`` in m, ``v_edges_mps`` in
m/s, ``mean_response_mps2`` per VUT in m/s²). The CSV is the same shares as a long table, one row
per (VUT pair, dimension, bin). Imports neither SUMO nor torch.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from sumo_ayss.records.jsonio import read_json
from sumo_ayss.records.table import write_rows
from sumo_ayss.run_folder.layout import CaseFolder
from sumo_ayss.util.atomic import atomic_write_json
from sumo_ayss.util.errors import TableError

__all__ = [
    "DISCRIMINABILITY_COLUMNS",
    "RECORD_FIELDS",
    "discriminability_rows",
    "read_discriminability_json",
    "write_discriminability",
]

DISCRIMINABILITY_COLUMNS = ("pair", "dimension", "bin_low", "bin_high", "share")
"""``discriminability.csv``'s columns: ``pair`` ("a vs b"), ``dimension`` (``all``,
``h_m``, ``v_vut_mps``, ``v_pov_mps``), the bin's edges (m or m/s; empty for ``all``) and
the share of the AYSS box's states in the bin where the two responses differ (empty: no
state in the bin)."""

RECORD_FIELDS = ("pairs", "h_edges_m", "v_edges_mps", "vuts", "mean_response_mps2")
"""Fields every record holds (what the report draws)."""


def discriminability_rows(record: Mapping[str, Any]) -> list[dict[str, Any]]:
    """The long table of a record (one row per pair, dimension and bin)."""
    rows: list[dict[str, Any]] = []
    dims = (
        ("h_m", record["h_edges_m"], "share_by_h"),
        ("v_vut_mps", record["v_edges_mps"], "share_by_v_vut"),
        ("v_pov_mps", record["v_edges_mps"], "share_by_v_pov"),
    )
    for p in record["pairs"]:
        label = f"{p['a']} vs {p['b']}"
        rows.append({"pair": label, "dimension": "all", "bin_low": "", "bin_high": "",
                     "share": p["share"]})  # fmt: skip
        for dim, edges, key in dims:
            for lo, hi, s in zip(edges[:-1], edges[1:], p[key], strict=True):
                rows.append({"pair": label, "dimension": dim, "bin_low": lo, "bin_high": hi,
                             "share": "" if s is None else s})  # fmt: skip
    return rows


def write_discriminability(folder: CaseFolder, record: Mapping[str, Any]) -> list[Path]:
    """Write ``discriminability.json`` (the record; indented, keys sorted) and
    ``discriminability.csv`` (:func:`discriminability_rows`) into ``folder`` (created);
    returns the two paths."""
    folder.path.mkdir(parents=True, exist_ok=True)
    atomic_write_json(folder.discriminability_json, dict(record))
    write_rows(folder.discriminability_csv, DISCRIMINABILITY_COLUMNS, discriminability_rows(record))
    return [folder.discriminability_json, folder.discriminability_csv]


def read_discriminability_json(path: Path) -> dict[str, Any]:
    """Read ``discriminability.json``.

    Raises:
        TableError: The file is missing, not a JSON object, or lacks a field of
            :data:`RECORD_FIELDS` (naming the file and the fields).
    """
    data = read_json(path)
    missing = [k for k in RECORD_FIELDS if k not in data]
    if missing:
        raise TableError(f"{path}: missing fields {missing}")
    return data
