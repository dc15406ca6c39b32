"""Read run folders and case folders back for the report and rank, tolerating missing and
broken files.

A run folder ``<out>/<case>/<vut>/seed_<k>/`` is written by :mod:`sumo_ayss.train` and by the
evaluate stage, a case's ``crossplay.csv`` by the cross-play stage; their file names and the
schema of each file are in :mod:`sumo_ayss.run_folder`, whose readers this module calls (one
reader per file). :mod:`sumo_ayss.analysis` reads no file: :func:`analyse_runs` hands it the
loaded runs and each case's cross-play matrix
(:func:`~sumo_ayss.report.episodes.load_crossplay`), one analysis per case for whoever needs
it (the report, rank).

Nothing here raises on a missing or unreadable file: :func:`load_run` records a sentence per
problem in :attr:`Run.problems` and leaves the field empty, so a report on a run that has not
been evaluated yet says what is missing instead of crashing. This module imports neither
SUMO nor torch.
"""

from __future__ import annotations

import logging
from collections import Counter
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sumo_ayss.analysis.case import CaseAnalysis, CaseOptions, analyse_case
from sumo_ayss.analysis.harm import EpisodeStats, HarmScale
from sumo_ayss.cases import case_names, case_of_indicator
from sumo_ayss.config import RewardConfig, build
from sumo_ayss.errors import AyssError, ConfigError
from sumo_ayss.report.checks import Training, read_training
from sumo_ayss.report.episodes import harm_scale_of, load_crossplay, read_episode_stats
from sumo_ayss.run_folder import (
    AYSS_CSV,
    AYSS_SCHEMA,
    CONFIG_YAML,
    EVAL_CSV,
    OUTCOME_JSON,
    SPCP_JSON,
    VERSIONS_JSON,
    Estimate,
    Outcome,
    OutcomeSubset,
    RunConfig,
    RunFolder,
    SpcpChoice,
    find_run_dirs,
    read_eval_rows,
    read_outcome_json,
    read_run_config,
    read_spcp,
    read_table,
    read_versions,
    seed_of_dir,
)

__all__ = [
    "RUN_FILES",
    "AyssSamples",
    "Estimate",
    "EvalCurve",
    "Outcome",
    "OutcomeSubset",
    "Run",
    "RunFiles",
    "SpcpChoice",
    "analyse_runs",
    "find_run_dirs",
    "group_runs",
    "load_run",
    "read_ayss",
    "read_eval_curve",
    "read_outcome",
]

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class RunFiles:
    """The names of the files the report reads (from :mod:`sumo_ayss.run_folder`)."""

    config: str = CONFIG_YAML
    eval_table: str = EVAL_CSV
    spcp: str = SPCP_JSON
    outcome: str = OUTCOME_JSON
    ayss: str = AYSS_CSV
    versions: str = VERSIONS_JSON


RUN_FILES = RunFiles()
"""The file names the report reads."""


# --------------------------------------------------------------------------- records


def _empty_f() -> NDArray[np.float64]:
    return np.empty(0, dtype=np.float64)


@dataclass(frozen=True)
class EvalCurve:
    """The SPCP-candidate evaluations of one run (``eval.csv``), sorted by step.

    Attributes:
        step: Training steps of each candidate, shape ``(k,)``.
        mean_return: Mean evaluation episode reward, shape ``(k,)``.
        crash_rate: Fraction of evaluation episodes with a collision, shape ``(k,)``.
        lane_change_rate: Fraction with a lane change, shape ``(k,)`` (0 in car-following).
        mean_final_headway_m: Mean final headway in m, shape ``(k,)``.
    """

    step: NDArray[np.float64] = field(default_factory=_empty_f)
    mean_return: NDArray[np.float64] = field(default_factory=_empty_f)
    crash_rate: NDArray[np.float64] = field(default_factory=_empty_f)
    lane_change_rate: NDArray[np.float64] = field(default_factory=_empty_f)
    mean_final_headway_m: NDArray[np.float64] = field(default_factory=_empty_f)
    n_dropped: int = 0
    """Rows skipped because a cell was not a (finite) number."""

    def __len__(self) -> int:
        return int(self.step.size)


@dataclass(frozen=True)
class AyssSamples:
    """The adversarial-yet-safe samples of one SPCP (``ayss.csv``).

    Attributes:
        h: Distance headway per sample, m, shape ``(n,)``, finite.
        indicator: Aggressiveness indicator per sample, shape ``(n,)``, finite: POV
            acceleration in m/s² or Δv̄ in m/s; more negative = more aggressive.
        indicator_name: The file's ``indicator_name`` (most common value), or None.
    """

    h: NDArray[np.float64]
    indicator: NDArray[np.float64]
    indicator_name: str | None

    def __len__(self) -> int:
        return int(self.h.size)


@dataclass
class Run:
    """Everything the report reads from one run folder; fields are None when unavailable.

    Attributes:
        path: The run folder.
        case: The case name (from ``config.yaml``, else the folder path).
        vut: VUT name.
        seed: Training seed, or None if unknown.
        vut_description: The VUT's description from the catalog in ``config.yaml``.
        reward: The run's reward configuration, or None.
        eval_curve: The candidate evaluations, or None.
        spcp: The selected SPCP, or None.
        outcome: The outcome summary, or None.
        ayss: The AYSS samples, or None.
        versions: Package versions the run used (``versions.json``), or empty.
        training: Training budget and SPCP state (:func:`~sumo_ayss.report.checks.read_training`).
        harm_scale: The constants that turn this run's episodes into harm (from the reward
            and the episode length in ``config.yaml``), or None.
        episodes: The outcome episodes reduced to harm, crashes and mobility (from
            ``outcome.csv``), or None.
        problems: One sentence per missing or unreadable file.
    """

    path: Path
    case: str
    vut: str
    seed: int | None
    vut_description: str = ""
    reward: RewardConfig | None = None
    eval_curve: EvalCurve | None = None
    spcp: SpcpChoice | None = None
    outcome: Outcome | None = None
    ayss: AyssSamples | None = None
    versions: dict[str, str] = field(default_factory=dict)
    training: Training = field(default_factory=Training)
    harm_scale: HarmScale | None = None
    episodes: EpisodeStats | None = None
    problems: list[str] = field(default_factory=list)

    @property
    def label(self) -> str:
        """``"pi1 seed 0"``."""
        return f"{self.vut} seed {self.seed if self.seed is not None else '?'}"


# --------------------------------------------------------------------------- grouping


def group_runs(runs: Sequence[Run]) -> dict[str, dict[str, list[Run]]]:
    """Runs grouped by case, then VUT; cases in registry order (:mod:`sumo_ayss.cases`),
    unknown ones last, VUTs and seeds sorted.

    Args:
        runs: Loaded runs.

    Returns:
        ``{case: {vut: [runs sorted by seed]}}``.
    """
    order = {name: i for i, name in enumerate(case_names())}
    out: dict[str, dict[str, list[Run]]] = {}
    for case in sorted({r.case for r in runs}, key=lambda c: (order.get(c, len(order)), c)):
        by_vut: dict[str, list[Run]] = {}
        for vut in sorted({r.vut for r in runs if r.case == case}):
            members = [r for r in runs if r.case == case and r.vut == vut]
            by_vut[vut] = sorted(members, key=lambda r: (r.seed is None, r.seed or 0, str(r.path)))
        out[case] = by_vut
    return out


# --------------------------------------------------------------------------- readers


def read_outcome(path: Path) -> Outcome:
    """The outcome summary of ``outcome.json`` (:func:`sumo_ayss.run_folder.read_outcome_json`).

    Raises:
        TableError: If the file is missing or does not follow the writer's schema.
    """
    return read_outcome_json(path).outcome


def read_eval_curve(path: Path) -> EvalCurve:
    """``eval.csv`` as an :class:`EvalCurve`, sorted by step; rows with a bad cell are
    skipped and counted.

    Raises:
        CheckpointError: If the file is unreadable or lacks a column.
    """
    rows, n_dropped = read_eval_rows(path, skip_bad_rows=True)
    rows.sort(key=lambda r: r["step"])

    def col(name: str) -> NDArray[np.float64]:
        return np.array([r[name] for r in rows], dtype=np.float64)

    return EvalCurve(
        step=col("step"),
        mean_return=col("mean_return"),
        crash_rate=col("crash_rate"),
        lane_change_rate=col("lane_change_rate"),
        mean_final_headway_m=col("mean_final_headway_m"),
        n_dropped=n_dropped,
    )


def read_ayss(path: Path) -> AyssSamples:
    """Headway and indicator of every sample of ``ayss.csv`` (read against
    :data:`~sumo_ayss.run_folder.AYSS_SCHEMA`).

    Raises:
        TableError: If the file does not follow the schema.
    """
    table = read_table(path, AYSS_SCHEMA)
    names = Counter(str(n) for n in table["indicator_name"])
    return AyssSamples(
        h=np.asarray(table["h_m"], dtype=np.float64),
        indicator=np.asarray(table["indicator"], dtype=np.float64),
        indicator_name=names.most_common(1)[0][0] if names else None,
    )


def _vut_description(env: Mapping[str, Any], vut: str) -> str:
    vuts = env.get("vuts")
    entry = vuts.get(vut) if isinstance(vuts, Mapping) else None
    if not isinstance(entry, Mapping):
        return ""
    if entry.get("description"):
        return str(entry["description"])
    params = entry.get("params") or {}
    shown = ", ".join(f"{k}={v}" for k, v in sorted(params.items()) if k in ("minGap", "tau"))
    return f"{entry.get('model', '?')}" + (f" ({shown})" if shown else "")


def load_run(path: str | Path) -> Run:
    """Reads one run folder; never raises for missing or unreadable files.

    Args:
        path: The run folder ``<out>/<case>/<vut>/seed_<k>/``.

    Returns:
        The :class:`Run`; each file that is missing or cannot be parsed leaves its field
        None and adds a sentence to :attr:`Run.problems`.
    """
    folder = RunFolder(Path(path).resolve())
    run_dir = folder.path
    run = Run(
        path=run_dir,
        case=run_dir.parent.parent.name or "unknown",
        vut=run_dir.parent.name or "unknown",
        seed=seed_of_dir(run_dir),
    )
    _load_config(run, folder)

    def attempt(file: Path, reader: Callable[[Path], Any], attr: str) -> None:
        if not file.is_file():
            run.problems.append(f"{file.name} missing")
            return
        try:
            setattr(run, attr, reader(file))
        except (AyssError, OSError, ValueError) as exc:
            run.problems.append(f"{file.name} unreadable ({exc})")
            logger.warning("%s: %s unreadable: %s", run_dir, file.name, exc)

    attempt(folder.eval_table, read_eval_curve, "eval_curve")
    if run.eval_curve is not None and run.eval_curve.n_dropped:
        run.problems.append(
            f"{EVAL_CSV}: {run.eval_curve.n_dropped} candidate row(s) without a "
            "finite step or mean_return dropped"
        )
    attempt(folder.spcp_json, read_spcp, "spcp")
    attempt(folder.outcome_json, read_outcome, "outcome")
    if run.harm_scale is not None:
        scale = run.harm_scale
        attempt(folder.outcome_csv, lambda p: read_episode_stats(p, scale), "episodes")
    attempt(folder.ayss_csv, read_ayss, "ayss")
    if folder.versions.is_file():  # optional: no problem recorded when absent
        try:
            run.versions = read_versions(folder.versions)
        except AyssError as exc:
            run.problems.append(f"{VERSIONS_JSON} unreadable ({exc})")
    _check_empty(run)
    _check_ayss(run)
    run.training = read_training(run_dir)
    return run


def _load_config(run: Run, folder: RunFolder) -> None:
    """Fills case, VUT, seed, VUT description and reward from ``config.yaml``."""
    if not folder.config.is_file():
        run.problems.append(
            f"{CONFIG_YAML} missing (case, VUT and seed taken from the folder path)"
        )
        return
    try:
        config: RunConfig = read_run_config(folder.config)
        env = config.experiment.get("env") or {}
        if not isinstance(env, Mapping):
            raise ConfigError("env is not a mapping")
    except AyssError as exc:
        run.problems.append(f"{CONFIG_YAML} unreadable ({exc})")
        return
    run.case = str(env.get("case", run.case))
    run.vut = config.vut
    run.seed = config.seed
    run.vut_description = _vut_description(env, run.vut)
    try:
        # Only the reward section is rebuilt: the whole experiment would import torch.
        run.reward = build(RewardConfig, env.get("reward") or {}, "env.reward", run.path)
    except (ConfigError, TypeError) as exc:
        run.problems.append(f"{CONFIG_YAML}: reward section invalid ({exc})")
        return
    try:
        run.harm_scale = harm_scale_of(run.reward, env)
    except (ConfigError, TypeError, ValueError) as exc:
        run.problems.append(f"{CONFIG_YAML}: episode timing invalid ({exc})")


def _check_empty(run: Run) -> None:
    """Notes a table that was read but holds no row (a header only: a half-written run)."""
    curve = run.eval_curve
    if curve is not None and curve.step.size == 0 and not curve.n_dropped:
        run.problems.append(f"{EVAL_CSV}: no rows (header only), so no learning curve")
    if run.ayss is not None and len(run.ayss) == 0:
        run.problems.append(f"{AYSS_CSV}: no rows (header only), so no AYSS sample")


def _check_ayss(run: Run) -> None:
    """Notes an AYSS file that holds another case's indicator."""
    ayss = run.ayss
    if ayss is None or ayss.indicator_name is None:
        return
    expected_case = case_of_indicator(ayss.indicator_name)
    if expected_case is not None and expected_case != run.case:
        run.problems.append(
            f"{AYSS_CSV}: indicator {ayss.indicator_name!r} belongs to {expected_case}, "
            f"not {run.case}"
        )


# --------------------------------------------------------------------------- cases


def analyse_runs(
    runs: Sequence[Run], options: CaseOptions, *, paper: bool = True
) -> list[CaseAnalysis]:
    """The analysis of every case among ``runs``, each computed once, in :func:`group_runs`
    order (:func:`~sumo_ayss.analysis.case.analyse_case` on the case's runs and its
    cross-play table, :func:`~sumo_ayss.report.episodes.load_crossplay`).

    Args:
        runs: Loaded runs (any cases and VUTs).
        options: Statistical settings.
        paper: Compute the paper mode (the AYSS bootstrap, the slow part).
    """
    return [
        analyse_case(case, by_vut, options, crossplay=load_crossplay(by_vut), paper=paper)
        for case, by_vut in group_runs(runs).items()
    ]
