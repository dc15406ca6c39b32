"""Leaderboard: train SPCPs for K VUTs through the pipeline and rank them by safety.

    python -m sumo_ayss.rank configs/ladders/min_gap.yaml [--seeds 100 101 102] [--out DIR]

The config is a pipeline YAML (:mod:`sumo_ayss.pipeline`) whose ``grid.vuts`` lists the
VUTs to rank (catalog models from the experiments' ``env.vuts`` or the pipeline's own
``vuts`` section). After the grid (resumable: finished jobs are skipped), this writes
``<out>/ranking.csv`` and ``<out>/ranking.md`` (per case and mode: rank, VUT, score with
its interval, seeds or blocks, and the verdict against the next VUT) and the HTML report,
and prints the table. With ``expected_order`` (a known safety order, e.g. a ladder), it also
writes ``<out>/order_check.json``: per case and mode, Kendall's τ of the ranking against it,
whether the two ends differ significantly, and how many adjacent pairs do.

The mode (``report.mode`` or ``--mode``, one of :mod:`sumo_ayss.modes`) decides which
rows come first and which ranking the report's verdicts use; the rows of every other mode
available for a case follow, each tagged with its mode:

* ``crossplay`` (default): the pipeline then runs every SPCP of a case against every VUT
  (:mod:`sumo_ayss.crossplay`) and ranks by the mean harm per episode the pooled SPCPs bring
  about (:mod:`sumo_ayss.analysis.harm`; lower = safer), a paired t-test over training-seed
  blocks; available wherever ``<out>/<case>/crossplay.csv`` exists;
* ``exposure`` (always available): the mean harm per episode of each VUT's own SPCPs
  (lower = safer), a paired t-test over shared seeds;
* ``paper`` (in paper mode only, the AYSS bootstrap is slow): the paper's AYSS
  aggressiveness index (:func:`sumo_ayss.analysis.ranking.safety_index`).

After the pipeline, the rows come from the analyses the pipeline computed for its report
(:class:`sumo_ayss.pipeline.PipelineResult`): no run folder is read and no bootstrap drawn
again. ``--no-run`` ranks existing run folders (each read once, each case analysed once,
the bootstrap only in paper mode) and never runs cross-play.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from sumo_ayss.analysis.case import CaseAnalysis
from sumo_ayss.analysis.seeds import kendall_tau
from sumo_ayss.modes import (
    Mode,
    analyse_cases,
    check_mode,
    get_mode,
    registered_modes,
)
from sumo_ayss.modes.formatting import fmt_num
from sumo_ayss.run_folder import (
    OrderCheck,
    OrderChecks,
    RunRecord,
    StudyFolder,
    case_runs,
    read_run,
    write_order_check,
    write_ranking_csv,
)

if TYPE_CHECKING:
    from sumo_ayss.analysis.harm import VutOutcome
    from sumo_ayss.config.report import ReportOptions

__all__ = [
    "analyse",
    "analyse_loaded",
    "available_modes",
    "order_check",
    "order_checks",
    "ranking_rows",
    "write_ranking",
]


def analyse(
    run_dirs: Sequence[Path], options: ReportOptions | None = None
) -> list[CaseAnalysis[RunRecord]]:
    """The analysis of every case among ``run_dirs``, for ranking without the pipeline.

    Each run folder is read once (:func:`sumo_ayss.run_folder.read_run`) and each case
    analysed once (:func:`sumo_ayss.modes.analyse_cases`); the AYSS bootstrap runs in
    paper mode only.
    """
    return analyse_loaded([read_run(d) for d in run_dirs], options)


def analyse_loaded(
    runs: Sequence[RunRecord], options: ReportOptions | None = None
) -> list[CaseAnalysis[RunRecord]]:
    """:func:`analyse` of runs already loaded."""
    from sumo_ayss.config.report import ReportOptions

    options = options or ReportOptions()
    # The AYSS bootstrap only where the mode ranks by the safety index.
    paper = check_mode(options.mode).needs_safety_index
    return analyse_cases(case_runs(runs), options, paper=paper)


def available_modes(a: CaseAnalysis[RunRecord]) -> list[str]:
    """The modes with a ranking for this case (:attr:`~sumo_ayss.modes.Mode.available`),
    the analysis's own mode first, then the others in registry order.
    """
    have = [m.name for m in registered_modes() if m.available(a)]
    return sorted(have, key=lambda m: m != a.mode)


def _rows(a: CaseAnalysis[RunRecord], mode: Mode) -> list[dict[str, Any]]:
    """The ``ranking.csv`` rows of one case in one mode, with crashes and mobility where
    the mode reads outcomes (:meth:`~sumo_ayss.modes.Mode.outcomes`)."""
    outcomes = mode.outcomes(a)
    unit = mode.unit(a)
    rows = []
    for s in mode.standings(a):
        o = outcomes.get(s.vut)
        rows.append(
            {
                "case": a.case,
                "mode": mode.name,
                "rank": s.rank,
                "vut": s.vut,
                "score": s.score,
                "lo": s.lo,
                "hi": s.hi,
                "n_seeds": s.n_seeds,
                "unit": unit,
                "p_vs_next": s.p if s.p is not None else "",
                "significant_vs_next": s.significant if s.significant is not None else "",
                "vs_next": s.vs_next,
                "crash_rate": o.crash_rate if o else "",
                "crash_lo": o.crash_lo if o else "",
                "crash_hi": o.crash_hi if o else "",
                "crashes": o.crashes if o else "",
                "episodes": o.episodes if o else "",
                "mobility_mps": o.mobility if o else "",
                "timid": o.timid if o else "",
                "p_vs_next_adjusted": s.p_adjusted if s.p_adjusted is not None else "",
                "margin_vs_next": _finite_or_empty(s.margin),
                "margin_lo": _finite_or_empty(s.margin_lo),
                "margin_hi": _finite_or_empty(s.margin_hi),
                **_hazard_cells(o),
            }
        )
    return rows


def _hazard_cells(o: VutOutcome | None) -> dict[str, Any]:
    """The ``ranking.csv`` hazard cells of a VUT (:data:`~sumo_ayss.run_folder.
    RANKING_HAZARD_COLUMNS`; none where not recorded, so the file keeps its old columns)."""
    h = None if o is None else o.hazards
    if o is None or h is None or not math.isfinite(h.get("unjustified_braking", math.nan)):
        return {}
    return {
        "unjustified_braking_rate": h["unjustified_braking"],
        "unjustified_dv_mps": h["unjustified_dv_mps"],
        "rear_end_rate": _finite_or_empty(h.get("rear_end", math.nan)),
        "rear_end_caused_rate": _finite_or_empty(h.get("rear_end_unjustified", math.nan)),
        "follower_max_braking_mps2": _finite_or_empty(h.get("follower_max_braking_mps2", math.nan)),
        "overbraking": o.overbraking,
    }


def _finite_or_empty(x: float) -> float | str:
    """A number for a ``ranking.csv`` cell; "" for NaN (no value)."""
    return x if math.isfinite(x) else ""


def ranking_rows(analyses: Sequence[CaseAnalysis[RunRecord]]) -> list[dict[str, Any]]:
    """Ranking rows of every case, for every mode available (:func:`available_modes`: the
    analysis's mode first), safest first within a (case, mode); ``mode`` tags each row.

    Cross-play mode: H, the mean harm per episode the pooled SPCPs bring about (lower =
    safer). Exposure mode: the mean harm per episode of each VUT's own SPCPs (lower = safer).
    Paper mode: the AYSS safety index (higher = safer).
    """
    rows: list[dict[str, Any]] = []
    for a in analyses:
        for mode in available_modes(a):
            rows += _rows(a, get_mode(mode))
    return rows


def order_check(
    a: CaseAnalysis[RunRecord], expected: Sequence[str], mode: str | None = None
) -> OrderCheck | None:
    """How one case's ranking in one mode compares with a known order (safest first).

    Args:
        a: The case's analysis.
        expected: The known order, safest first.
        mode: The mode whose ranking is checked; default the analysis's mode.

    Returns:
        The :class:`~sumo_ayss.run_folder.OrderCheck` (Kendall τ of the ranking against
        the known order; whether the expected safest and least safe VUT differ
        significantly, in the right direction; significant adjacent pairs of the ranking),
        or None when the mode has no ranking for this case or the case's VUTs are not
        exactly the expected ones.
    """
    mode = mode or a.mode
    if mode not in available_modes(a):
        return None
    standings = get_mode(mode).standings(a)
    order = [s.vut for s in standings]
    sig = [s.ranked_apart for s in standings[:-1]]
    if sorted(order) != sorted(expected) or len(order) < 2:
        return None
    ends_ok, ends_p = get_mode(mode).ends(a, expected[0], expected[-1])
    return OrderCheck(
        case=a.case,
        mode=mode,
        order=tuple(order),
        expected=tuple(expected),
        tau=kendall_tau(order, list(expected)),
        ends_significant=ends_ok,
        ends_p=ends_p,
        significant_adjacent=sum(sig),
        adjacent=len(sig),
    )


def order_checks(
    analyses: Sequence[CaseAnalysis[RunRecord]], expected: Sequence[str]
) -> list[OrderCheck]:
    """:func:`order_check` of every (case, mode) available, the analysis's mode first."""
    return [
        c
        for a in analyses
        for mode in available_modes(a)
        if (c := order_check(a, expected, mode)) is not None
    ]


def write_ranking(
    rows: Sequence[dict[str, Any]],
    out: Path,
    checks: Sequence[OrderCheck] = (),
    expected: Sequence[str] = (),
    notes: Sequence[str] = (),
) -> tuple[Path, Path]:
    """``ranking.csv`` and ``ranking.md`` in the study folder ``out`` (written atomically),
    and with a known order, ``order_check.json`` (see :func:`order_check`;
    :mod:`sumo_ayss.run_folder.study`). ``notes``: more ``ranking.md`` lines (the VUTs
    against the careful human)."""
    from sumo_ayss.util.atomic import atomic_write_text

    study = StudyFolder(out)
    write_ranking_csv(study.ranking_csv, rows)
    hazards = any(r.get("unjustified_braking_rate", "") != "" for r in rows)
    extra = " unjustified braking | hazards caused |" if hazards else ""
    lines = [
        "| case | mode | rank | VUT | score (95 % CI) | seeds | crash rate (95 % CI) | "
        "mean speed | vs next |" + extra,
        "|---|---|---:|---|---|---:|---|---|---|" + ("---|---|" if hazards else ""),
    ]
    labels, lines_of = _tie_labels(rows)
    for i, r in enumerate(rows):
        mode = get_mode(r["mode"])
        digits = mode.digits
        ci = mode.interval_text(r["lo"], r["hi"], r["n_seeds"], digits)
        ci = f" ({ci})" if ci else ""
        lines.append(
            f"| {r['case']} | {r['mode']} | {labels[i]} | {r['vut']} | "
            f"{fmt_num(r['score'], digits)}{ci} {r['unit']} | {r['n_seeds']} | {_crash_cell(r)} | "
            f"{_mobility_cell(r)} | {r['vs_next']} |"
            + (f" {_unjustified_cell(r)} | {_hazards_cell(r)} |" if hazards else "")
        )
    for c in checks:
        lines += [
            "",
            f"Known order ({c.case}, {c.mode} mode), safest first: "
            f"{' > '.join(expected)}. Ranking: "
            f"{lines_of.get((c.case, c.mode), ' > '.join(c.order))}. "
            f"Kendall tau = {c.tau:.2f}; ends significantly different: "
            f"{'yes' if c.ends_significant else 'no'} (p = {c.ends_p:.3g}); "
            f"significant adjacent pairs: {c.significant_adjacent} of {c.adjacent}.",
        ]
    lines += notes
    atomic_write_text(study.ranking_md, "\n".join(lines) + "\n")
    if checks:
        write_order_check(study.order_check_json, OrderChecks(tuple(expected), tuple(checks)))
    return study.ranking_csv, study.ranking_md


def _tie_labels(
    rows: Sequence[dict[str, Any]],
) -> tuple[list[str], dict[tuple[str, str], str]]:
    """Per row its rank as ``ranking.md`` shows it (a tie shares one, ``"2–3"``), and per
    (case, mode) its ranking line (``"a > b ≈ c"``), from ``significant_vs_next``."""
    from sumo_ayss.modes.formatting import rank_labels, ranking_line

    groups: dict[tuple[str, str], list[int]] = {}
    for i, r in enumerate(rows):
        groups.setdefault((r["case"], r["mode"]), []).append(i)
    labels = [""] * len(rows)
    lines: dict[tuple[str, str], str] = {}
    for key, idx in groups.items():
        sig = [rows[i]["significant_vs_next"] in (True, "True") for i in idx[:-1]]
        for i, label in zip(idx, rank_labels(sig), strict=True):
            labels[i] = label
        lines[key] = ranking_line([rows[i]["vut"] for i in idx], sig)
    return labels, lines


def _crash_cell(row: dict[str, Any]) -> str:
    """The crash rate of a ``ranking.csv`` row as the report writes it; "" in paper mode."""
    from sumo_ayss.modes.formatting import crash_text

    if row["crashes"] == "":
        return ""
    return crash_text(row["crashes"], row["episodes"], row["crash_lo"], row["crash_hi"])


def _mobility_cell(row: dict[str, Any]) -> str:
    """The mobility of a ``ranking.csv`` row as the report writes it; "" in paper mode."""
    from sumo_ayss.modes.formatting import mobility_text

    return "" if row["mobility_mps"] == "" else mobility_text(row["mobility_mps"], row["timid"])


def _unjustified_cell(row: dict[str, Any]) -> str:
    """``"52 %, 1.1 m/s (OVER-BRAKING)"``: episodes with unjustified hard braking, the speed
    shed so per episode, the flag; "" where not recorded."""
    if row.get("unjustified_braking_rate", "") == "":
        return ""
    flag = " (OVER-BRAKING)" if row.get("overbraking") in (True, "True") else ""
    rate, dv = float(row["unjustified_braking_rate"]), float(row["unjustified_dv_mps"])
    return f"{100 * rate:.0f} %, {dv:.2f} m/s{flag}"


def _hazards_cell(row: dict[str, Any]) -> str:
    """``"rear-ends 0.0 % (caused 0.0 %), follower 4.1 m/s²"``; "" where not recorded."""
    if row.get("rear_end_rate", "") == "":
        return ""
    rear, caused = float(row["rear_end_rate"]), float(row["rear_end_caused_rate"])
    brake = float(row["follower_max_braking_mps2"])
    return f"rear-ends {100 * rear:.1f} % (caused {100 * caused:.1f} %), follower {brake:.1f} m/s²"


if __name__ == "__main__":  # python -m sumo_ayss.rank: the command (sumo_ayss.commands)
    from sumo_ayss.commands.rank import main

    main()
