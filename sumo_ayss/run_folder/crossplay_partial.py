"""``crossplay.partial/``: the finished cells of a cross-play table not yet written whole.

The cross-play stage drives one (VUT, opponent) cell at a time, each its own fresh
simulation (:mod:`sumo_ayss.scenarios.crossplay`). A stage interrupted after some cells (a
Ctrl-C, a SIGKILL, a lost node) would otherwise start its case again from the first pair: at
32 VUTs that was six minutes lost. :class:`CellStore` keeps every finished cell as its own
file, written atomically as soon as the cell is done::

    <out>/<case>/crossplay.partial/cell_<16 hex>.csv            (the main table's cells)
    <out>/<case>/crossplay_reference.partial/cell_<16 hex>.csv  (the reference drivers')

each one :data:`~.schemas.CROSSPLAY_SCHEMA` table of the cell's rows. The file name is the
:func:`~sumo_ayss.util.fingerprint.fingerprint` of everything the cell's rows depend on (the VUT
and its env config, the opponent and the SHA-256 of its ``spcp.zip``, the scenario set, the crash
labeller), so a cell made with other inputs is never read back: it is simply not found. A
rerun reads the cells it finds and drives only the others; the rows read back are the rows
written (floats as ``repr``), so the finished table is byte-identical to an undisturbed
run's. The stage removes the folder once the whole table is written.

Imports neither SUMO nor torch.
"""

from __future__ import annotations

import logging
import shutil
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sumo_ayss.records.table import read_table, table_from_rows, write_table
from sumo_ayss.run_folder.schemas import CROSSPLAY_SCHEMA
from sumo_ayss.util.errors import TableError
from sumo_ayss.util.fingerprint import fingerprint

__all__ = ["CellStore"]

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class CellStore:
    """The finished cells of one cross-play table, one file each in ``folder``.

    Attributes:
        folder: ``<case>/crossplay.partial/`` (or the reference table's); created at the
            first cell saved.
    """

    folder: Path

    @classmethod
    def resume(cls, folder: Path, *, force: bool = False) -> CellStore:
        """The store of ``folder`` with the cells an interrupted run left there (logged);
        ``force`` drops them first (every cell is driven again)."""
        store = cls(folder)
        if force:
            store.clear()
        elif held := store.count():
            logger.info("%s: %d finished cells of an interrupted run are kept", folder, held)
        return store

    def path(self, key: Sequence[Any]) -> Path:
        """The file of the cell ``key`` (everything its rows depend on, JSON-able or
        ``str``-able, in a fixed order)."""
        return self.folder / f"cell_{fingerprint(*key)}.csv"

    def load(self, key: Sequence[Any]) -> list[dict[str, Any]] | None:
        """The rows of a finished cell, or None when it was not finished (or its file is
        unreadable: logged, and the cell is driven again)."""
        path = self.path(key)
        if not path.is_file():
            return None
        try:
            return list(read_table(path, CROSSPLAY_SCHEMA).rows())
        except TableError as exc:
            logger.warning("%s; the cell is driven again", exc)
            return None

    def save(self, key: Sequence[Any], rows: Sequence[dict[str, Any]]) -> None:
        """Write a finished cell's rows, atomically."""
        write_table(self.path(key), table_from_rows(CROSSPLAY_SCHEMA, rows))

    def count(self) -> int:
        """Finished cells held."""
        return len(list(self.folder.glob("cell_*.csv"))) if self.folder.is_dir() else 0

    def clear(self) -> None:
        """Remove the folder (the whole table has been written)."""
        shutil.rmtree(self.folder, ignore_errors=True)
