"""``crossplay.json``: the cross-play stage's record of one case, one writer and one reader.

It lies in the case folder ``<out>/<case>/`` (:class:`~.layout.CaseFolder`), beside
``crossplay.csv`` (:data:`~.schemas.CROSSPLAY_SCHEMA`, written and read with
:func:`~.table.write_table` / :func:`~.table.read_table`)::

    {"stage": "crossplay", "case": "cut_in", "n": 200, "seed": 4242,
     "opponents": [{"vut": "pi1", "seed": 0, "spcp_sha256": "..."}, ...],
     "vuts": ["pi1", "pi2"], "wall_s": 812.4, "rollout": "outcome",
     "diagonal": [{"vut": "pi1", "seed": 0, "n": 200, "n_equal": 200}, ...]}

``n`` and ``seed`` are the scenario set (:func:`~sumo_ayss.envs.odd.sample_initial_conditions`)
and, with the opponents and ``rollout``, what a rerun compares before skipping the case.
``rollout`` names how the episodes were driven: ``"outcome"`` (the outcome stage's single
env, :mod:`sumo_ayss.scenarios.crossplay`) or ``"pairs"`` (many pairs in one simulation,
how tables were made before issue 21; such a table is re-run). ``diagonal`` is the check
that each SPCP, driven against its own VUT, reproduced its run's ``outcome.csv``: per run,
how many of the ``n`` episodes were equal (absent in older records).

Imports neither SUMO nor torch.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeVar

from sumo_ayss.errors import TableError
from sumo_ayss.run_folder.jsonio import read_json, write_json

__all__ = [
    "ROLLOUT",
    "CrossplayOpponent",
    "CrossplayRecord",
    "DiagonalCheck",
    "read_crossplay_json",
    "write_crossplay_json",
]

#: How the cross-play stage drives its episodes now (see the module docstring).
ROLLOUT = "outcome"
_R = TypeVar("_R")

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
    """

    case: str
    n: int
    seed: int
    opponents: tuple[CrossplayOpponent, ...]
    vuts: tuple[str, ...]
    wall_s: float
    rollout: str = ROLLOUT
    diagonal: tuple[DiagonalCheck, ...] = ()

    def same_inputs(self, other: CrossplayRecord) -> bool:
        """Whether ``other`` ran the same scenarios against the same SPCPs the same way (a
        rerun skips)."""
        mine = (self.n, self.seed, self.opponents, self.rollout)
        return mine == (other.n, other.seed, other.opponents, other.rollout)

    def extended_by(self, other: CrossplayRecord) -> bool:
        """Whether ``other`` is this run with more opponents (same scenarios, same rollout,
        every opponent of this one among them): only the new ones need driving."""
        same = (self.n, self.seed, self.rollout) == (other.n, other.seed, other.rollout)
        return same and set(self.opponents) < set(other.opponents)


def write_crossplay_json(path: Path, record: CrossplayRecord) -> None:
    """Write ``crossplay.json``."""
    write_json(
        path,
        {
            "stage": "crossplay",
            "case": record.case,
            "n": record.n,
            "seed": record.seed,
            "opponents": [dataclasses.asdict(o) for o in record.opponents],
            "vuts": list(record.vuts),
            "wall_s": round(record.wall_s, 3),
            "rollout": record.rollout,
            "diagonal": [dataclasses.asdict(d) for d in record.diagonal],
        },
    )


def _field(data: Mapping[str, Any], key: str, kind: type | tuple[type, ...], where: str) -> Any:
    if key not in data:
        raise TableError(f"{where}: missing field {key!r}")
    value = data[key]
    if isinstance(value, bool) or not isinstance(value, kind):  # no field is a boolean
        names = " or ".join(k.__name__ for k in (kind if isinstance(kind, tuple) else (kind,)))
        raise TableError(f"{where}: {key}: expected {names}, got {value!r}")
    return value


def _records(
    data: Mapping[str, Any], key: str, where: str, cls: type[_R], kinds: tuple[type, ...]
) -> tuple[_R, ...]:
    """The list ``data[key]`` of JSON objects as ``cls`` records, field by field in the
    order of ``cls``'s dataclass fields, each checked to be of its kind."""
    out = []
    for i, item in enumerate(_field(data, key, list, where)):
        at = f"{where}: {key}[{i}]"
        if not isinstance(item, Mapping):
            raise TableError(f"{at}: expected an object, got {item!r}")
        names = [f.name for f in dataclasses.fields(cls)]  # type: ignore[arg-type]
        out.append(cls(*(_field(item, n, k, at) for n, k in zip(names, kinds, strict=True))))
    return tuple(out)


def read_crossplay_json(path: Path) -> CrossplayRecord:
    """Read ``crossplay.json``.

    Raises:
        TableError: The file is missing, not a JSON object, or a field is missing or of the
            wrong type; the message names the file and the field.
    """
    data = read_json(path)
    where = str(path)
    opponents = _records(data, "opponents", where, CrossplayOpponent, (str, int, str))
    vuts = _field(data, "vuts", list, where)
    if not all(isinstance(v, str) for v in vuts):
        raise TableError(f"{where}: vuts: expected a list of names, got {vuts!r}")
    diagonal = (
        _records(data, "diagonal", where, DiagonalCheck, (str, int, int, int))
        if "diagonal" in data
        else ()  # a record from before the check
    )
    rollout = data.get("rollout", _LEGACY_ROLLOUT)
    if not isinstance(rollout, str):
        raise TableError(f"{where}: rollout: expected str, got {rollout!r}")
    return CrossplayRecord(
        case=_field(data, "case", str, where),
        n=_field(data, "n", int, where),
        seed=_field(data, "seed", int, where),
        opponents=opponents,
        vuts=tuple(vuts),
        wall_s=float(_field(data, "wall_s", (int, float), where)),
        rollout=rollout,
        diagonal=diagonal,
    )
