"""``<out>/<case>/adaptive.json``: the looks of adaptive seeding at one case, and its seeds.

Written by the pipeline after every look (:mod:`sumo_ayss.grid.adaptive`); read by the pipeline
when it resumes (the seeds already added are part of the grid) and by ``rank --no-run``.
A look is stored as an :class:`AdaptiveLook`, the fields of the analysis's
:class:`sumo_ayss.analysis.sequential.SettleCheck`. ``vuts`` names the VUTs looked at, each
with its definition's key
(:func:`~sumo_ayss.config.identity.vut_key`): a grid whose VUTs are others (one added,
dropped, redefined or renamed) ignores the record and starts over (records written before
``vuts`` existed are taken as they are).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from pathlib import Path

from sumo_ayss.records.jsonio import json_field, json_list, json_records, read_json, write_json
from sumo_ayss.util.errors import TableError

__all__ = ["ADAPTIVE_FORMAT", "AdaptiveLook", "AdaptiveRecord", "read_adaptive", "write_adaptive"]

ADAPTIVE_FORMAT = 1
"""Version of the file's layout."""


@dataclass(frozen=True)
class AdaptiveLook:
    """One look as stored: the fields of the analysis's
    :class:`sumo_ayss.analysis.sequential.SettleCheck` (storage imports no analysis; the
    pipeline stores a check with ``AdaptiveLook(**dataclasses.asdict(check))``).

    Attributes:
        n_seeds: Seed blocks per VUT at this look.
        omnibus_p: p of the F gate (NaN: no test).
        gate_level: The calibrated level the gate must be below.
        safest: The VUT with the lowest score.
        least_safe: The VUT with the highest score.
        ends_p: The paired-t p of ``safest`` against ``least_safe`` (NaN: no test).
        alpha: The level ``ends_p`` must be below.
        settled: Both tests passed.
    """

    n_seeds: int
    omnibus_p: float
    gate_level: float
    safest: str
    least_safe: str
    ends_p: float
    alpha: float
    settled: bool


@dataclass(frozen=True)
class AdaptiveRecord:
    """Adaptive seeding at one case.

    Attributes:
        first_seeds: The grid's own seeds (``grid.seeds``), where every case starts.
        max_seeds: The cap on seeds per VUT.
        alpha: The procedure's false-positive rate.
        seeds: Every seed the case's VUTs were trained on so far, in the order added.
        looks: Every look so far, in order.
        vuts: ``(name, definition key)`` of every VUT looked at (stored as a JSON object;
            empty in records written before it).
    """

    first_seeds: tuple[int, ...]
    max_seeds: int
    alpha: float
    seeds: tuple[int, ...]
    looks: tuple[AdaptiveLook, ...]
    vuts: tuple[tuple[str, str], ...] = ()

    @property
    def settled(self) -> bool:
        """Whether the last look found the ranking settled."""
        return bool(self.looks) and self.looks[-1].settled


def write_adaptive(path: str | Path, record: AdaptiveRecord) -> None:
    """Write ``adaptive.json`` atomically."""
    data = asdict(record)
    data["vuts"] = dict(record.vuts)
    data["format"] = ADAPTIVE_FORMAT
    write_json(path, data)


def read_adaptive(path: str | Path) -> AdaptiveRecord:
    """Read ``adaptive.json``.

    Raises:
        TableError: If the file is missing, unreadable or not in this layout.
    """
    data = read_json(path)
    where = str(path)
    if data.get("format") != ADAPTIVE_FORMAT:
        raise TableError(f"{path}: format {data.get('format')!r}, expected {ADAPTIVE_FORMAT}")
    looks = json_records(data, "looks", AdaptiveLook, where)  # read first, as before
    vuts = (json_field(data, "vuts", (dict, type(None)), where) if "vuts" in data else None) or {}
    return AdaptiveRecord(
        first_seeds=json_list(data, "first_seeds", int, where),
        max_seeds=json_field(data, "max_seeds", int, where),
        alpha=float(json_field(data, "alpha", (int, float), where)),
        seeds=json_list(data, "seeds", int, where),
        looks=looks,
        vuts=tuple((str(k), str(v)) for k, v in vuts.items()),
    )
