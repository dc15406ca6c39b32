"""Safety measures of a case's opponent pool: loading, and ``measures.csv`` (issue 27).

The pool is the case's cross-play table where there is one (every opponent SPCP against
every VUT: the bootstrap's unit is the opponent), else each VUT's own SPCPs' outcome
tables (the unit is the training seed). Files written before the measure columns hold NaN
there: the pool is then reported as "not recorded" (rerun the outcome stage, or
``scripts/add_measures.py``, and cross-play).

``<out>/measures.csv`` (written by ``rank`` beside ``ranking.csv``): one row per (case,
measure, VUT) — the median with its interval, the 10th and 90th percentiles, the share of
infinite values, the VUT's rank by that measure alone, its rank in the primary ranking and
Kendall's τ between the two orders — and per VUT the R157 cut-in share
(:mod:`sumo_ayss.analysis.r157`) as measure ``r157_handled_share``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from sumo_ayss.analysis.case import CaseAnalysis
from sumo_ayss.analysis.measure_ranking import (
    MEASURES,
    MeasureRanking,
    R157Row,
    measure_rankings,
    r157_rows,
)
from sumo_ayss.analysis.r157 import R157_TIME_MARGIN_S, R157_TIME_S, must_avoid_column
from sumo_ayss.modes import CROSSPLAY, EXPOSURE
from sumo_ayss.modes.crossplay import crossplay_result
from sumo_ayss.modes.exposure import exposure_result
from sumo_ayss.records.table import read_table
from sumo_ayss.run_folder import CROSSPLAY_SCHEMA, RunRecord, StudyFolder, write_measures_csv
from sumo_ayss.util.errors import AyssError

__all__ = ["CaseMeasures", "case_measures", "write_measures"]


@dataclass(frozen=True)
class CaseMeasures:
    """A case's measures under its pool.

    Attributes:
        case: The case.
        pool: ``"cross-play"`` or ``"own SPCPs"``.
        vuts: The VUTs, in the primary order where there is one.
        primary_mode: The mode of the primary ranking (``crossplay``/``exposure``).
        primary_order: The primary ranking, safest first.
        rankings: One per measure (:func:`~sumo_ayss.analysis.measure_ranking.
            measure_rankings`).
        r157: The R157 cut-in share per VUT with the constant ``r157_time_s`` (cut-in only,
            else empty).
        values: ``{measure column: {vut: defined values}}`` for the figure (∞ kept: the
            medians count it).
        r157_time_s: The constant term [s] of R157's condition behind ``r157``.
        r157_alt_s: The other constant shown beside it (0.45 s for 0.35 s, and back).
        r157_alt: The share with ``r157_alt_s``; empty where the tables do not hold the
            closing speed at the intrusion (written before ``r157_closing_mps``).
        primary_apart: Per adjacent pair of ``primary_order``, whether the primary mode's
            family-adjusted test separates them (a tie where not).
    """

    case: str
    pool: str
    vuts: tuple[str, ...]
    primary_mode: str
    primary_order: tuple[str, ...]
    rankings: tuple[MeasureRanking, ...]
    r157: tuple[R157Row, ...]
    values: dict[str, dict[str, np.ndarray]]
    r157_time_s: float = R157_TIME_S
    r157_alt_s: float = R157_TIME_MARGIN_S
    r157_alt: tuple[R157Row, ...] = ()
    primary_apart: tuple[bool, ...] = ()


def _primary(a: CaseAnalysis[RunRecord]) -> tuple[str, tuple[str, ...]]:
    crossplay = crossplay_result(a).rows
    if crossplay:
        return CROSSPLAY.name, tuple(r.name for r in crossplay)
    return EXPOSURE.name, tuple(r.name for r in exposure_result(a).rows)


def _pool_columns(a: CaseAnalysis[RunRecord]) -> tuple[str, dict[str, np.ndarray]] | None:
    """The pool's episodes: vut, group (the bootstrap unit), collided and the measures."""
    pool = crossplay_result(a).path
    if pool is not None and pool.is_file():
        t = read_table(pool, CROSSPLAY_SCHEMA)
        group = np.char.add(
            np.char.add(t["opponent_vut"].astype(str), "/"), t["opponent_seed"].astype(str)
        )
        cols = {"vut": t["vut"].astype(str), "group": group, "collided": t["collided"]}
        return "cross-play", {**cols, **{n: t[n] for n in _measure_columns()}}
    parts: list[dict[str, np.ndarray]] = []
    for vut, runs in a.runs.items():
        for run in runs:
            table = run.outcome_table
            if table is None:  # missing or unreadable: the run's problems say which
                continue
            n = len(table)
            part = {"vut": np.full(n, vut), "group": np.full(n, str(run.seed))}
            part["collided"] = table["collided"]
            parts.append({**part, **{c: table[c] for c in _measure_columns()}})
    if not parts:
        return None
    return "own SPCPs", {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}


def _measure_columns() -> list[str]:
    return [m.column for m in MEASURES] + [
        "r157_must_avoid",
        "r157_ttc_lane_intrusion_s",
        "r157_closing_mps",
    ]


def case_measures(
    a: CaseAnalysis[RunRecord], *, level: float = 0.95, r157_time_s: float = R157_TIME_S
) -> CaseMeasures | str:
    """The measures of case ``a``, or one sentence saying why there are none.

    ``r157_time_s``: the constant term of R157's cut-in condition (``report.r157_time_s``);
    the share is also computed with the other of 0.35 s / 0.45 s where the tables hold the
    closing speed (:attr:`CaseMeasures.r157_alt`).
    """
    try:
        found = _pool_columns(a)
    except AyssError as e:
        return f"the episode tables could not be read ({e})"
    if found is None:
        return "no outcome or cross-play table was found"
    pool, cols = found
    if all(np.isnan(cols[m.column]).all() for m in MEASURES):
        return (
            f"the {pool} tables were written before the measures were recorded (rerun the "
            "outcome stage and cross-play, or scripts/add_measures.py)"
        )
    mode, order = _primary(a)
    vuts = tuple(dict.fromkeys([*order, *a.runs]))
    rankings = measure_rankings(
        cols["vut"],
        cols["group"],
        {m.column: cols[m.column] for m in MEASURES},
        vuts=vuts,
        primary_order=order,
        level=level,
    )
    r157: tuple[R157Row, ...] = ()
    r157_alt: tuple[R157Row, ...] = ()
    alt_s = R157_TIME_MARGIN_S if r157_time_s == R157_TIME_S else R157_TIME_S
    for time_s in (r157_time_s, alt_s):
        must = must_avoid_column(
            cols["r157_ttc_lane_intrusion_s"],
            cols["r157_closing_mps"],
            cols["r157_must_avoid"],
            time_s,
        )
        if np.isnan(must).all():
            continue
        rows = tuple(r157_rows(cols["vut"], must, cols["collided"], vuts=vuts, level=level))
        if time_s == r157_time_s:
            r157 = rows
        else:
            r157_alt = rows
    values = {
        m.column: {v: cols[m.column][(cols["vut"] == v) & ~np.isnan(cols[m.column])] for v in vuts}
        for m in MEASURES
    }
    return CaseMeasures(
        a.case,
        pool,
        vuts,
        mode,
        order,
        tuple(rankings),
        r157,
        values,
        r157_time_s,
        alt_s,
        r157_alt,
        _primary_apart(a, mode),
    )


def _primary_apart(a: CaseAnalysis[RunRecord], mode: str) -> tuple[bool, ...]:
    """Per adjacent pair of the primary ranking, whether its (family-adjusted) test
    separates them."""
    rows = crossplay_result(a).rows if mode == CROSSPLAY.name else exposure_result(a).rows
    return tuple(bool(r.significant_vs_next) for r in rows[:-1])


def _rows(m: CaseMeasures) -> list[dict[str, object]]:
    rows: list[dict[str, object]] = []
    primary = {v: i + 1 for i, v in enumerate(m.primary_order)}
    for r in m.rankings:
        for s in r.rows:
            rows.append(
                {
                    "case": m.case,
                    "pool": m.pool,
                    "measure": r.spec.column,
                    "unit": r.spec.unit,
                    "higher_is_safer": r.spec.higher_is_safer,
                    "vut": s.vut,
                    "rank": s.rank or "",
                    "median": s.median,
                    "lo": s.lo,
                    "hi": s.hi,
                    "p10": s.p10,
                    "p90": s.p90,
                    "share_inf": s.share_inf,
                    "n": s.n,
                    "n_total": s.n_total,
                    "primary_mode": m.primary_mode,
                    "primary_rank": primary.get(s.vut, ""),
                    "tau_vs_primary": r.tau,
                }
            )
    for q in m.r157:
        rows.append(
            {
                "case": m.case,
                "pool": m.pool,
                "measure": "r157_handled_share",
                "unit": "-",
                "higher_is_safer": True,
                "vut": q.vut,
                "rank": "",
                "median": q.share,
                "lo": q.lo,
                "hi": q.hi,
                "p10": math.nan,
                "p90": math.nan,
                "share_inf": math.nan,
                "n": q.n_required,
                "n_total": q.n_intrusions,
                "primary_mode": m.primary_mode,
                "primary_rank": primary.get(q.vut, ""),
                "tau_vs_primary": math.nan,
            }
        )
    return rows


def write_measures(out: Path, analyses: Sequence[CaseAnalysis[RunRecord]]) -> Path | None:
    """``<out>/measures.csv`` of every case with recorded measures
    (:func:`~sumo_ayss.run_folder.write_measures_csv`); None if none."""
    rows: list[dict[str, object]] = []
    for a in analyses:
        m = case_measures(a)
        if isinstance(m, CaseMeasures):
            rows += _rows(m)
    if not rows:
        return None
    path = StudyFolder(out).measures_csv
    write_measures_csv(path, rows)
    return path
