"""Blocks of the outcome of the SPCPs: (d) outcome table, (e) premise check, (f) exposure."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from sumo_ayss.analysis.case import CaseAnalysis
from sumo_ayss.analysis.premise import Premise
from sumo_ayss.cases import OUTCOME_COLUMNS
from sumo_ayss.config.report import ReportOptions
from sumo_ayss.modes import EXPOSURE
from sumo_ayss.modes.exposure import exposure_result, exposure_sentence
from sumo_ayss.modes.formatting import fmt_num, seed_interval_text
from sumo_ayss.modes.paper import paper_result
from sumo_ayss.report.blocks import (
    Block,
    BulletList,
    Callout,
    FigureBlock,
    Heading,
    Paragraph,
    Table,
)
from sumo_ayss.report.sections.common import (
    TIMID_NOTE,
    crash_cell,
    fmt_est,
    mobility_cell,
    pairs_table,
    test_cell,
)
from sumo_ayss.report.seed_figure import seed_scores_figure
from sumo_ayss.run_folder import Outcome, RunRecord

__all__ = ["exposure_blocks", "outcome_blocks", "premise_blocks"]


def _outcome_cells(o: Outcome) -> dict[str, str]:
    """Every column of :data:`~sumo_ayss.cases.OUTCOME_COLUMNS` for one SPCP's outcome."""
    sub = o.lane_change_no_collision
    return {
        "crash": fmt_est(o.crash_rate, 1, 100.0),
        "lane_change": fmt_est(o.lane_change_rate, 1, 100.0),
        "lc_return": fmt_est(sub.mean_return if sub else None),
        "lc_headway": fmt_est(sub.mean_final_headway_m if sub else None),
        "lc_episodes": str(sub.n) if sub and sub.n is not None else "—",
        "return": fmt_est(o.mean_return),
        "headway": fmt_est(o.mean_final_headway_m),
        "return_all": fmt_est(o.mean_return),
        "headway_all": fmt_est(o.mean_final_headway_m),
    }


def outcome_blocks(a: CaseAnalysis[RunRecord]) -> list[Block]:
    columns = a.info.outcome_columns
    pct = "95 % CI"
    headers = ("VUT", "seed", "episodes", *(OUTCOME_COLUMNS[c] for c in columns))
    rows = []
    for vut, members in a.runs.items():
        for run in members:
            o = run.outcome
            if o is None:
                rows.append(
                    (vut, str(run.seed), "outcome.json missing", *["—"] * (len(headers) - 3))
                )
                continue
            n = str(o.n) if o.n is not None else "—"
            cells = _outcome_cells(o)
            rows.append((vut, str(run.seed), n, *(cells[c] for c in columns)))
    note = (
        f"Each cell: estimate ({pct}). c: episodes with a collision; r̄_epi: mean episode "
        "reward; h̄: mean distance headway at the last step."
    )
    if a.info.outcome_note:
        note += " " + a.info.outcome_note
    table = Table(
        f"Overall safety outcome of each SPCP ({a.info.paper_table} equivalent)",
        headers,
        tuple(rows),
        (False,) + (True,) * (len(headers) - 1),
        note,
    )
    blocks: list[Block] = [Heading(f"(d) Outcome of each SPCP ({a.info.paper_table})", 3), table]
    paper = a.info.paper_rows
    if paper:
        lc = a.info.lane_change
        p_headers = ("VUT", "SPCP", "c [%]") + (("lc [%]",) if lc else ()) + ("r̄_epi", "h̄ [m]")
        p_rows = tuple(
            (p.vut, f"π*{i + 1}", f"{p.crash_pct:.1f}")
            + ((f"{p.lane_change_pct:.0f}",) if lc and p.lane_change_pct is not None else ())
            + (f"{p.mean_return:.2f}", f"{p.mean_final_headway_m:.2f}")
            for i, p in enumerate(paper)
        )
        blocks.append(
            Table(
                f"For reference: the paper's {a.info.paper_table} (highway-env, 200 episodes "
                "per SPCP)",
                p_headers,
                p_rows,
                (False, False) + (True,) * (len(p_headers) - 2),
                "The paper's simulator, actuator and episode rewards differ from this testbed's, "
                "and its seeds are not ours: compare the pattern (similar outcomes for both "
                "VUTs), not the digits.",
            )
        )
    return blocks


def premise_sentence(premise: Premise | None, options: ReportOptions) -> str:
    """One sentence: did the SPCPs reach the same overall outcome?"""
    if premise is None or not premise.metrics:
        return "Premise check: needs outcome summaries of at least two VUTs."
    parts = []
    for m in premise.metrics:
        unit = f" {m.spec.unit}" if m.spec.unit else ""
        parts.append(
            f"{m.spec.name} spread {fmt_num(m.spread * m.spec.scale)}{unit} "
            f"(tolerance {fmt_num(m.tolerance * m.spec.scale)}{unit}"
            f"{'' if m.met else ', exceeded'})"
        )
    if premise.met:
        return (
            "Premise met: the SPCPs of all VUTs reached the same overall outcome within the "
            "stated tolerances (" + "; ".join(parts) + ")."
        )
    return (
        "Premise NOT met: the SPCPs of different VUTs did not reach the same overall outcome ("
        + "; ".join(parts)
        + "), so a comparison of their aggressiveness (paper mode) is confounded by the "
        "difference in outcome."
    )


def premise_blocks(a: CaseAnalysis[RunRecord], options: ReportOptions) -> list[Block]:
    blocks: list[Block] = [Heading("(e) Premise check: the same overall outcome?", 3)]
    premise = paper_result(a).premise
    if premise is None or not premise.metrics:
        return [*blocks, Paragraph(premise_sentence(premise, options))]
    pct = f"{100 * options.level:g} %"
    vuts = list(a.runs)
    rows = []
    for m in premise.metrics:
        unit = f" [{m.spec.unit}]" if m.spec.unit else ""
        cells = []
        for vut in vuts:
            if vut not in m.per_vut:
                cells.append("—")
                continue
            mean, lo, hi, n = m.per_vut[vut]
            sc = m.spec.scale
            ci = seed_interval_text(lo * sc, hi * sc, n)
            cells.append(f"{fmt_num(mean * sc)} ({ci})")
        rows.append(
            (
                m.spec.name + unit,
                *cells,
                fmt_num(m.spread * m.spec.scale),
                fmt_num(m.tolerance * m.spec.scale),
                "yes" if m.met else "no",
            )
        )
    blocks.append(
        Table(
            "Outcome of the SPCPs per VUT: seed mean (t-interval over seeds)",
            ("metric", *vuts, "spread (max − min)", "tolerance", "within tolerance"),
            tuple(rows),
            (False,) + (True,) * (len(vuts) + 2) + (False,),
            f"Each VUT: mean over its seeds' SPCPs ({pct} t-interval over seeds, clipped to "
            "what is possible: a crash rate to 0–100 %; fewer than three seeds give no "
            "interval). Metrics over all outcome episodes. Tolerances are report options "
            "(premise_reward, premise_crash_rate, premise_final_headway_m).",
        )
    )
    blocks.append(
        Callout(
            "Premise",
            (premise_sentence(premise, options),),
            "none" if premise.met else "warning",
        )
    )
    return blocks


def exposure_blocks(
    a: CaseAnalysis[RunRecord], colors: Mapping[str, str], out_dir: Path, options: ReportOptions
) -> list[Block]:
    blocks: list[Block] = [Heading("(f) Exposure ranking", 3)]
    blocks.append(Paragraph(EXPOSURE.description))
    result = exposure_result(a)
    if not result.rows:
        return [*blocks, Paragraph("No exposure: no outcome summaries in this case yet.")]
    pct = f"{100 * options.level:g} %"
    scores = result.scores
    outcomes = result.outcomes
    path = seed_scores_figure(
        result.rows,
        scores,
        colors,
        out_dir / f"{a.case}_exposure_by_seed.png",
        ylabel="harm per episode of the VUT's own SPCP",
        title=f"{a.info.title}: exposure harm per seed (lower = safer)",
    )
    blocks.append(
        FigureBlock(
            path,
            f"Harm per episode of every seed's own SPCP (grey: one line per training seed), "
            f"safest VUT on the left; diamonds: seed mean with its {pct} t-interval over "
            "seeds, clipped to 0–1 (none with fewer than three seeds).",
        )
    )
    rows = []
    for r in result.rows:
        nxt = r.vs_next
        per_seed = ", ".join(f"s{k}: {fmt_num(v, 3)}" for k, v in scores[r.name].items())
        ci = seed_interval_text(r.lo, r.hi, r.n_seeds, 3)
        o = outcomes.get(r.name)
        rows.append(
            (
                str(r.rank),
                r.name,
                f"{fmt_num(r.mean, 3)} ({ci})",
                per_seed,
                str(r.n_seeds),
                test_cell(nxt),
                ("yes" if nxt.significant else "no") if nxt else "—",
                crash_cell(o),
                mobility_cell(o),
            )
        )
    blocks.append(
        Table(
            "Ranking by exposure harm (mean harm per episode of each VUT's own SPCPs), safest "
            "first; crash rate and mean VUT speed over the same episodes",
            (
                "rank",
                "VUT",
                f"harm ({pct} CI)",
                "per-seed harm",
                "seeds",
                "test vs next",
                "significant vs next",
                "crash rate (Wilson 95 % CI, episodes pooled)",
                "mean speed",
            ),
            tuple(rows),
            (True, False, True, True, True, False, False, True, True),
        )
    )
    if any(o.timid for o in outcomes.values()):
        blocks.append(Callout("Timid VUT", (TIMID_NOTE,), "warning"))
    blocks.append(pairs_table(result.pairs, "harm", pct, options.welch_alpha))
    blocks.append(
        BulletList(
            tuple(exposure_sentence(r.vs_next) for r in result.rows if r.vs_next is not None),
        )
    )
    return blocks
