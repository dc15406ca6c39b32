"""The report: statistics per case, one document model, and its HTML and Markdown writers.

:func:`write_report` reads run folders, groups them by (case, VUT), pools seeds, draws the
figures (:mod:`.figures`), computes the safety index of every VUT and the pairwise verdicts
(:mod:`sumo_ayss.analysis.ranking`), and writes into one folder:

* ``report.html`` — one self-contained file: figures embedded as base64 PNG, inline CSS, no
  JavaScript, no network; it opens offline;
* ``summary.md`` — the same tables and verdicts, figures linked by relative path;
* the PNG figures themselves.

Both documents are rendered from the same list of blocks (:class:`Heading`,
:class:`Paragraph`, :class:`Callout`, :class:`FigureBlock`, :class:`Table`,
:class:`BulletList`), so they cannot disagree.

Significance rule: a difference between two VUTs is called significant only when BOTH the
hierarchical-bootstrap interval of the difference of their safety indices excludes 0 AND
the seed-level Welch t-test on the per-seed indices gives p < 0.05 (with three seeds the
bootstrap alone is anti-conservative, see :func:`sumo_ayss.analysis.ranking.safety_index`).
"""

from __future__ import annotations

import base64
import dataclasses
import datetime as dt
import html
import itertools
import logging
import math
import os
import zlib
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

import numpy as np

from sumo_ayss.analysis.premise import Premise, premise_check
from sumo_ayss.analysis.ranking import (
    Indicator,
    RankedVut,
    SafetyIndex,
    Verdict,
    compare,
    rank,
    safety_index,
)
from sumo_ayss.analysis.seeds import (
    SeedComparison,
    SeedRankRow,
    SeedScores,
    rank_seeds,
    verdict_sentence,
)
from sumo_ayss.errors import ConfigError
from sumo_ayss.report import figures
from sumo_ayss.report.checks import NOISE_SE, TRUSTED_TIMESTEPS, mixing_problems, trust_warnings
from sumo_ayss.report.discriminability import discriminability_blocks
from sumo_ayss.report.figures import CaseInfo, case_info
from sumo_ayss.report.load import (
    RUN_FILES,
    Estimate,
    Run,
    find_run_dirs,
    group_runs,
    load_run,
)
from sumo_ayss.report.options import MODES, ReportOptions

__all__ = [
    "DEFAULT_TITLE",
    "HTML_NAME",
    "MARKDOWN_NAME",
    "PAPER_TABLES",
    "BulletList",
    "Callout",
    "CaseAnalysis",
    "FigureBlock",
    "Heading",
    "PairVerdict",
    "PaperRow",
    "Paragraph",
    "Report",
    "ReportOptions",
    "Table",
    "analyse_case",
    "build_report",
    "pair_verdict",
    "render_html",
    "render_markdown",
    "significance_rule",
    "vut_safety_index",
    "write_report",
]

logger = logging.getLogger(__name__)

DEFAULT_TITLE = "Safety ranking of vehicles under test by adversarial-yet-safe scenarios"
HTML_NAME = "report.html"
MARKDOWN_NAME = "summary.md"


def significance_rule(options: ReportOptions) -> str:
    """The rule of the paper mode, in words, for the report."""
    pct = f"{100 * options.level:g} %"
    return (
        "Paper-mode significance rule: a difference between two VUTs is called significant "
        "only when "
        f"BOTH the {pct} hierarchical-bootstrap interval of the difference of their safety "
        "indices excludes 0 AND the seed-level Welch t-test on the per-seed indices gives "
        f"p < {options.welch_alpha:g}. With only a few seeds per VUT the bootstrap alone is "
        "anti-conservative (resampling a few seeds understates the seed-to-seed spread), so the "
        "Welch test, which treats each seed's SPCP as one observation, must agree."
    )


# --------------------------------------------------------------------------- paper reference


@dataclass(frozen=True)
class PaperRow:
    """One row of the paper's Table II / III (highway-env, not this testbed).

    Attributes:
        vut: VUT name (pi1: s0 = 10 m, pi2: s0 = 20 m).
        seed: Seed index 1..3 within the VUT (the paper's π*_1..6 in order).
        crash_pct: Crash rate c in %.
        lane_change_pct: Lane-change rate lc in % (cut-in), else None.
        mean_return: Mean episode reward r̄_epi.
        mean_final_headway_m: Mean headway at the last step h̄, m.
    """

    vut: str
    seed: int
    crash_pct: float
    lane_change_pct: float | None
    mean_return: float
    mean_final_headway_m: float


PAPER_TABLES: Mapping[str, tuple[PaperRow, ...]] = {
    "car_following": (
        PaperRow("pi1", 1, 0.0, None, 19.48, 1.65),
        PaperRow("pi1", 2, 0.0, None, 19.45, 1.82),
        PaperRow("pi1", 3, 0.0, None, 19.43, 1.71),
        PaperRow("pi2", 1, 0.0, None, 19.30, 2.42),
        PaperRow("pi2", 2, 0.0, None, 19.31, 2.62),
        PaperRow("pi2", 3, 0.0, None, 19.29, 3.76),
    ),
    "cut_in": (
        PaperRow("pi1", 1, 1.0, 99.0, 20.99, 0.36),
        PaperRow("pi1", 2, 2.0, 99.0, 20.74, 0.36),
        PaperRow("pi1", 3, 0.5, 98.0, 20.78, 0.36),
        PaperRow("pi2", 1, 3.5, 100.0, 20.41, 0.41),
        PaperRow("pi2", 2, 1.0, 100.0, 20.93, 0.38),
        PaperRow("pi2", 3, 1.0, 100.0, 21.14, 0.35),
    ),
}
"""The paper's Tables II (car-following) and III (cut-in), for reference."""


# --------------------------------------------------------------------------- document blocks


@dataclass(frozen=True)
class Heading:
    """A section heading; ``anchor`` is its in-page id."""

    text: str
    level: int = 2
    anchor: str = ""


@dataclass(frozen=True)
class Paragraph:
    """Plain text (no markup)."""

    text: str


@dataclass(frozen=True)
class Callout:
    """A highlighted box: a verdict (``safer`` / ``none``), a ``warning`` or ``info``."""

    title: str
    lines: tuple[str, ...]
    kind: Literal["safer", "none", "warning", "info"] = "info"


@dataclass(frozen=True)
class FigureBlock:
    """A PNG figure with its caption."""

    path: Path
    caption: str


@dataclass(frozen=True)
class Table:
    """A table of plain-text cells; ``numeric`` marks right-aligned columns."""

    caption: str
    headers: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    numeric: tuple[bool, ...] = ()
    note: str = ""


@dataclass(frozen=True)
class BulletList:
    """A bulleted list of plain-text items; with a ``summary`` HTML folds it (no script)."""

    items: tuple[str, ...]
    summary: str = ""


Block = Heading | Paragraph | Callout | FigureBlock | Table | BulletList


@dataclass(frozen=True)
class Report:
    """A whole report: title, a subtitle line and the blocks, in order."""

    title: str
    subtitle: str
    blocks: tuple[Block, ...]


# --------------------------------------------------------------------------- statistics


@dataclass(frozen=True)
class PairVerdict:
    """A pairwise verdict under the report's significance rule.

    Attributes:
        verdict: The bootstrap verdict of :func:`sumo_ayss.analysis.ranking.compare`.
        significant: Whether BOTH the bootstrap interval excludes 0 AND the seed-level
            Welch p-value is below ``welch_alpha``.
        safer: The safer VUT under that rule, or None.
        sentence: One quotable sentence stating the verdict under that rule.
    """

    verdict: Verdict
    significant: bool
    safer: str | None
    sentence: str


def _fmt_p(p: float) -> str:
    """``"= 0.012"`` or ``"< 0.001"``; ``"n/a"`` for NaN."""
    if not math.isfinite(p):
        return "n/a"
    return "< 0.001" if p < 0.001 else f"= {p:.3f}"


def _prob(p: float) -> str:
    """A probability for a table cell: ``"0.953"``, ``"< 0.001"``, ``"> 0.999"``, ``"—"``."""
    if p is None or not math.isfinite(p):
        return "—"
    if p < 0.001:
        return "< 0.001"
    return "> 0.999" if p > 0.999 else f"{p:.3f}"


def pair_verdict(
    a: SafetyIndex,
    b: SafetyIndex,
    *,
    name_a: str,
    name_b: str,
    indicator: Indicator,
    level: float = 0.95,
    welch_alpha: float = 0.05,
) -> PairVerdict:
    """Compares two VUTs and applies the report's significance rule.

    Args:
        a: Safety index of VUT A.
        b: Safety index of VUT B (same ``h_range``, ``n_bins`` and ``n_boot`` as ``a``).
        name_a: Name of A.
        name_b: Name of B.
        indicator: How the indicator is named in the sentence.
        level: Confidence level of the bootstrap interval.
        welch_alpha: Threshold of the seed-level Welch p-value.

    Returns:
        The :class:`PairVerdict`.

    Raises:
        ConfigError: If the two indices are not comparable.
    """
    v = compare(a, b, name_a=name_a, name_b=name_b, level=level, indicator=indicator)
    welch_ok = math.isfinite(v.p_seed_welch) and v.p_seed_welch < welch_alpha
    significant = v.significant and welch_ok
    if v.significant and not significant:
        neutral = dataclasses.replace(v, safer=None, significant=False).sentence()
        why = (
            f"the seed-level Welch test gives p {_fmt_p(v.p_seed_welch)} (needs < {welch_alpha:g})"
            if math.isfinite(v.p_seed_welch)
            else "the seed-level Welch test is undefined (it needs two seeds per VUT with spread)"
        )
        sentence = (
            f"{neutral} The bootstrap interval alone excludes 0, but {why}, so the difference "
            "is not called significant."
        )
    else:
        welch = (
            f"p {_fmt_p(v.p_seed_welch)}"
            if math.isfinite(v.p_seed_welch)
            else "undefined (it needs two seeds per VUT with spread)"
        )
        sentence = f"{v.sentence()} Seed-level Welch test: {welch}."
    return PairVerdict(v, significant, v.safer if significant else None, sentence)


def _vut_rng(options: ReportOptions, case: str, vut: str) -> np.random.Generator:
    """A bootstrap stream per (case, VUT), stable whatever other VUTs are in the report."""
    return np.random.default_rng([options.rng_seed, zlib.crc32(f"{case}/{vut}".encode())])


def vut_safety_index(
    runs: Sequence[Run], options: ReportOptions, rng: np.random.Generator | int | None = None
) -> SafetyIndex | None:
    """Safety index of one VUT from the AYSS samples of its runs (one seed per run).

    Args:
        runs: The VUT's runs; those without AYSS samples are skipped.
        options: Headway range, bins, level and bootstrap size.
        rng: Bootstrap generator or seed.

    Returns:
        The :class:`SafetyIndex`, or None if no run has a sample in the headway range.
    """
    seeds = [r.ayss for r in runs if r.ayss is not None and len(r.ayss) > 0]
    if not seeds:
        return None
    try:
        return safety_index(
            [s.indicator for s in seeds],
            [s.h for s in seeds],
            options.h_range,
            n_bins=options.index_bins,
            level=options.level,
            n_boot=options.n_boot,
            rng=rng,
        )
    except ConfigError as exc:  # e.g. no sample in the headway range
        logger.warning("no safety index: %s", exc)
        return None


@dataclass
class CaseAnalysis:
    """Statistics of one case.

    Attributes:
        case: Case name.
        info: Naming and units of the case.
        runs: ``{vut: runs sorted by seed}``.
        indices: ``{vut: safety index}`` for VUTs with AYSS samples.
        ranking: VUTs safest first (point estimate).
        pairs: Verdicts of every pair, in ranking order (A ranked above B).
        headline: The verdict sentence of the top-ranked pair, or why there is none.
        headline_kind: ``"safer"``, ``"none"`` or ``"warning"``.
        ranking_line: ``"pi2 > pi1"`` (``>`` significant under the rule, ``≈`` not).
        problems: Missing or unreadable files, one sentence each.
        mode: The analysis mode of ``headline``, ``ranking_line`` and :attr:`ranked`.
        exposure_rows: Exposure-mode ranking, safest first.
        exposure_pairs: Exposure-mode comparisons of every pair (A ranked above B).
        exposure_scores: ``{vut: {seed: E}}``, the per-seed exposures behind the ranking.
        premise: Whether the SPCPs reached the same overall outcome, or None.
        paper_headline: The paper-mode headline (also when ``mode`` is exposure).
        paper_ranking_line: The paper-mode ranking line.
    """

    case: str
    info: CaseInfo
    runs: dict[str, list[Run]]
    indices: dict[str, SafetyIndex] = field(default_factory=dict)
    ranking: list[RankedVut] = field(default_factory=list)
    pairs: list[PairVerdict] = field(default_factory=list)
    headline: str = ""
    headline_kind: Literal["safer", "none", "warning"] = "warning"
    ranking_line: str = ""
    problems: list[str] = field(default_factory=list)
    mode: str = "exposure"
    exposure_rows: list[SeedRankRow] = field(default_factory=list)
    exposure_pairs: list[SeedComparison] = field(default_factory=list)
    exposure_scores: dict[str, dict[int, float]] = field(default_factory=dict)
    premise: Premise | None = None
    paper_headline: str = ""
    paper_ranking_line: str = ""


EXPOSURE_SCORE = "extract {amount} {more_less} reward per episode"
"""How an exposure difference reads in a verdict sentence."""


def _exposure(out: CaseAnalysis, options: ReportOptions) -> None:
    """Exposure-mode ranking and the premise check, from the runs' outcome summaries."""
    scores = []
    for vut, members in out.runs.items():
        values = {
            r.seed: r.outcome.mean_return.value
            for r in members
            if r.seed is not None and r.outcome is not None and r.outcome.mean_return.known
        }
        if values:
            scores.append(SeedScores(vut, values))
        else:
            out.problems.append(f"{vut}: no outcome summary with a seed, so no exposure")
    out.exposure_scores = {sc.name: dict(sc.values) for sc in scores}
    if scores:
        out.exposure_rows, out.exposure_pairs = rank_seeds(
            scores, higher_is_safer=False, level=options.level, alpha=options.welch_alpha
        )
    metrics: dict[str, dict[str, list[float]]] = {
        "mean_return": {},
        "crash_rate": {},
        "mean_final_headway_m": {},
    }
    for vut, members in out.runs.items():
        for r in members:
            if r.outcome is None:
                continue
            for key in metrics:
                metrics[key].setdefault(vut, []).append(getattr(r.outcome, key).value)
    out.premise = premise_check(metrics, tolerances=options.premise_tolerances, level=options.level)


def exposure_sentence(c: SeedComparison) -> str:
    """The exposure-mode verdict sentence of one comparison."""
    return verdict_sentence(
        c, higher_is_safer=False, score=EXPOSURE_SCORE, unit="", mode="exposure"
    )


def premise_sentence(premise: Premise | None, options: ReportOptions) -> str:
    """One sentence: did the SPCPs reach the same overall outcome?"""
    if premise is None or not premise.metrics:
        return "Premise check: needs outcome summaries of at least two VUTs."
    parts = []
    for m in premise.metrics:
        unit = f" {m.spec.unit}" if m.spec.unit else ""
        parts.append(
            f"{m.spec.name} spread {_num(m.spread * m.spec.scale)}{unit} "
            f"(tolerance {_num(m.tolerance * m.spec.scale)}{unit}"
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


def analyse_case(
    case: str, runs: dict[str, list[Run]], options: ReportOptions, *, paper: bool = True
) -> CaseAnalysis:
    """Safety index per VUT, ranking, pairwise verdicts and the headline of one case.

    Args:
        case: Case name.
        runs: ``{vut: runs}``.
        options: Statistical settings.
        paper: Compute the paper mode (AYSS safety indices and their bootstrap, the slow
            part); the report always does, a ranking in exposure mode need not.

    Returns:
        The :class:`CaseAnalysis`.
    """
    info = case_info(case)
    out = CaseAnalysis(case=case, info=info, runs=runs)
    for members in runs.values():
        for run in members:
            out.problems += [f"{_rel_label(run)}: {p}" for p in run.problems]
    for vut, members in runs.items() if paper else ():
        idx = vut_safety_index(members, options, _vut_rng(options, case, vut))
        if idx is not None:
            out.indices[vut] = idx
        else:
            out.problems.append(
                f"{vut}: no AYSS sample with h in [0, {options.h_max_m:g}] m, so no safety index"
            )
    if out.indices:
        out.ranking = rank(out.indices, level=options.level)
    order = [r.name for r in out.ranking]
    for i, a in enumerate(order):
        for b in order[i + 1 :]:
            try:
                out.pairs.append(
                    pair_verdict(
                        out.indices[a],
                        out.indices[b],
                        name_a=a,
                        name_b=b,
                        indicator=info.indicator,
                        level=options.level,
                        welch_alpha=options.welch_alpha,
                    )
                )
            except ConfigError as exc:
                out.problems.append(f"{a} vs {b}: not comparable ({exc})")
    _headline(out)
    out.headline = "[paper mode] " + out.headline
    _exposure(out, options)
    if out.premise is not None and out.premise.metrics and not out.premise.met:
        out.headline += (
            " Confounded: the SPCPs did not reach the same overall outcome (premise check), "
            "so this aggressiveness comparison does not isolate the VUTs' safety."
        )
        if out.headline_kind == "safer":
            out.headline_kind = "warning"
    out.paper_headline, out.paper_ranking_line = out.headline, out.ranking_line
    out.mode = options.mode
    if options.mode == "exposure":
        _exposure_headline(out)
    return out


def _exposure_headline(out: CaseAnalysis) -> None:
    """Headline and ranking line of the exposure mode."""
    rows = out.exposure_rows
    if len(rows) < 2:
        out.headline = "[exposure mode] No verdict yet: a verdict needs outcomes of two VUTs."
        out.headline_kind = "warning"
        out.ranking_line = rows[0].name if rows else ""
        return
    top = rows[0].vs_next
    assert top is not None
    out.headline = exposure_sentence(top)
    out.headline_kind = "safer" if top.significant else "none"
    if out.info.exposure_caution:
        out.headline += " " + out.info.exposure_caution
        out.headline_kind = "warning"
    out.ranking_line = rows[0].name + "".join(
        (" > " if prev.significant_vs_next else " ≈ ") + row.name
        for prev, row in itertools.pairwise(rows)
    )


def _headline(out: CaseAnalysis) -> None:
    order = [r.name for r in out.ranking]
    if not order:
        out.headline = "No verdict yet: no VUT of this case has AYSS samples (ayss.csv)."
        out.headline_kind = "warning"
        return
    if len(order) == 1:
        out.headline = (
            f"No verdict yet: only {order[0]} has AYSS samples; a verdict needs two VUTs."
        )
        out.headline_kind = "warning"
        return
    top = next((p for p in out.pairs if p.verdict.name_a == order[0]), None)
    if top is None:
        out.headline = "No verdict: the safety indices of the top two VUTs are not comparable."
        out.headline_kind = "warning"
        return
    out.headline = top.sentence
    out.headline_kind = "safer" if top.significant else "none"
    parts = [order[0]]
    by_pair = {(p.verdict.name_a, p.verdict.name_b): p for p in out.pairs}
    for a, b in itertools.pairwise(order):
        pair = by_pair.get((a, b))
        parts.append((" > " if pair is not None and pair.significant else " ≈ ") + b)
    out.ranking_line = "".join(parts)


def _rel_label(run: Run) -> str:
    return f"{run.case}/{run.vut}/seed_{run.seed if run.seed is not None else '?'}"


# --------------------------------------------------------------------------- formatting


def _num(value: float, digits: int = 2) -> str:
    """A number with a real minus sign; ``—`` for NaN."""
    if value is None or not math.isfinite(value):
        return "—"
    text = f"{value:.{digits}f}"
    return text.replace("-", "−")


def _interval(lo: float, hi: float, digits: int = 2) -> str:
    if not (math.isfinite(lo) and math.isfinite(hi)):
        return ""
    sep = "–" if lo >= 0 and hi >= 0 else " to "
    return f"{_num(lo, digits)}{sep}{_num(hi, digits)}"


def _est(e: Estimate | None, digits: int = 2, scale: float = 1.0, unit: str = "") -> str:
    """``"19.48 (19.30–19.66)"``, ``"1.0 % (0.3–3.6)"``; ``—`` when unknown."""
    if e is None or not e.known:
        return "—"
    ci = _interval(e.lo * scale, e.hi * scale, digits)
    value = _num(e.value * scale, digits) + (f" {unit}" if unit else "")
    return f"{value} ({ci})" if ci else value


def _seed_points_text(members: Sequence[Run], idx: SafetyIndex) -> str:
    """Per-seed indices, labelled by seed when every seed with samples entered the index."""
    seeds = [r.seed for r in members if r.ayss is not None and len(r.ayss) > 0]
    if len(seeds) != len(idx.seed_points):
        return ", ".join(_num(p) for p in idx.seed_points)
    return ", ".join(f"s{s}: {_num(p)}" for s, p in zip(seeds, idx.seed_points, strict=True))


def _seeds_text(members: Sequence[Run]) -> str:
    return ", ".join(str(r.seed) if r.seed is not None else "?" for r in members)


# --------------------------------------------------------------------------- blocks per case


def _case_blocks(
    a: CaseAnalysis, colors: Mapping[str, str], out_dir: Path, options: ReportOptions
) -> list[Block]:
    info, case = a.info, a.case
    anchor = f"case-{case}"
    blocks: list[Block] = [Heading(f"{info.title} ({case})", 2, anchor)]
    blocks.append(Callout(f"Verdict — {info.title}", _verdict_lines(a, options), a.headline_kind))
    if a.problems:
        blocks.append(
            Callout("Missing or incomplete data in this case", tuple(a.problems), "warning")
        )
    blocks += _reward_blocks(a, out_dir)
    blocks += _learning_blocks(a, colors, out_dir)
    blocks += _indicator_blocks(a, colors, out_dir, options)
    blocks += _outcome_blocks(a)
    blocks += _premise_blocks(a, options)
    blocks += _exposure_blocks(a, colors, out_dir, options)
    blocks += _ranking_blocks(a, colors, out_dir, options)
    case_dirs = list(dict.fromkeys(r.path.parent.parent for rs in a.runs.values() for r in rs))
    blocks += discriminability_blocks(case, list(a.runs), case_dirs, out_dir, colors)
    return blocks


def _verdict_lines(a: CaseAnalysis, options: ReportOptions) -> tuple[str, ...]:
    """The verdict callout: the mode's headline and ranking, the premise, the other mode."""
    lines = [a.headline]
    if a.ranking_line:
        lines.append(f"Ranking ({a.mode} mode), safest first: {a.ranking_line}")
    lines.append(premise_sentence(a.premise, options))
    if a.mode != "paper":
        paper = a.paper_headline
        if a.paper_ranking_line:
            paper += f" Ranking (paper mode): {a.paper_ranking_line}."
        lines.append(paper)
    return tuple(lines)


def _premise_blocks(a: CaseAnalysis, options: ReportOptions) -> list[Block]:
    blocks: list[Block] = [Heading("(e) Premise check: the same overall outcome?", 3)]
    premise = a.premise
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
            mean, lo, hi, _n = m.per_vut[vut]
            sc = m.spec.scale
            ci = _interval(lo * sc, hi * sc)
            cells.append(f"{_num(mean * sc)} ({ci})" if ci else _num(mean * sc))
        rows.append(
            (
                m.spec.name + unit,
                *cells,
                _num(m.spread * m.spec.scale),
                _num(m.tolerance * m.spec.scale),
                "yes" if m.met else "no",
            )
        )
    blocks.append(
        Table(
            "Outcome of the SPCPs per VUT: seed mean (t-interval over seeds)",
            ("metric", *vuts, "spread (max − min)", "tolerance", "within tolerance"),
            tuple(rows),
            (False,) + (True,) * (len(vuts) + 2) + (False,),
            f"Each VUT: mean over its seeds' SPCPs ({pct} t-interval over seeds; one seed "
            "gives no interval). Metrics over all outcome episodes. Tolerances are report "
            "options (premise_reward, premise_crash_rate, premise_final_headway_m).",
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


def _exposure_blocks(
    a: CaseAnalysis, colors: Mapping[str, str], out_dir: Path, options: ReportOptions
) -> list[Block]:
    blocks: list[Block] = [Heading("(f) Exposure ranking (default mode)", 3)]
    blocks.append(Paragraph(MODES["exposure"]))
    if not a.exposure_rows:
        return [*blocks, Paragraph("No exposure: no outcome summaries in this case yet.")]
    pct = f"{100 * options.level:g} %"
    scores = a.exposure_scores
    path = figures.seed_scores_figure(
        a.exposure_rows,
        scores,
        colors,
        out_dir / f"{a.case}_exposure_by_seed.png",
        ylabel="adversarial exposure E (mean episode reward)",
        title=f"{a.info.title}: exposure per seed (lower = safer)",
    )
    blocks.append(
        FigureBlock(
            path,
            f"Exposure E of every seed's SPCP (grey: one line per training seed), safest VUT "
            f"on the left; diamonds: seed mean with its {pct} t-interval over seeds.",
        )
    )
    rows = []
    for r in a.exposure_rows:
        nxt = r.vs_next
        per_seed = ", ".join(f"s{k}: {_num(v)}" for k, v in scores[r.name].items())
        rows.append(
            (
                str(r.rank),
                r.name,
                f"{_num(r.mean)} ({_interval(r.lo, r.hi)})"
                if _interval(r.lo, r.hi)
                else _num(r.mean),
                per_seed,
                str(r.n_seeds),
                f"{nxt.test}, p {_fmt_p(nxt.p)}" if nxt else "—",
                ("yes" if nxt.significant else "no") if nxt else "—",
            )
        )
    blocks.append(
        Table(
            "Ranking by exposure E (mean episode reward per SPCP), safest first",
            (
                "rank",
                "VUT",
                f"E ({pct} CI)",
                "per-seed E",
                "seeds",
                "test vs next",
                "significant vs next",
            ),
            tuple(rows),
            (True, False, True, True, True, False, False),
        )
    )
    p_rows = tuple(
        (
            c.name_a,
            c.name_b,
            f"{_num(-c.difference)} ({_interval(-c.hi, -c.lo)})",
            c.test,
            _prob(c.p),
            "yes" if c.significant else "no",
        )
        for c in a.exposure_pairs
    )
    blocks.append(
        Table(
            "Pairwise comparisons (A ranked above B)",
            (
                "A",
                "B",
                f"E_B − E_A ({pct} CI)",
                "test",
                "p",
                f"significant (p < {options.welch_alpha:g})",
            ),
            p_rows,
            (False, False, True, False, True, False),
        )
    )
    blocks.append(BulletList(tuple(exposure_sentence(c) for c in a.exposure_pairs)))
    return blocks


def _reward_blocks(a: CaseAnalysis, out_dir: Path) -> list[Block]:
    blocks: list[Block] = [Heading("(a) Reward shapes", 3)]
    rewards = [r.reward for rs in a.runs.values() for r in rs if r.reward is not None]
    if not rewards:
        return [*blocks, Paragraph("No readable config.yaml: the reward shapes are unknown.")]
    path = figures.reward_shapes_figure(rewards[0], out_dir / f"{a.case}_reward_shapes.png")
    if path is None:
        return [*blocks, Paragraph("The reward-shape figure could not be drawn on this machine.")]
    caption = (
        "Adversarial reward R = α_A·R_A as a function of the distance headway h, as configured "
        "in the runs' config.yaml (same-lane shape; the lane-change shape applies to cut-in)."
    )
    if any(r != rewards[0] for r in rewards[1:]):
        caption += (
            " Caution: the runs of this case do not all use the same reward; shown: the first."
        )
    return [*blocks, FigureBlock(path, caption)]


def _learning_blocks(a: CaseAnalysis, colors: Mapping[str, str], out_dir: Path) -> list[Block]:
    path = figures.learning_curves_figure(
        a.runs,
        colors,
        out_dir / f"{a.case}_learning_curves.png",
        title=f"{a.info.title}: learning curves (evaluation on the fixed scenarios)",
    )
    rows = []
    for vut, members in a.runs.items():
        for run in members:
            n_cand = str(len(run.eval_curve)) if run.eval_curve is not None else "—"
            step = f"{run.spcp.step:,}" if run.spcp is not None else "—"
            score = _num(run.spcp.score, 3) if run.spcp is not None else "—"
            crit = run.spcp.criterion if run.spcp is not None and run.spcp.criterion else "—"
            rows.append(
                (
                    vut,
                    str(run.seed),
                    n_cand,
                    step,
                    score,
                    crit,
                    run.training.status,
                    _display_path(run.path, out_dir),
                )
            )
    table = Table(
        "SPCP selection: the candidate with the best score on the fixed evaluation scenarios",
        ("VUT", "seed", "candidates", "SPCP step", "score", "criterion", "SPCP", "run folder"),
        tuple(rows),
        (False, True, True, True, True, False, False, False),
    )
    caption = (
        "Mean evaluation episode reward of every SPCP candidate vs training steps; one colour "
        "per VUT, one line style per seed; the star marks the selected SPCP."
    )
    return [Heading("(b) Learning curves and SPCP selection", 3), FigureBlock(path, caption), table]


def _indicator_blocks(
    a: CaseAnalysis, colors: Mapping[str, str], out_dir: Path, options: ReportOptions
) -> list[Block]:
    info = a.info
    edges = options.figure_edges
    path = figures.indicator_figure(
        a.runs,
        colors,
        out_dir / f"{a.case}_indicator_vs_headway.png",
        edges=edges,
        axis_label=info.axis_label,
        level=options.level,
        title=f"{info.title}: {info.symbol} of the AYSS vs headway (paper {info.paper_figure})",
    )
    caption = (
        f"Mean {info.symbol} of the adversarial-yet-safe states (AYSS) per "
        f"{options.bin_width_m:g} m headway bin, with {100 * options.level:g} % confidence "
        "bands (Student t per bin, samples pooled over seeds). More negative = a more "
        "aggressive SPCP = a safer VUT. Right: each seed's SPCP alone. Bottom: samples per bin "
        "and per SPCP; bins with fewer than two samples are not drawn."
    )
    rows = []
    for vut, members in a.runs.items():
        for run in members:
            if run.ayss is None:
                rows.append((vut, str(run.seed), "missing", "—", "—"))
                continue
            h, y = run.ayss.h, run.ayss.indicator
            inside = (h >= 0) & (h <= options.h_max_m)
            mean = float(np.mean(y[inside])) if inside.any() else math.nan
            rows.append(
                (vut, str(run.seed), str(len(run.ayss)), str(int(inside.sum())), _num(mean))
            )
    table = Table(
        "AYSS samples per SPCP",
        ("VUT", "seed", "samples", f"with h ≤ {options.h_max_m:g} m", f"mean {info.symbol}"),
        tuple(rows),
        (False, True, True, True, True),
    )
    heading = f"(c) Aggressiveness vs headway ({info.paper_figure} equivalent)"
    return [Heading(heading, 3), FigureBlock(path, caption), table]


def _outcome_blocks(a: CaseAnalysis) -> list[Block]:
    cut_in = a.case == "cut_in"
    pct = "95 % CI"
    if cut_in:
        headers: tuple[str, ...] = (
            "VUT",
            "seed",
            "episodes",
            "crash rate c [%]",
            "lane-change rate lc [%]",
            "r̄_epi (LC, no crash)",
            "h̄ [m] (LC, no crash)",
            "episodes LC, no crash",
            "r̄_epi (all)",
            "h̄ [m] (all)",
        )
    else:
        headers = ("VUT", "seed", "episodes", "crash rate c [%]", "r̄_epi", "h̄ [m]")
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
            crash = _est(o.crash_rate, 1, 100.0)
            if cut_in:
                sub = o.lane_change_no_collision
                rows.append(
                    (
                        vut,
                        str(run.seed),
                        n,
                        crash,
                        _est(o.lane_change_rate, 1, 100.0),
                        _est(sub.mean_return if sub else None),
                        _est(sub.mean_final_headway_m if sub else None),
                        str(sub.n) if sub and sub.n is not None else "—",
                        _est(o.mean_return),
                        _est(o.mean_final_headway_m),
                    )
                )
            else:
                rows.append(
                    (
                        vut,
                        str(run.seed),
                        n,
                        crash,
                        _est(o.mean_return),
                        _est(o.mean_final_headway_m),
                    )
                )
    note = (
        f"Each cell: estimate ({pct}). c: episodes with a collision; r̄_epi: mean episode "
        "reward; h̄: mean distance headway at the last step."
    )
    if cut_in:
        note += (
            " As in the paper, r̄_epi and h̄ are over episodes with a lane change and no collision."
        )
    table = Table(
        f"Overall safety outcome of each SPCP ({a.info.paper_table} equivalent)",
        headers,
        tuple(rows),
        (False,) + (True,) * (len(headers) - 1),
        note,
    )
    blocks: list[Block] = [Heading(f"(d) Outcome of each SPCP ({a.info.paper_table})", 3), table]
    paper = PAPER_TABLES.get(a.case)
    if paper:
        p_headers = ("VUT", "SPCP", "c [%]") + (("lc [%]",) if cut_in else ()) + ("r̄_epi", "h̄ [m]")
        p_rows = tuple(
            (p.vut, f"π*{i + 1}", f"{p.crash_pct:.1f}")
            + ((f"{p.lane_change_pct:.0f}",) if cut_in and p.lane_change_pct is not None else ())
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


def _ranking_blocks(
    a: CaseAnalysis, colors: Mapping[str, str], out_dir: Path, options: ReportOptions
) -> list[Block]:
    info = a.info
    unit = info.indicator.unit
    blocks: list[Block] = [
        Heading("(g) Paper mode: safety index from the AYSS and pairwise verdicts", 3)
    ]
    pct = f"{100 * options.level:g} %"
    blocks.append(
        Paragraph(
            f"Safety index = − mean over {options.index_bins} equal headway bins on "
            f"[0, {options.h_max_m:g}] m of the per-bin mean {info.symbol} of the AYSS "
            f"(larger = safer VUT), with a {pct} hierarchical-bootstrap interval "
            f"({options.n_boot} replicates: seeds, then samples within a seed)."
        )
    )
    if not a.indices:
        return [*blocks, Paragraph("No safety index: no AYSS samples in this case yet.")]
    path = figures.safety_index_figure(
        a.indices,
        colors,
        out_dir / f"{a.case}_safety_index.png",
        unit=unit,
        what=info.symbol if a.case != "cut_in" else "Δv̄",
        title=f"{info.title}: safety index",
    )
    blocks.append(
        FigureBlock(path, f"Safety index per VUT with its {pct} interval; safest on top.")
    )
    by_pair = {(p.verdict.name_a, p.verdict.name_b): p for p in a.pairs}
    rows = []
    for r in a.ranking:
        idx = a.indices[r.name]
        nxt = a.ranking[r.rank].name if r.rank < len(a.ranking) else None
        pair = by_pair.get((r.name, nxt)) if nxt else None
        rows.append(
            (
                str(r.rank),
                r.name,
                f"{_num(r.point)} ({_interval(r.lo, r.hi)})",
                _seed_points_text(a.runs[r.name], idx),
                str(r.n_seeds),
                str(idx.n_samples),
                _prob(pair.verdict.p_a_safer) if pair else "—",
                ("yes" if pair.significant else "no") if pair else "—",
            )
        )
    blocks.append(
        Table(
            f"Ranking by safety index [{unit}], safest first",
            (
                "rank",
                "VUT",
                f"index ({pct} CI)",
                "per-seed index",
                "seeds",
                "samples",
                "P(safer than next)",
                "significant vs next",
            ),
            tuple(rows),
            (True, False, True, True, True, True, True, False),
        )
    )
    if a.pairs:
        p_rows = tuple(
            (
                p.verdict.name_a,
                p.verdict.name_b,
                f"{_num(p.verdict.difference)} ({_interval(p.verdict.diff_lo, p.verdict.diff_hi)})",
                _prob(p.verdict.p_a_safer),
                _num(p.verdict.cohens_d),
                _prob(p.verdict.p_seed_welch),
                "yes" if p.verdict.significant else "no",
                "yes" if p.significant else "no",
                p.safer or "no significant difference",
            )
            for p in a.pairs
        )
        blocks.append(
            Table(
                "Pairwise verdicts (A ranked above B)",
                (
                    "A",
                    "B",
                    f"index A − B [{unit}] ({pct} CI)",
                    "P(A safer)",
                    "Cohen's d",
                    "Welch p (seeds)",
                    "bootstrap CI excludes 0",
                    "significant (both)",
                    "safer",
                ),
                p_rows,
                (False, False, True, True, True, True, False, False, False),
                significance_rule(options),
            )
        )
        blocks.append(BulletList(tuple(p.sentence for p in a.pairs)))
    return blocks


# --------------------------------------------------------------------------- whole report


def _display_path(path: Path, base: Path) -> str:
    """``path`` relative to ``base`` (the report folder), so reports carry no machine paths."""
    return Path(os.path.relpath(Path(path).resolve(), Path(base).resolve())).as_posix()


def _training_table(runs: Sequence[Run]) -> Table:
    rows = []
    for r in runs:
        t = r.training
        rows.append(
            (
                r.case,
                r.label,
                "?" if t.total_timesteps is None else f"{t.total_timesteps:,}",
                "?" if t.eval_every is None else f"{t.eval_every:,}",
                str(t.n_candidates),
                "?" if t.spcp_step is None else f"{t.spcp_step:,}",
                "?" if t.last_step is None else f"{t.last_step:,}",
                t.status,
            )
        )
    return Table(
        "Training budget and SPCP per run",
        (
            "case",
            "run",
            "total_timesteps",
            "eval_every",
            "candidates",
            "SPCP step",
            "last candidate step",
            "SPCP",
        ),
        tuple(rows),
        (False, False, True, True, True, True, True, False),
        note=(
            "Budgets in training transitions. SPCP: 'may still improve' when it is the last "
            "candidate; 'plateau' when the last candidate's mean evaluation reward is within "
            f"{NOISE_SE:g} standard errors (SE, the SPCP's std / sqrt(episodes)) of the "
            "SPCP's; 'peaked' when it is further below. Below "
            f"{TRUSTED_TIMESTEPS:,} transitions (the shipped experiments' budget) verdicts "
            "are not to be trusted."
        ),
    )


def _inputs_blocks(
    runs: Sequence[Run], groups: Mapping[str, Mapping[str, list[Run]]], out_dir: Path
) -> list[Block]:
    blocks: list[Block] = [Heading("Inputs", 2, "inputs")]
    rows = []
    for case, by_vut in groups.items():
        for vut, members in by_vut.items():
            desc = next((r.vut_description for r in members if r.vut_description), "")
            complete = sum(1 for r in members if not r.problems)
            rows.append(
                (case, vut, desc or "—", str(len(members)), _seeds_text(members), str(complete))
            )
    blocks.append(
        Table(
            "Runs per case and VUT (seeds are pooled per VUT)",
            ("case", "VUT", "VUT definition", "seeds", "seed values", "complete runs"),
            tuple(rows),
            (False, False, False, True, False, True),
        )
    )
    blocks.append(_training_table(runs))
    blocks.append(
        BulletList(
            tuple(_display_path(r.path, out_dir) for r in runs),
            f"Run folders used ({len(runs)}, relative to this report's folder)",
        )
    )
    versions: dict[str, Counter[str]] = {}
    for run in runs:
        for key, value in run.versions.items():
            versions.setdefault(key, Counter())[value] += 1
    with_versions = sum(1 for r in runs if r.versions)
    if versions:
        v_rows = tuple(
            (key, "; ".join(f"{v} ({n} runs)" if len(c) > 1 else v for v, n in c.most_common()))
            for key, c in sorted(versions.items())
        )
        blocks.append(
            Table(
                f"Versions ({RUN_FILES.versions} of {with_versions} of {len(runs)} runs)",
                ("package", "version"),
                v_rows,
            )
        )
    else:
        blocks.append(Paragraph(f"No run holds a {RUN_FILES.versions}: versions unknown."))
    return blocks


def build_report(
    runs: Sequence[Run],
    out_dir: Path,
    *,
    title: str = DEFAULT_TITLE,
    options: ReportOptions | None = None,
) -> Report:
    """Computes the statistics, draws the figures into ``out_dir`` and assembles the blocks.

    Args:
        runs: Loaded runs (any cases and VUTs).
        out_dir: Folder for the PNG figures (created).
        title: Report title.
        options: Statistical settings; defaults if None.

    Returns:
        The :class:`Report`.
    """
    options = options or ReportOptions()
    out_dir.mkdir(parents=True, exist_ok=True)
    groups = group_runs(runs)
    colors = figures.vut_colors(sorted({r.vut for r in runs}))
    analyses = [analyse_case(case, by_vut, options) for case, by_vut in groups.items()]
    now = dt.datetime.now().astimezone().strftime("%Y-%m-%d %H:%M %Z")
    n_seeds = ", ".join(
        f"{case}: " + ", ".join(f"{vut} × {len(m)}" for vut, m in by_vut.items())
        for case, by_vut in groups.items()
    )
    budgets = sorted({r.training.total_timesteps or 0 for r in runs})
    budget = ", ".join(f"{b:,}" if b else "unknown" for b in budgets)
    subtitle = (
        f"Generated {now} from {len(runs)} run folders ({n_seeds or 'none'}); training budget "
        f"{budget or 'none'} transitions per run."
    )
    blocks: list[Block] = []
    warnings = trust_warnings([(f"{r.case} {r.label}", r.training) for r in runs])
    if warnings:
        blocks.append(Callout("Read the verdicts with care", tuple(warnings), "warning"))
    blocks.append(Heading("Verdicts", 2, "verdicts"))
    if not analyses:
        blocks.append(Callout("No runs", ("No run folder was found.",), "warning"))
    for a in analyses:
        blocks.append(Callout(a.info.title, _verdict_lines(a, options), a.headline_kind))
    blocks.append(Paragraph(f"Verdicts above are in {options.mode} mode. " + MODES[options.mode]))
    blocks.append(Paragraph(significance_rule(options)))
    blocks.append(
        Paragraph(
            "How to read this report: against each VUT an adversarial-yet-safe opponent (POV) "
            "was trained with the same reward; its best checkpoint is the VUT's SPCP. Exposure "
            "mode ranks VUTs by how much of that reward their SPCPs extract (sections d and f): "
            "less means the opponent could create fewer and less close near-misses. The "
            "paper's reading (sections c and g) assumes that all SPCPs reached the same overall "
            "outcome (checked in section e) and then reveals a safer VUT by a more aggressive "
            "SPCP: harder braking (car-following) or a smaller Δv̄ (cut-in) at the same headway."
        )
    )
    blocks += _inputs_blocks(runs, groups, out_dir)
    for a in analyses:
        blocks += _case_blocks(a, colors, out_dir, options)
    return Report(title, subtitle, tuple(blocks))


def write_report(
    paths: Sequence[str | Path],
    out_dir: str | Path | None = None,
    *,
    title: str = DEFAULT_TITLE,
    options: ReportOptions | None = None,
) -> Path:
    """Reads run folders and writes ``report.html``, ``summary.md`` and the PNGs.

    Args:
        paths: Run folders ``<out>/<case>/<vut>/seed_<k>`` and/or roots to search.
        out_dir: Output folder; default ``<first path>/report``.
        title: Report title.
        options: Statistical settings; defaults if None.

    Returns:
        The path of ``report.html``.

    Raises:
        ConfigError: If ``paths`` is empty, a path is not a folder, or no run folder is
            found.
    """
    if not paths:
        raise ConfigError("paths: expected at least one run folder or root")
    run_dirs = find_run_dirs(paths)
    if not run_dirs:
        raise ConfigError(f"no run folder (with {RUN_FILES.config}) under {list(map(str, paths))}")
    target = Path(out_dir) if out_dir is not None else Path(paths[0]) / "report"
    runs = [load_run(d) for d in run_dirs]
    problems = mixing_problems(
        [(r.case, r.vut, r.seed, _display_path(r.path, Path.cwd()), r.training) for r in runs]
    )
    if problems:
        raise ConfigError(
            "these runs must not be pooled into one report (report each group separately, "
            "e.g. one pipeline output folder at a time):\n  " + "\n  ".join(problems)
        )
    for warning in trust_warnings([(f"{r.case} {r.label}", r.training) for r in runs]):
        logger.warning("%s", warning)
    report = build_report(runs, target, title=title, options=options)
    html_path = target / HTML_NAME
    from sumo_ayss.atomic import atomic_write_text

    atomic_write_text(html_path, render_html(report))
    atomic_write_text(target / MARKDOWN_NAME, render_markdown(report, target))
    logger.info("report written to %s", html_path)
    return html_path


# --------------------------------------------------------------------------- HTML


_CSS = """
:root { --ink:#1d2433; --muted:#5b6474; --line:#d9dee7; --bg:#f6f8fb; --accent:#2457a6; }
* { box-sizing: border-box; }
body { margin:0; background:var(--bg); color:var(--ink);
  font: 15px/1.5 "DejaVu Sans", "Segoe UI", Helvetica, Arial, sans-serif; }
main { max-width: 1240px; margin: 0 auto; padding: 24px 28px 60px; background:#fff;
  box-shadow: 0 0 0 1px var(--line); }
h1 { font-size: 26px; margin: 8px 0 4px; }
h2 { font-size: 21px; margin: 40px 0 12px; padding-bottom: 6px;
  border-bottom: 2px solid var(--accent); }
h3 { font-size: 17px; margin: 28px 0 8px; color: var(--accent); }
p.sub { color: var(--muted); margin: 0 0 16px; }
nav { font-size: 14px; margin: 8px 0 20px; }
nav a { margin-right: 16px; color: var(--accent); }
.callout { border-left: 6px solid #8a94a6; background:#f2f4f8; padding: 12px 16px;
  margin: 12px 0; border-radius: 4px; }
.callout .t { font-weight: 700; font-size: 13px; text-transform: uppercase;
  letter-spacing: .04em; color: var(--muted); margin-bottom: 4px; }
.callout p { margin: 4px 0; }
.callout.safer { border-color:#1f8a4c; background:#eaf7ef; }
.callout.safer p:first-of-type, .callout.none p:first-of-type { font-size: 17px; font-weight: 600; }
.callout.none { border-color:#6c7a92; background:#eef1f6; }
.callout.warning { border-color:#d08a00; background:#fff6e0; }
.callout.warning p { font-size: 14px; margin: 2px 0; }
figure { margin: 12px 0 18px; }
figure img { display:block; max-width:100%; height:auto; border:1px solid var(--line); }
figcaption { color: var(--muted); font-size: 13.5px; margin-top: 6px; }
div.table { overflow-x: auto; margin: 14px 0 10px; }
table { border-collapse: collapse; margin: 0 0 4px; font-size: 13.5px; }
p.tcap { font-weight: 600; margin: 0 0 6px; }
details { margin: 8px 0; font-size: 14px; }
summary { cursor: pointer; color: var(--accent); }
th, td { border: 1px solid var(--line); padding: 4px 9px; vertical-align: top; }
th { background: #eef2f8; text-align: left; }
td.n { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
tbody tr:nth-child(even) { background: #fafbfd; }
.note { color: var(--muted); font-size: 13px; margin: 2px 0 14px; max-width: 1100px; }
ul.plain { font-size: 14px; }
code, .path { font-family: "DejaVu Sans Mono", Consolas, monospace; font-size: 12.5px; }
"""


def _e(text: str) -> str:
    return html.escape(text, quote=True)


def _html_block(block: Block) -> str:
    if isinstance(block, Heading):
        tag = f"h{min(max(block.level, 1), 6)}"
        anchor = f' id="{_e(block.anchor)}"' if block.anchor else ""
        return f"<{tag}{anchor}>{_e(block.text)}</{tag}>"
    if isinstance(block, Paragraph):
        return f"<p>{_e(block.text)}</p>"
    if isinstance(block, Callout):
        body = "".join(f"<p>{_e(line)}</p>" for line in block.lines)
        return (
            f'<div class="callout {block.kind}"><div class="t">{_e(block.title)}</div>{body}</div>'
        )
    if isinstance(block, FigureBlock):
        data = base64.b64encode(block.path.read_bytes()).decode("ascii")
        return (
            f'<figure><img alt="{_e(block.caption)}" src="data:image/png;base64,{data}">'
            f"<figcaption>{_e(block.caption)}</figcaption></figure>"
        )
    if isinstance(block, Table):
        return _html_table(block)
    items = '<ul class="plain">' + "".join(f"<li>{_e(i)}</li>" for i in block.items) + "</ul>"
    if block.summary:
        return f"<details><summary>{_e(block.summary)}</summary>{items}</details>"
    return items


def _html_table(t: Table) -> str:
    numeric = t.numeric or (False,) * len(t.headers)
    head = "".join(f"<th>{_e(h)}</th>" for h in t.headers)
    body = []
    for row in t.rows:
        cells = "".join(
            f'<td class="n">{_e(c)}</td>' if numeric[i] else f"<td>{_e(c)}</td>"
            for i, c in enumerate(row)
        )
        body.append(f"<tr>{cells}</tr>")
    note = f'<p class="note">{_e(t.note)}</p>' if t.note else ""
    return (
        f'<div class="table"><p class="tcap">{_e(t.caption)}</p><table><thead><tr>{head}</tr>'
        f"</thead><tbody>{''.join(body)}</tbody></table>{note}</div>"
    )


def render_html(report: Report) -> str:
    """The report as one self-contained HTML document (inline CSS and images, no script).

    Args:
        report: The report.

    Returns:
        The HTML text.
    """
    anchors = [b for b in report.blocks if isinstance(b, Heading) and b.anchor]
    nav = " ".join(f'<a href="#{_e(b.anchor)}">{_e(b.text)}</a>' for b in anchors)
    body = "\n".join(_html_block(b) for b in report.blocks)
    return (
        "<!DOCTYPE html>\n"
        '<html lang="en"><head><meta charset="utf-8">'
        '<meta name="viewport" content="width=device-width, initial-scale=1">'
        f"<title>{_e(report.title)}</title><style>{_CSS}</style></head>\n"
        f"<body><main><h1>{_e(report.title)}</h1>"
        f'<p class="sub">{_e(report.subtitle)}</p><nav>{nav}</nav>\n{body}\n'
        "</main></body></html>\n"
    )


# --------------------------------------------------------------------------- Markdown


def _md_cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def _md_block(block: Block, base: Path) -> str:
    if isinstance(block, Heading):
        return f"{'#' * min(max(block.level, 1), 6)} {block.text}"
    if isinstance(block, Paragraph):
        return block.text
    if isinstance(block, Callout):
        lines = [f"> **{block.title}**", ">"]
        for i, line in enumerate(block.lines):
            strong = i == 0 and block.kind in ("safer", "none")
            lines += [f"> **{line}**" if strong else f"> {line}", ">"]
        return "\n".join(lines[:-1])
    if isinstance(block, FigureBlock):
        try:
            rel = block.path.relative_to(base).as_posix()
        except ValueError:
            rel = block.path.as_posix()
        return f"![{_md_cell(block.caption)}]({rel})\n\n*{block.caption}*"
    if isinstance(block, Table):
        numeric = block.numeric or (False,) * len(block.headers)
        out = [f"**{block.caption}**", ""]
        out.append("| " + " | ".join(_md_cell(h) for h in block.headers) + " |")
        out.append("|" + "|".join("---:" if n else "---" for n in numeric) + "|")
        out += ["| " + " | ".join(_md_cell(c) for c in row) + " |" for row in block.rows]
        if block.note:
            out += ["", f"*{block.note}*"]
        return "\n".join(out)
    items = "\n".join(f"- {item}" for item in block.items)
    return f"{block.summary}:\n\n{items}" if block.summary else items


def render_markdown(report: Report, base: Path) -> str:
    """The report as Markdown; figures are linked relative to ``base`` (the output folder).

    Args:
        report: The report.
        base: Folder the Markdown file is written to.

    Returns:
        The Markdown text.
    """
    parts = [f"# {report.title}", f"*{report.subtitle}*"]
    parts += [_md_block(b, base) for b in report.blocks]
    return "\n\n".join(parts) + "\n"
