"""The study folder: the files a pipeline or ``rank`` writes beside the case folders.

A study folder ``<out>/`` (a pipeline's ``out``) holds the case folders
``<out>/<case>/`` (:class:`~.layout.CaseFolder`: cross-play, discriminability) and these
files, each with one writer and one reader here:

======================  ================================  ====================================
file                    writer / reader                   what
======================  ================================  ====================================
``pipeline.json``       write_/read_pipeline_json         the resolved pipeline configuration
``ranking.csv``         write_/read_ranking_csv           one row per (case, mode, VUT)
                        (:data:`RANKING_COLUMNS`)
``ranking.md``          (``rank``'s own words)            the same rows as a Markdown table
``order_check.json``    write_/read_order_check           the ranking against a known order
``measures.csv``        write_/read_measures_csv          one row per (case, measure, VUT)
                        (:data:`MEASURES_COLUMNS`)
``report/``             (the report)                      ``report.html``, ``summary.md``
======================  ================================  ====================================

Every file is written atomically. The CSV files are read by the one CSV reader
(:func:`~sumo_ayss.records.table.read_table`) with a schema of text columns: the cells as
written, so a script that writes a file back (``scripts/keep_paper_rows.py``) keeps every
digit.
Imports neither SUMO nor torch.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sumo_ayss.records.jsonio import json_list, json_records, read_json
from sumo_ayss.records.table import read_table, text_schema, write_rows
from sumo_ayss.run_folder.layout import (
    CaseFolder,
    FolderFile,
    RunFolder,
)
from sumo_ayss.util.atomic import atomic_write_json

__all__ = [
    "MEASURES_COLUMNS",
    "RANKING_COLUMNS",
    "RANKING_HAZARD_COLUMNS",
    "OrderCheck",
    "OrderChecks",
    "StudyFolder",
    "read_measures_csv",
    "read_order_check",
    "read_pipeline_json",
    "read_ranking_csv",
    "write_measures_csv",
    "write_order_check",
    "write_pipeline_json",
    "write_ranking_csv",
]

RANKING_COLUMNS = (
    "case",
    "mode",
    "rank",
    "vut",
    "score",
    "lo",
    "hi",
    "n_seeds",
    "unit",
    "p_vs_next",
    "significant_vs_next",
    "vs_next",
    "crash_rate",
    "crash_lo",
    "crash_hi",
    "crashes",
    "episodes",
    "mobility_mps",
    "timid",
    "p_vs_next_adjusted",
    "margin_vs_next",
    "margin_lo",
    "margin_hi",
)
"""``ranking.csv``'s columns. ``score``: harm per episode in cross-play and exposure mode
(:mod:`sumo_ayss.analysis.harm`, lower = safer), the AYSS safety index in paper mode (higher
= safer); ``lo``/``hi`` its interval, ``n_seeds`` the seeds or blocks behind it;
``p_vs_next`` (the test's raw p), ``p_vs_next_adjusted`` (adjusted for the ranking's family
of claims: Holm over the adjacent pairs, :mod:`sumo_ayss.analysis.multiplicity`; it decides
``significant_vs_next``) and ``vs_next`` (a sentence) compare the VUT with the next one;
``margin_vs_next`` is how much safer it is than the next (the paired difference the test is
about, score unit, positive = safer) with its interval ``margin_lo``/``margin_hi`` (empty
where the seeds cannot support one). ``crash_rate`` with its Wilson interval
``crash_lo``/``crash_hi`` (fractions), ``crashes`` of ``episodes``, ``mobility_mps`` (mean
VUT speed, m/s) and ``timid`` (mobility below 80 % of the median VUT's) describe the same
episodes as the score; empty in paper mode."""

RANKING_HAZARD_COLUMNS = (
    "unjustified_braking_rate",
    "unjustified_dv_mps",
    "rear_end_rate",
    "rear_end_caused_rate",
    "follower_max_braking_mps2",
    "overbraking",
)
"""``ranking.csv``'s hazard columns (issue 33; :mod:`sumo_ayss.analysis.hazards`), written
after :data:`RANKING_COLUMNS` only where a study recorded hazards (a follower behind the
VUT), so a study without them keeps its file byte for byte: per VUT over the same episodes
as the score, the share of episodes with unjustified hard braking, the speed shed so per
episode [m/s], the share of rear-ends, of rear-ends it caused, the follower's mean largest
braking [m/s²], and the OVER-BRAKING flag. Empty for a row without them (paper mode)."""

_RANKING_ADDED = RANKING_COLUMNS[RANKING_COLUMNS.index("crash_rate") :]
"""The columns a ``ranking.csv`` written before crashes and mobility (and, later, the
family-adjusted p and the margin against the next VUT) were recorded lacks."""

MEASURES_COLUMNS = (
    "case",
    "pool",
    "measure",
    "unit",
    "higher_is_safer",
    "vut",
    "rank",
    "median",
    "lo",
    "hi",
    "p10",
    "p90",
    "share_inf",
    "n",
    "n_total",
    "primary_mode",
    "primary_rank",
    "tau_vs_primary",
)
"""``measures.csv``'s columns: per (case, measure, VUT) the median with its interval
(``lo``, ``hi``), the 10th and 90th percentiles, the share of infinite values, ``n`` finite
of ``n_total`` values, the VUT's ``rank`` by that measure alone, its ``primary_rank`` in the
``primary_mode``'s ranking and Kendall's τ between the two orders (``tau_vs_primary``);
``pool`` is ``cross-play`` or ``own SPCPs``; units as in ``unit``."""


@dataclass(frozen=True)
class StudyFolder:
    """The paths of a study folder's own files.

    Attributes:
        path: The study folder ``<out>/`` (a pipeline's ``out``).
    """

    path: Path

    def __post_init__(self) -> None:
        object.__setattr__(self, "path", Path(self.path))

    #: The resolved pipeline configuration (paths relative to the study folder).
    pipeline_json = FolderFile("pipeline.json")
    #: One row per (case, mode, VUT), safest first (:data:`RANKING_COLUMNS`).
    ranking_csv = FolderFile("ranking.csv")
    #: The ranking as a Markdown table, with the known-order check in words.
    ranking_md = FolderFile("ranking.md")
    #: Per (case, mode), the ranking against a known order (:class:`OrderCheck`).
    order_check_json = FolderFile("order_check.json")
    #: One row per (case, measure, VUT): the safety measures (:data:`MEASURES_COLUMNS`).
    measures_csv = FolderFile("measures.csv")
    #: The HTML and Markdown report.
    report_dir = FolderFile("report")

    def case(self, case: str) -> CaseFolder:
        """The case folder ``<out>/<case>/``."""
        return CaseFolder(self.path / case)

    def run(self, case: str, vut: str, seed: int) -> RunFolder:
        """The run folder ``<out>/<case>/<vut>/seed_<seed>/``."""
        return RunFolder(self.path / case / vut / f"seed_{seed}")


# --------------------------------------------------------------------------- pipeline.json


def write_pipeline_json(path: Path, config: Mapping[str, Any]) -> None:
    """Write ``pipeline.json``: the resolved pipeline configuration as a JSON object."""
    atomic_write_json(path, dict(config))


def read_pipeline_json(path: Path) -> dict[str, Any]:
    """Read ``pipeline.json``.

    Raises:
        TableError: The file is missing, not JSON or not an object (naming the file).
    """
    return read_json(path)


# --------------------------------------------------------------------------- CSV tables


def write_ranking_csv(path: Path, rows: Sequence[Mapping[str, Any]]) -> None:
    """Write ``ranking.csv`` (:data:`RANKING_COLUMNS`, then :data:`RANKING_HAZARD_COLUMNS`
    where a row has one; a missing cell is written empty)."""
    if any(r.get(c, "") != "" for r in rows for c in RANKING_HAZARD_COLUMNS):
        write_rows(path, RANKING_COLUMNS + RANKING_HAZARD_COLUMNS, rows)
        return
    bare = [{k: v for k, v in r.items() if k not in RANKING_HAZARD_COLUMNS} for r in rows]
    write_rows(path, RANKING_COLUMNS, bare)


def read_ranking_csv(path: Path) -> list[dict[str, str]]:
    """Read ``ranking.csv``: one ``{column: cell}`` per row of :data:`RANKING_COLUMNS`,
    cells as written. A file written before the crash and mobility columns existed (e.g.
    ``results/sensitivity_actuator``) has them empty; one without hazards has
    :data:`RANKING_HAZARD_COLUMNS` empty.

    Raises:
        TableError: The file is missing or unreadable, lacks a column of
            :data:`RANKING_COLUMNS` up to ``vs_next`` or has one of none, or has a row of
            the wrong length (naming the file and the row).
    """
    columns = RANKING_COLUMNS + RANKING_HAZARD_COLUMNS
    added = _RANKING_ADDED + RANKING_HAZARD_COLUMNS
    schema = text_schema(StudyFolder.ranking_csv.name, columns, added)
    return list(read_table(path, schema).rows())


def write_measures_csv(path: Path, rows: Sequence[Mapping[str, Any]]) -> None:
    """Write ``measures.csv`` (:data:`MEASURES_COLUMNS`)."""
    write_rows(path, MEASURES_COLUMNS, rows)


def read_measures_csv(path: Path) -> list[dict[str, str]]:
    """Read ``measures.csv``: one ``{column: cell}`` per row, cells as written.

    Raises:
        TableError: As :func:`read_ranking_csv`, for :data:`MEASURES_COLUMNS`.
    """
    schema = text_schema(StudyFolder.measures_csv.name, MEASURES_COLUMNS)
    return list(read_table(path, schema).rows())


# --------------------------------------------------------------------------- order_check.json


@dataclass(frozen=True)
class OrderCheck:
    """One case's ranking in one mode against a known order (safest first).

    Attributes:
        case: The case.
        mode: The ranking mode.
        order: The ranking, safest first.
        expected: The known order, safest first.
        tau: Kendall's τ of ``order`` against ``expected``, in [-1, 1].
        ends_significant: Whether the expected safest and least safe VUT differ
            significantly, in the right direction.
        ends_p: The p-value of that test.
        significant_adjacent: Adjacent pairs of the ranking that differ significantly.
        adjacent: Adjacent pairs of the ranking.
    """

    case: str
    mode: str
    order: tuple[str, ...]
    expected: tuple[str, ...]
    tau: float
    ends_significant: bool
    ends_p: float
    significant_adjacent: int
    adjacent: int


@dataclass(frozen=True)
class OrderChecks:
    """``order_check.json``: the known order and every (case, mode) checked against it."""

    expected: tuple[str, ...]
    cases: tuple[OrderCheck, ...]


def write_order_check(path: Path, checks: OrderChecks) -> None:
    """Write ``order_check.json``."""
    cases = []
    for c in checks.cases:
        data = dataclasses.asdict(c)
        data["order"], data["expected"] = list(c.order), list(c.expected)
        cases.append(data)
    atomic_write_json(path, {"expected": list(checks.expected), "cases": cases})


def read_order_check(path: Path) -> OrderChecks:
    """Read ``order_check.json``.

    Raises:
        TableError: The file is missing, not a JSON object, or a field is missing or of the
            wrong type; the message names the file and the field.
    """
    data = read_json(path)
    where = str(path)
    return OrderChecks(
        json_list(data, "expected", str, where), json_records(data, "cases", OrderCheck, where)
    )
