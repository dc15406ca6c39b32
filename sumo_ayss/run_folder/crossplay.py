"""``crossplay.json``: the cross-play stage's record of one case, one writer and one reader.

It lies in the case folder ``<out>/<case>/`` (:class:`~.layout.CaseFolder`), beside
``crossplay.csv`` (:data:`~.schemas.CROSSPLAY_SCHEMA`, written and read with
:func:`~sumo_ayss.records.table.write_table` / :func:`~sumo_ayss.records.table.read_table`)::

    {"stage": "crossplay", "case": "cut_in", "n": 200, "seed": 4242,
     "opponents": [{"vut": "pi1", "seed": 0, "spcp_sha256": "..."}, ...],
     "vuts": ["pi1", "pi2"], "wall_s": 812.4, "rollout": "outcome",
     "diagonal": [{"vut": "pi1", "seed": 0, "n": 200, "n_equal": 200}, ...],
     "vut_keys": {"pi1": "3f0c...", "pi2": "a91b..."}}

``n`` and ``seed`` are the scenario set (:func:`~sumo_ayss.envs.odd.scenario_set`)
and, with the opponents and ``rollout``, what a rerun compares before skipping the case.
``rollout`` names how the episodes were driven: ``"outcome"`` (the outcome stage's single
env, :mod:`sumo_ayss.scenarios.crossplay`) or ``"pairs"`` (many pairs in one simulation,
how tables were made before issue 21; such a table is re-run). ``diagonal`` is the check
that each SPCP, driven against its own VUT, reproduced its run's ``outcome.csv``: per run,
how many of the ``n`` episodes were equal (absent in older records). ``vut_keys`` names the
vehicle each VUT name stood for (:func:`~sumo_ayss.config.identity.vut_key` of its
definition; absent in older records): a study that adds, drops, redefines or renames a VUT
keeps the cells whose VUT and opponent are unchanged
(:mod:`sumo_ayss.stages.crossplay_cells`).

:func:`load_crossplay` reads a case's table and record back for the analysis, as stored
(:class:`CrossplayTables`); the analysis scores them on the runs' harm scale
(:func:`sumo_ayss.analysis.crossplay_scoring.crossplay_input`).

Imports neither SUMO nor torch, nor the analysis.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from sumo_ayss.records.jsonio import json_field, json_list, json_records, read_json, write_json
from sumo_ayss.records.table import Table, read_table
from sumo_ayss.run_folder.layout import CaseFolder
from sumo_ayss.run_folder.schemas import CROSSPLAY_SCHEMA
from sumo_ayss.util.errors import TableError

if TYPE_CHECKING:
    from sumo_ayss.run_folder.record import RunRecord

__all__ = [
    "ROLLOUT",
    "CrossplayOpponent",
    "CrossplayRecord",
    "CrossplayTables",
    "DiagonalCheck",
    "load_crossplay",
    "read_crossplay_json",
    "read_crossplay_table",
    "write_crossplay_json",
]

#: How the cross-play stage drives its episodes now (see the module docstring).
ROLLOUT = "outcome"

#: What a record without ``rollout`` was driven by.
_LEGACY_ROLLOUT = "pairs"


@dataclass(frozen=True)
class CrossplayOpponent:
    """One SPCP of the cross-play pool.

    Attributes:
        vut: The VUT it was trained against.
        seed: Its training seed.
        spcp_sha256: SHA-256 of its ``spcp.zip``.
    """

    vut: str
    seed: int
    spcp_sha256: str


@dataclass(frozen=True)
class DiagonalCheck:
    """One SPCP against its own VUT in cross-play, compared with its run's outcome table.

    Attributes:
        vut: The VUT (and the VUT the SPCP was trained against).
        seed: The run's training seed.
        n: Episodes compared.
        n_equal: Episodes equal in every column both tables hold (return, collision, final
            headway, decisions, near-miss pay, mobility), exactly.
    """

    vut: str
    seed: int
    n: int
    n_equal: int

    @property
    def ok(self) -> bool:
        return self.n_equal == self.n

    @property
    def share_differing(self) -> float:
        return (self.n - self.n_equal) / self.n if self.n else 0.0


@dataclass(frozen=True)
class CrossplayRecord:
    """``crossplay.json``.

    Attributes:
        case: The case.
        n: Scenarios per (VUT, opponent).
        seed: Seed of the scenario set.
        opponents: The SPCP pool, in the order of the table.
        vuts: The VUTs driven against, in the order of the table.
        wall_s: Wall time of the rollouts, s.
        rollout: How the episodes were driven (:data:`ROLLOUT` now).
        diagonal: The diagonal check per run (empty in records written before it).
        vut_keys: The definition key of each VUT, in the order of ``vuts`` (empty in
            records written before them).
    """

    case: str
    n: int
    seed: int
    opponents: tuple[CrossplayOpponent, ...]
    vuts: tuple[str, ...]
    wall_s: float
    rollout: str = ROLLOUT
    diagonal: tuple[DiagonalCheck, ...] = ()
    vut_keys: tuple[str, ...] = ()


def write_crossplay_json(path: Path, record: CrossplayRecord) -> None:
    """Write ``crossplay.json``: the record's fields (``wall_s`` to the millisecond),
    ``vut_keys`` as ``{vut: key}`` and left out when empty."""
    data = {"stage": "crossplay", **dataclasses.asdict(record), "wall_s": round(record.wall_s, 3)}
    if keys := data.pop("vut_keys"):
        data["vut_keys"] = dict(zip(record.vuts, keys, strict=True))
    write_json(path, data)


def read_crossplay_json(path: Path) -> CrossplayRecord:
    """Read ``crossplay.json``.

    Raises:
        TableError: The file is missing, not a JSON object, or a field is missing or of the
            wrong type; the message names the file and the field.
    """
    data = read_json(path)
    where = str(path)
    opponents = json_records(data, "opponents", CrossplayOpponent, where)
    vuts = json_list(data, "vuts", str, where)
    diagonal = (
        json_records(data, "diagonal", DiagonalCheck, where)
        if "diagonal" in data
        else ()  # a record from before the check
    )
    rollout = json_field(data, "rollout", str, where) if "rollout" in data else _LEGACY_ROLLOUT
    keys = data.get("vut_keys", {})  # absent in records written before them
    if (
        not isinstance(keys, Mapping)
        or (keys and sorted(keys) != sorted(vuts))
        or not all(isinstance(k, str) for k in keys.values())
    ):
        raise TableError(f"{where}: vut_keys: expected a key per VUT of {list(vuts)}, got {keys!r}")
    return CrossplayRecord(
        case=json_field(data, "case", str, where),
        n=json_field(data, "n", int, where),
        seed=json_field(data, "seed", int, where),
        opponents=opponents,
        vuts=vuts,
        wall_s=float(json_field(data, "wall_s", (int, float), where)),
        rollout=rollout,
        diagonal=diagonal,
        vut_keys=tuple(keys[v] for v in vuts) if keys else (),
    )


# --------------------------------------------------------------------------- the analysis's input


def read_crossplay_table(path: Path) -> Table:
    """A case folder's ``crossplay.csv`` (or ``crossplay_reference.csv``), read against
    :data:`~.schemas.CROSSPLAY_SCHEMA`; the analysis scores it
    (:func:`sumo_ayss.analysis.crossplay_scoring.score_crossplay`).

    Raises:
        TableError: If the file is missing or does not follow the schema.
    """
    return read_table(path, CROSSPLAY_SCHEMA)


@dataclass(frozen=True)
class CrossplayTables:
    """A case's cross-play files as found, stored data only: the analysis scores them
    (:func:`sumo_ayss.analysis.crossplay_scoring.crossplay_input`).

    Attributes:
        case_dir: The case folder the runs lie in, or None (several).
        path: ``crossplay.csv``, or None (not found, or the runs lie in several folders).
        table: ``crossplay.csv`` read, or None.
        missing: Why there is no table (one sentence: a file unreadable, or the runs in
            several case folders), "" with no problem.
        problem: A line for the case's problem list, or "".
        vuts: The VUTs the record says the table drove, or None (no ``crossplay.json``).
        diagonal: The record's diagonal check, ``(vut, seed, n, n_equal)`` per run.
        reference: ``crossplay_reference.csv`` read, or None.
        reference_problem: Why that file is unreadable, or "".
        inevitable: ``inevitable.json``'s ``(n, seed, indices)``, or None.
        inevitable_problem: Why that file is unreadable, or "".
    """

    case_dir: Path | None = None
    path: Path | None = None
    table: Table | None = None
    missing: str = ""
    problem: str = ""
    vuts: tuple[str, ...] | None = None
    diagonal: tuple[tuple[str, int, int, int], ...] = ()
    reference: Table | None = None
    reference_problem: str = ""
    inevitable: tuple[int, int, tuple[int, ...]] | None = None
    inevitable_problem: str = ""


def write_inevitable(
    path: Path, n: int, seed: int, ics: Sequence[bool], strategies: Sequence[str]
) -> None:
    """``inevitable.json``: the scenario set (``n`` draws of ``seed``) and the indices of its
    inevitable-collision states (:mod:`sumo_ayss.scenarios.inevitable`)."""
    write_json(
        path,
        {
            "n": int(n),
            "seed": int(seed),
            "ics": [i for i, flag in enumerate(ics) if flag],
            "strategies": list(strategies),
        },
    )


def read_inevitable(path: Path) -> tuple[int, int, tuple[int, ...]]:
    """``(n, seed, ICS scenario indices)`` of an ``inevitable.json``.

    Raises:
        TableError: If the file is missing, unreadable or malformed.
    """
    data = read_json(path)
    n = json_field(data, "n", int, str(path))
    seed = json_field(data, "seed", int, str(path))
    ics = json_field(data, "ics", list, str(path))
    if not all(isinstance(i, int) and 0 <= i < n for i in ics):
        raise TableError(f"{path}: ics must list scenario indices in [0, {n})")
    return n, seed, tuple(ics)


def load_crossplay(runs: Mapping[str, Sequence[RunRecord]]) -> CrossplayTables:
    """The cross-play files of one case's runs: ``crossplay.csv`` of the case folder they lie
    in (the parent of the VUT folders), its record's diagonal check (``crossplay.json``), the
    reference rows and the inevitable-collision states; never raises.

    Args:
        runs: ``{vut: runs}`` of one case (:func:`~.record.read_run`).

    Returns:
        The :class:`CrossplayTables`: the tables and the record's VUTs and diagonal as
        read, or why there is none (no table, runs in several case folders, an unreadable
        record or table). Whether a table may be ranked (its record drove other VUTs than
        the runs', or its diagonal did not reproduce the outcome tables) and scoring it are
        the analysis's (:func:`sumo_ayss.analysis.crossplay_scoring.crossplay_input`).
    """
    case_dirs = sorted({r.path.parent.parent for rs in runs.values() for r in rs})
    if len(case_dirs) != 1:
        folders = ", ".join(map(str, case_dirs))
        return CrossplayTables(
            missing=f"no cross-play table: the runs lie in several case folders ({folders})"
        )
    folder = CaseFolder(case_dirs[0])
    path = folder.crossplay_csv
    if not path.is_file():
        return CrossplayTables(case_dir=folder.path)
    found = CrossplayTables(case_dir=folder.path, path=path)
    if folder.crossplay_json.is_file():
        try:
            record = read_crossplay_json(folder.crossplay_json)
        except TableError as exc:
            return dataclasses.replace(
                found,
                missing=f"the cross-play record is unreadable ({exc})",
                problem=str(exc),  # names the file
            )
        diagonal = tuple((d.vut, d.seed, d.n, d.n_equal) for d in record.diagonal)
        found = dataclasses.replace(found, vuts=record.vuts, diagonal=diagonal)
    try:
        found = dataclasses.replace(found, table=read_crossplay_table(path))
    except TableError as exc:
        text = str(exc)  # a TableError names the file already
        problem = text if text.startswith(str(path)) else f"{path}: {text}"
        return dataclasses.replace(
            found, missing=f"the cross-play table is unreadable ({problem})", problem=problem
        )
    if folder.crossplay_reference_csv.is_file():
        try:
            reference = read_crossplay_table(folder.crossplay_reference_csv)
        except TableError as exc:  # the ranking stands without it
            return dataclasses.replace(found, reference_problem=f"reference rows unreadable: {exc}")
        found = dataclasses.replace(found, reference=reference)
    if folder.inevitable_json.is_file():
        try:
            return dataclasses.replace(found, inevitable=read_inevitable(folder.inevitable_json))
        except TableError as exc:
            return dataclasses.replace(found, inevitable_problem=str(exc))
    return found
