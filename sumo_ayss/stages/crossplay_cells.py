"""Which cells of a case's cross-play table a new request can keep, and which it must drive.

A cross-play table is a grid of cells, one per (VUT, opponent SPCP), each ``n`` episodes
in a fresh simulation of its own (:mod:`sumo_ayss.scenarios.crossplay`): a cell depends on
the VUT's definition, the opponent's SPCP (its ``spcp.zip`` and training seed, the SUMO
seed of the cell) and the scenario set, and on nothing else of the study. So when a study
changes (a VUT added, dropped, redefined or renamed; adaptive seeding's new seeds), every
cell whose VUT and opponent are unchanged is kept from the recorded table, and only the
others are driven: a new VUT against every opponent, every new opponent against every VUT.

A VUT is matched by its definition's key (:func:`~sumo_ayss.config.identity.vut_key`,
recorded in ``crossplay.json`` as ``vut_keys``), so a renamed VUT keeps its cells under its
new name; a record written before the keys existed matches a VUT by name, and only while
every SPCP it recorded for that VUT is still in the pool (a redefined VUT retrains, and so
changes its SPCPs). An opponent is matched by training seed and SPCP SHA-256.

:func:`plan_cells` returns the kept rows (renamed to the request's names) and diagonal
checks, and the opponents each VUT still has to meet; :func:`merged_rows` puts kept and
new rows in the order one run over the whole request writes them, so the merged table
equals a full rerun's. :func:`kept_reference_rows` does the same for the reference drivers'
table (``crossplay_reference.csv``); :func:`cell_groups` puts the VUTs that meet the same
opponents into one drive.

Imports neither SUMO nor torch.
"""

from __future__ import annotations

import dataclasses
from collections import Counter
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sumo_ayss.records.table import read_table
from sumo_ayss.run_folder import (
    CROSSPLAY_SCHEMA,
    CrossplayOpponent,
    CrossplayRecord,
    DiagonalCheck,
)
from sumo_ayss.util.errors import TableError

__all__ = [
    "CellPlan",
    "cell_groups",
    "crossplay_inputs",
    "kept_reference_rows",
    "merged_rows",
    "plan_cells",
    "same_scenarios",
    "same_vuts",
]


def same_vuts(done: CrossplayRecord, requested: CrossplayRecord) -> bool:
    """Whether both tables drive the same VUTs in the same order and, where both records
    name their definitions, the same vehicles."""
    keys = not (done.vut_keys and requested.vut_keys) or done.vut_keys == requested.vut_keys
    return done.vuts == requested.vuts and keys


def crossplay_inputs(record: CrossplayRecord) -> dict[str, Any]:
    """What a table was made from: the scenario set, the opponents and how they were driven
    (the cross-play stage's inputs, :class:`~sumo_ayss.stages.contract.CrossplayStage`)."""
    return {
        "n": record.n,
        "seed": record.seed,
        "opponents": [dataclasses.asdict(o) for o in record.opponents],
        "rollout": record.rollout,
    }


def same_scenarios(done: CrossplayRecord, requested: CrossplayRecord) -> bool:
    """Whether both tables' cells were driven on the same scenarios in the same way, so that
    a cell of one may stand for the same cell of the other."""
    return (done.n, done.seed, done.rollout) == (requested.n, requested.seed, requested.rollout)


@dataclass(frozen=True)
class CellPlan:
    """What of a recorded cross-play a request keeps, and what it must drive.

    Attributes:
        kept_rows: The recorded rows of every kept cell, under the request's names.
        kept_checks: The recorded diagonal checks of the kept opponents, under the
            request's names.
        to_drive: Per VUT of the request (its order), the opponents it has yet to meet
            (pool order); a VUT with nothing to drive is absent.
        renamed: ``(recorded name, requested name)`` of every VUT kept under a new name.
        wall_s: The recorded table's wall time, s (the kept cells' cost is part of it).
    """

    kept_rows: tuple[dict[str, Any], ...]
    kept_checks: tuple[DiagonalCheck, ...]
    to_drive: Mapping[str, tuple[CrossplayOpponent, ...]]
    renamed: tuple[tuple[str, str], ...] = ()
    wall_s: float = 0.0

    @property
    def n_kept(self) -> int:
        """Cells kept (VUT × opponent)."""
        return len({(r["vut"], r["opponent_vut"], r["opponent_seed"]) for r in self.kept_rows})

    @property
    def n_to_drive(self) -> int:
        """Cells to drive."""
        return sum(len(o) for o in self.to_drive.values())


def _vut_matches(earlier: CrossplayRecord, requested: CrossplayRecord) -> dict[str, str]:
    """Requested VUT name -> the recorded name of the same vehicle (absent: a new VUT)."""
    pool = {(o.vut, o.seed, o.spcp_sha256) for o in requested.opponents}
    found: dict[str, str] = {}
    if earlier.vut_keys and requested.vut_keys:
        by_key: dict[str, list[str]] = {}
        for name, key in zip(earlier.vuts, earlier.vut_keys, strict=True):
            by_key.setdefault(key, []).append(name)
        for name, key in zip(requested.vuts, requested.vut_keys, strict=True):
            names = by_key.get(key, [])
            if names:
                found[name] = name if name in names else names[0]
        return found
    for name in requested.vuts:  # an older record: by name, while its SPCPs are unchanged
        own = {(o.vut, o.seed, o.spcp_sha256) for o in earlier.opponents if o.vut == name}
        if name in earlier.vuts and own and own <= pool:
            found[name] = name
    return found


def plan_cells(
    earlier: CrossplayRecord, rows: Iterable[Mapping[str, Any]], requested: CrossplayRecord
) -> CellPlan:
    """The cells of ``requested`` that the recorded cross-play (``earlier`` and its table's
    ``rows``) already holds, and the rest. ``earlier`` must be of the same scenarios and
    rollout (the caller checks) and carry its diagonal check."""
    vuts = _vut_matches(earlier, requested)
    by_spcp = {(o.seed, o.spcp_sha256): o for o in earlier.opponents}
    opponents = {  # requested opponent -> recorded opponent of the same SPCP
        o: by_spcp[(o.seed, o.spcp_sha256)]
        for o in requested.opponents
        if (o.seed, o.spcp_sha256) in by_spcp
    }
    old_vut = {old: new for new, old in vuts.items()}
    old_opp = {(e.vut, e.seed): o for o, e in opponents.items()}
    kept = []
    for row in rows:
        new_vut = old_vut.get(row["vut"])
        opp = old_opp.get((row["opponent_vut"], row["opponent_seed"]))
        if new_vut is not None and opp is not None:
            kept.append({**row, "vut": new_vut, "opponent_vut": opp.vut})
    checks = {(d.vut, d.seed): d for d in earlier.diagonal}
    kept_checks = tuple(
        dataclasses.replace(checks[(e.vut, e.seed)], vut=o.vut)
        for o, e in opponents.items()
        if o.vut in vuts and (e.vut, e.seed) in checks
    )
    to_drive = {
        v: tuple(o for o in requested.opponents if v not in vuts or o not in opponents)
        for v in requested.vuts
    }
    renamed = tuple((old, new) for new, old in vuts.items() if old != new)
    live = {v: o for v, o in to_drive.items() if o}
    return CellPlan(tuple(kept), kept_checks, live, renamed, earlier.wall_s)


def merged_rows(
    rows: Iterable[Mapping[str, Any]], vuts: Sequence[str], pool: Sequence[CrossplayOpponent]
) -> list[Mapping[str, Any]]:
    """``rows`` in the order one run over the whole request writes them: VUT (``vuts``
    order), then opponent (``pool`` order), then scenario."""
    order = {(o.vut, o.seed): j for j, o in enumerate(pool)}
    return sorted(
        rows,
        key=lambda r: (
            vuts.index(r["vut"]),
            order[(r["opponent_vut"], r["opponent_seed"])],
            r["scenario"],
        ),
    )


def kept_reference_rows(
    path: Path,
    references: Sequence[str],
    n: int,
    seed: int,
    earlier: CrossplayRecord | None,
    pool: tuple[CrossplayOpponent, ...],
) -> list[dict[str, Any]]:
    """The rows of ``crossplay_reference.csv`` whose reference is asked for and whose
    opponent is, by ``earlier``'s SHA-256, an SPCP of ``pool`` (under its current name);
    none without a usable file or record of this scenario set."""
    if earlier is None or (earlier.n, earlier.seed) != (n, seed) or not path.is_file():
        return []
    try:
        old = read_table(path, CROSSPLAY_SCHEMA)
    except TableError:
        return []
    then = {(o.vut, o.seed): o.spcp_sha256 for o in earlier.opponents}
    now = {(o.seed, o.spcp_sha256): o for o in pool}
    kept = []
    for row in old.rows():
        sha = then.get((row["opponent_vut"], row["opponent_seed"]))
        o = now.get((row["opponent_seed"], sha)) if sha is not None else None
        if o is not None and row["vut"] in references:
            kept.append({**row, "opponent_vut": o.vut})
    per_cell = Counter((r["vut"], r["opponent_vut"], r["opponent_seed"]) for r in kept)
    return [r for r in kept if per_cell[(r["vut"], r["opponent_vut"], r["opponent_seed"])] == n]


def cell_groups(
    to_drive: dict[str, tuple[CrossplayOpponent, ...]],
) -> dict[tuple[CrossplayOpponent, ...], tuple[str, ...]]:
    """The VUTs that meet the same opponents, together (one
    :func:`~sumo_ayss.scenarios.crossplay.run_crossplay` each): ``{opponents: VUTs}``, in
    the order of the VUTs."""
    groups: dict[tuple[CrossplayOpponent, ...], list[str]] = {}
    for vut, opps in to_drive.items():
        groups.setdefault(opps, []).append(vut)
    return {opps: tuple(vuts) for opps, vuts in groups.items()}
