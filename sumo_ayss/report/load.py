"""Read run folders back for the report, tolerating missing and half-written files.

A run folder ``<out>/<case>/<vut>/seed_<k>/`` is written by :mod:`sumo_ayss.train` and by the
evaluate stage. Every file name, every ``outcome.json`` key and every ``ayss.csv`` column the
report relies on is named once, here (:data:`RUN_FILES`, :data:`OUTCOME_KEYS`,
:data:`AYSS_COLUMNS`, :data:`EVAL_COLUMNS_USED`), so the report can be aligned with the
writers in one place.

Nothing here raises on a missing or unreadable file: :func:`load_run` records a sentence per
problem in :attr:`Run.problems` and leaves the field empty, so a report on a run that has not
been evaluated yet says what is missing instead of crashing. This module imports neither
SUMO nor torch.
"""

from __future__ import annotations

import csv
import json
import logging
import math
import re
from collections import Counter
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from numpy.typing import NDArray

from sumo_ayss.config import RewardConfig, build, safe_load_yaml
from sumo_ayss.errors import ConfigError
from sumo_ayss.report.checks import Training, read_training

__all__ = [
    "AYSS_COLUMNS",
    "EVAL_COLUMNS_USED",
    "OUTCOME_KEYS",
    "RUN_FILES",
    "AyssSamples",
    "Estimate",
    "EvalCurve",
    "Outcome",
    "OutcomeKeys",
    "OutcomeSubset",
    "Run",
    "RunFiles",
    "SpcpChoice",
    "find_run_dirs",
    "group_runs",
    "load_run",
    "read_ayss",
    "read_eval_curve",
    "read_outcome",
]

logger = logging.getLogger(__name__)


# --------------------------------------------------------------------------- names, in one place


@dataclass(frozen=True)
class RunFiles:
    """File names inside a run folder."""

    config: str = "config.yaml"
    eval_table: str = "eval.csv"
    spcp: str = "spcp.json"
    outcome: str = "outcome.json"
    ayss: str = "ayss.csv"
    versions: str = "versions.json"


RUN_FILES = RunFiles()
"""The file names the report reads."""


@dataclass(frozen=True)
class OutcomeKeys:
    """Keys of ``outcome.json`` (the 200 outcome episodes of one SPCP).

    Expected layout (rates are fractions in [0, 1], returns per episode, headways in m)::

        {"n": 200,
         "crash_rate": {"value": 0.01, "lo": 0.0, "hi": 0.03},
         "lane_change_rate": {...},            # cut-in only
         "mean_return": {...},
         "mean_final_headway_m": {...},
         "lane_change_no_collision": {         # cut-in only: episodes with a lane change
             "n": 180,                         # and no collision (the paper's Table III)
             "mean_return": {...},
             "mean_final_headway_m": {...}}}

    An estimate may also be a bare number, or carry its interval as ``"ci": [lo, hi]``;
    the value may be named by any of :attr:`value`, the bounds by :attr:`lo` / :attr:`hi`.
    """

    n: str = "n"
    crash_rate: str = "crash_rate"
    lane_change_rate: str = "lane_change_rate"
    mean_return: str = "mean_return"
    mean_final_headway_m: str = "mean_final_headway_m"
    lane_change_no_collision: str = "lane_change_no_collision"
    summary: str = "summary"
    lc_no_collision_return: str = "lc_no_collision_return"
    lc_no_collision_final_headway_m: str = "lc_no_collision_final_headway_m"
    value: tuple[str, ...] = ("value", "mean", "point", "estimate")
    lo: tuple[str, ...] = ("lo", "ci_lo", "lower")
    hi: tuple[str, ...] = ("hi", "ci_hi", "upper")
    ci: str = "ci"
    n_aliases: tuple[str, ...] = ("n", "n_episodes")


OUTCOME_KEYS = OutcomeKeys()
"""The ``outcome.json`` keys the report reads."""


@dataclass(frozen=True)
class AyssColumns:
    """Columns of ``ayss.csv``: one row per adversarial-yet-safe sample.

    Only :attr:`h` and :attr:`indicator` are required; :attr:`indicator_name` says which
    indicator the file holds (:data:`INDICATOR_NAMES`).
    """

    v_pov: str = "v_pov_mps"
    v_vut: str = "v_vut_mps"
    h: str = "h_m"
    same_lane: str = "same_lane"
    action: str = "action"
    target_speed_mps: str = "target_speed_mps"
    ttc_s: str = "ttc_s"
    indicator: str = "indicator"
    indicator_name: str = "indicator_name"


AYSS_COLUMNS = AyssColumns()
"""The ``ayss.csv`` columns the report reads."""

#: ``indicator_name`` values in ``ayss.csv`` and the case whose indicator each is.
INDICATOR_NAMES: Mapping[str, str] = {
    "pov_accel_mps2": "car_following",
    "delta_v_bar_mps": "cut_in",
}

#: Columns of ``eval.csv`` the report reads (``step`` and ``mean_return`` are required).
EVAL_COLUMNS_USED: tuple[str, ...] = (
    "step",
    "mean_return",
    "std_return",
    "crash_rate",
    "lane_change_rate",
    "mean_final_headway_m",
    "n_episodes",
)

_SEED_DIR = re.compile(r"^seed_(-?\d+)$")


# --------------------------------------------------------------------------- records


@dataclass(frozen=True)
class Estimate:
    """A point estimate with its confidence interval; NaN where unknown.

    Attributes:
        value: Point estimate, in the quantity's unit (rates as fractions).
        lo: Lower confidence bound.
        hi: Upper confidence bound.
    """

    value: float = math.nan
    lo: float = math.nan
    hi: float = math.nan

    @property
    def known(self) -> bool:
        """Whether the point estimate is a finite number."""
        return math.isfinite(self.value)


@dataclass(frozen=True)
class OutcomeSubset:
    """Outcome over a subset of episodes (cut-in: a lane change and no collision).

    Attributes:
        n: Episodes in the subset, or None if not stated.
        mean_return: Mean episode reward over the subset.
        mean_final_headway_m: Mean headway at the last step over the subset, m.
    """

    n: int | None
    mean_return: Estimate
    mean_final_headway_m: Estimate


@dataclass(frozen=True)
class Outcome:
    """Summary of the outcome episodes of one SPCP (paper Tables II and III).

    Attributes:
        n: Number of outcome episodes, or None if not stated.
        crash_rate: Fraction of episodes with a collision, in [0, 1].
        lane_change_rate: Fraction of episodes with a POV lane change (cut-in), or None.
        mean_return: Mean episode reward over all episodes.
        mean_final_headway_m: Mean headway at the last step over all episodes, m.
        lane_change_no_collision: The same over episodes with a lane change and no
            collision (cut-in), or None.
    """

    n: int | None
    crash_rate: Estimate
    lane_change_rate: Estimate | None
    mean_return: Estimate
    mean_final_headway_m: Estimate
    lane_change_no_collision: OutcomeSubset | None


def _empty_f() -> NDArray[np.float64]:
    return np.empty(0, dtype=np.float64)


@dataclass(frozen=True)
class EvalCurve:
    """The SPCP-candidate evaluations of one run (``eval.csv``), sorted by step.

    Attributes:
        step: Training steps of each candidate, shape ``(k,)``.
        mean_return: Mean evaluation episode reward, shape ``(k,)``.
        crash_rate: Fraction of evaluation episodes with a collision, shape ``(k,)``; NaN
            where the column is missing.
        lane_change_rate: Fraction with a lane change, shape ``(k,)``; NaN where missing.
        mean_final_headway_m: Mean final headway in m, shape ``(k,)``; NaN where missing.
    """

    step: NDArray[np.float64] = field(default_factory=_empty_f)
    mean_return: NDArray[np.float64] = field(default_factory=_empty_f)
    crash_rate: NDArray[np.float64] = field(default_factory=_empty_f)
    lane_change_rate: NDArray[np.float64] = field(default_factory=_empty_f)
    mean_final_headway_m: NDArray[np.float64] = field(default_factory=_empty_f)
    n_dropped: int = 0
    """Rows skipped because ``step`` or ``mean_return`` was not a finite number."""

    def __len__(self) -> int:
        return int(self.step.size)


@dataclass(frozen=True)
class SpcpChoice:
    """The selected SPCP of a run (``spcp.json``).

    Attributes:
        step: Training step of the selected candidate.
        score: Its selection score.
        criterion: Name of the selection criterion.
        reason: The selection's own sentence.
    """

    step: int
    score: float
    criterion: str
    reason: str


@dataclass(frozen=True)
class AyssSamples:
    """The adversarial-yet-safe samples of one SPCP (``ayss.csv``).

    Attributes:
        h: Distance headway per sample, m, shape ``(n,)``, finite.
        indicator: Aggressiveness indicator per sample, shape ``(n,)``, finite: POV
            acceleration in m/s² or Δv̄ in m/s; more negative = more aggressive.
        indicator_name: The file's ``indicator_name`` (most common value), or None.
        n_dropped: Rows dropped because ``h`` or the indicator was not a finite number.
    """

    h: NDArray[np.float64]
    indicator: NDArray[np.float64]
    indicator_name: str | None
    n_dropped: int = 0

    def __len__(self) -> int:
        return int(self.h.size)


@dataclass
class Run:
    """Everything the report reads from one run folder; fields are None when unavailable.

    Attributes:
        path: The run folder.
        case: ``"car_following"`` or ``"cut_in"`` (from ``config.yaml``, else the folder path).
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
    problems: list[str] = field(default_factory=list)

    @property
    def label(self) -> str:
        """``"pi1 seed 0"``."""
        return f"{self.vut} seed {self.seed if self.seed is not None else '?'}"


# --------------------------------------------------------------------------- finding runs


def _is_run_dir(path: Path) -> bool:
    """A folder holding a run's config or evaluation table, or named ``seed_<k>``."""
    return (
        (path / RUN_FILES.config).is_file()
        or (path / RUN_FILES.eval_table).is_file()
        or bool(_SEED_DIR.match(path.name))
    )


def find_run_dirs(paths: Iterable[str | Path]) -> list[Path]:
    """Run folders among ``paths`` and below them, each once, in a stable order.

    A path that is itself a run folder is taken as is; any other folder is searched
    recursively for run folders (a run folder is not searched further).

    Args:
        paths: Run folders and/or root folders.

    Returns:
        Resolved run folders, in the order first found (roots in the order given, folders
        below a root sorted by path).

    Raises:
        ConfigError: If a path does not exist or is not a folder.
    """
    found: list[Path] = []
    seen: set[Path] = set()
    for raw in paths:
        root = Path(raw).expanduser()
        if not root.is_dir():
            raise ConfigError(f"run folder or root: not a folder: {root}")
        for run_dir in _walk_runs(root.resolve()):
            if run_dir not in seen:
                seen.add(run_dir)
                found.append(run_dir)
    return found


def _walk_runs(root: Path) -> list[Path]:
    if _is_run_dir(root):
        return [root]
    out: list[Path] = []
    for child in sorted(p for p in root.iterdir() if p.is_dir() and not p.name.startswith(".")):
        out.extend(_walk_runs(child))
    return out


def group_runs(runs: Sequence[Run]) -> dict[str, dict[str, list[Run]]]:
    """Runs grouped by case, then VUT; cases car-following first, VUTs and seeds sorted.

    Args:
        runs: Loaded runs.

    Returns:
        ``{case: {vut: [runs sorted by seed]}}``.
    """
    order = {"car_following": 0, "cut_in": 1}
    out: dict[str, dict[str, list[Run]]] = {}
    for case in sorted({r.case for r in runs}, key=lambda c: (order.get(c, 9), c)):
        by_vut: dict[str, list[Run]] = {}
        for vut in sorted({r.vut for r in runs if r.case == case}):
            members = [r for r in runs if r.case == case and r.vut == vut]
            by_vut[vut] = sorted(members, key=lambda r: (r.seed is None, r.seed or 0, str(r.path)))
        out[case] = by_vut
    return out


# --------------------------------------------------------------------------- readers


def _number(value: Any) -> float:
    """``value`` as a float, NaN when it is not a number."""
    if isinstance(value, bool) or value is None:
        return math.nan
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan


def _first(data: Mapping[str, Any], names: Sequence[str]) -> Any:
    for name in names:
        if name in data:
            return data[name]
    return None


def _estimate(value: Any) -> Estimate | None:
    """An :class:`Estimate` from a number or a mapping (see :class:`OutcomeKeys`)."""
    keys = OUTCOME_KEYS
    if value is None:
        return None
    if not isinstance(value, Mapping):
        return Estimate(_number(value))
    point = _number(_first(value, keys.value))
    lo, hi = _number(_first(value, keys.lo)), _number(_first(value, keys.hi))
    ci = value.get(keys.ci)
    if isinstance(ci, Sequence) and not isinstance(ci, str) and len(ci) == 2:
        lo, hi = _number(ci[0]), _number(ci[1])
    return Estimate(point, lo, hi)


def _count(data: Mapping[str, Any]) -> int | None:
    n = _number(_first(data, OUTCOME_KEYS.n_aliases))
    return int(n) if math.isfinite(n) else None


def read_outcome(path: Path) -> Outcome:
    """Parses ``outcome.json``; unknown keys are ignored, missing ones become NaN / None.

    Args:
        path: The file.

    Returns:
        The :class:`Outcome`.

    Raises:
        OSError: If the file cannot be read.
        ValueError: If it is not JSON or its top level is not an object.
    """
    data = json.loads(path.read_text())
    if not isinstance(data, Mapping):
        raise ValueError("top level is not a JSON object")
    keys = OUTCOME_KEYS
    # The evaluate stage nests the estimates under "summary" (sumo_ayss.scenarios.outcome).
    if isinstance(data.get(keys.summary), Mapping):
        data = data[keys.summary]
    subset = data.get(keys.lane_change_no_collision)
    lc_subset = None
    if isinstance(subset, Mapping):
        lc_subset = OutcomeSubset(
            n=_count(subset),
            mean_return=_estimate(subset.get(keys.mean_return)) or Estimate(),
            mean_final_headway_m=_estimate(subset.get(keys.mean_final_headway_m)) or Estimate(),
        )
    elif isinstance(data.get(keys.lc_no_collision_return), Mapping):
        lc_return = _estimate(data.get(keys.lc_no_collision_return)) or Estimate()
        lc_subset = OutcomeSubset(
            n=_count(data[keys.lc_no_collision_return]),
            mean_return=lc_return,
            mean_final_headway_m=_estimate(data.get(keys.lc_no_collision_final_headway_m))
            or Estimate(),
        )
    return Outcome(
        n=_count(data),
        crash_rate=_estimate(data.get(keys.crash_rate)) or Estimate(),
        lane_change_rate=_estimate(data.get(keys.lane_change_rate)),
        mean_return=_estimate(data.get(keys.mean_return)) or Estimate(),
        mean_final_headway_m=_estimate(data.get(keys.mean_final_headway_m)) or Estimate(),
        lane_change_no_collision=lc_subset,
    )


def read_eval_curve(path: Path) -> EvalCurve:
    """Parses ``eval.csv`` (any column order; extra columns ignored), sorted by step.

    Args:
        path: The file.

    Returns:
        The :class:`EvalCurve`; rows whose ``step`` or ``mean_return`` is not a number are
        skipped.

    Raises:
        OSError: If the file cannot be read.
        ValueError: If ``step`` or ``mean_return`` is not a column.
    """
    with path.open(newline="") as f:
        reader = csv.DictReader(f)
        columns = set(reader.fieldnames or ())
        missing = [c for c in ("step", "mean_return") if c not in columns]
        if missing:
            raise ValueError(f"missing column(s) {missing}")
        rows = [{c: _number(row.get(c)) for c in EVAL_COLUMNS_USED} for row in reader]
    n_read = len(rows)
    rows = [r for r in rows if math.isfinite(r["step"]) and math.isfinite(r["mean_return"])]
    rows.sort(key=lambda r: r["step"])

    def col(name: str) -> NDArray[np.float64]:
        return np.array([r[name] for r in rows], dtype=np.float64)

    return EvalCurve(
        step=col("step"),
        mean_return=col("mean_return"),
        crash_rate=col("crash_rate"),
        lane_change_rate=col("lane_change_rate"),
        mean_final_headway_m=col("mean_final_headway_m"),
        n_dropped=n_read - len(rows),
    )


def read_ayss(path: Path) -> AyssSamples:
    """Parses ``ayss.csv``: headway and indicator of every sample.

    Args:
        path: The file.

    Returns:
        The :class:`AyssSamples`; rows with a non-numeric or non-finite ``h`` or indicator
        are dropped and counted.

    Raises:
        OSError: If the file cannot be read.
        ValueError: If the ``h`` or ``indicator`` column is missing.
    """
    cols = AYSS_COLUMNS
    with path.open(newline="") as f:
        reader = csv.DictReader(f)
        columns = set(reader.fieldnames or ())
        missing = [c for c in (cols.h, cols.indicator) if c not in columns]
        if missing:
            raise ValueError(f"missing column(s) {missing}")
        h_list: list[float] = []
        y_list: list[float] = []
        names: Counter[str] = Counter()
        for row in reader:
            h_list.append(_number(row.get(cols.h)))
            y_list.append(_number(row.get(cols.indicator)))
            name = (row.get(cols.indicator_name) or "").strip()
            if name:
                names[name] += 1
    h = np.array(h_list, dtype=np.float64)
    y = np.array(y_list, dtype=np.float64)
    ok = np.isfinite(h) & np.isfinite(y)
    return AyssSamples(
        h=h[ok],
        indicator=y[ok],
        indicator_name=names.most_common(1)[0][0] if names else None,
        n_dropped=int(np.count_nonzero(~ok)),
    )


def _read_spcp(path: Path) -> SpcpChoice:
    data = json.loads(path.read_text())
    if not isinstance(data, Mapping) or "step" not in data:
        raise ValueError("expected a JSON object with a 'step'")
    return SpcpChoice(
        step=int(data["step"]),
        score=_number(data.get("score")),
        criterion=str(data.get("criterion", "")),
        reason=str(data.get("reason", "")),
    )


def _read_versions(path: Path) -> dict[str, str]:
    data = json.loads(path.read_text())
    if not isinstance(data, Mapping):
        raise ValueError("expected a JSON object")
    return {str(k): str(v) for k, v in data.items()}


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


def _from_path(path: Path) -> tuple[str, str, int | None]:
    """``(case, vut, seed)`` guessed from ``<case>/<vut>/seed_<k>``."""
    match = _SEED_DIR.match(path.name)
    seed = int(match.group(1)) if match else None
    return path.parent.parent.name or "unknown", path.parent.name or "unknown", seed


def load_run(path: str | Path) -> Run:
    """Reads one run folder; never raises for missing or unreadable files.

    Args:
        path: The run folder ``<out>/<case>/<vut>/seed_<k>/``.

    Returns:
        The :class:`Run`; each file that is missing or cannot be parsed leaves its field
        None and adds a sentence to :attr:`Run.problems`.
    """
    run_dir = Path(path).resolve()
    case, vut, seed = _from_path(run_dir)
    run = Run(path=run_dir, case=case, vut=vut, seed=seed)
    _load_config(run)

    def attempt(name: str, reader: Any, attr: str) -> None:
        file = run_dir / name
        if not file.is_file():
            run.problems.append(f"{name} missing")
            return
        try:
            setattr(run, attr, reader(file))
        except (OSError, ValueError, TypeError, KeyError, csv.Error) as exc:
            run.problems.append(f"{name} unreadable ({exc})")
            logger.warning("%s: %s unreadable: %s", run_dir, name, exc)

    attempt(RUN_FILES.eval_table, read_eval_curve, "eval_curve")
    if run.eval_curve is not None and run.eval_curve.n_dropped:
        run.problems.append(
            f"{RUN_FILES.eval_table}: {run.eval_curve.n_dropped} candidate row(s) without a "
            "finite step or mean_return dropped"
        )
    attempt(RUN_FILES.spcp, _read_spcp, "spcp")
    attempt(RUN_FILES.outcome, read_outcome, "outcome")
    attempt(RUN_FILES.ayss, read_ayss, "ayss")
    versions_file = run_dir / RUN_FILES.versions
    if versions_file.is_file():  # optional: no problem recorded when absent
        try:
            run.versions = _read_versions(versions_file)
        except (OSError, ValueError) as exc:
            run.problems.append(f"{RUN_FILES.versions} unreadable ({exc})")
    _check_ayss(run)
    run.training = read_training(run_dir)
    return run


def _load_config(run: Run) -> None:
    """Fills case, VUT, seed, VUT description and reward from ``config.yaml``."""
    file = run.path / RUN_FILES.config
    if not file.is_file():
        run.problems.append(
            f"{RUN_FILES.config} missing (case, VUT and seed taken from the folder path)"
        )
        return
    try:
        data = safe_load_yaml(file.read_text(encoding="utf-8"), str(file)) or {}
        if not isinstance(data, Mapping):
            raise ValueError("top level is not a mapping")
        env = data.get("env") or {}
        if not isinstance(env, Mapping):
            raise ValueError("env is not a mapping")
    except (OSError, ValueError, yaml.YAMLError) as exc:  # ConfigError is a ValueError
        run.problems.append(f"{RUN_FILES.config} unreadable ({exc})")
        return
    run.case = str(env.get("case", run.case))
    run.vut = str(data.get("vut", env.get("vut", run.vut)))
    seed = _number(data.get("seed"))
    if math.isfinite(seed):
        run.seed = int(seed)
    run.vut_description = _vut_description(env, run.vut)
    try:
        # Only the reward section is rebuilt: the whole experiment would import torch.
        run.reward = build(RewardConfig, env.get("reward") or {}, "env.reward", run.path)
    except (ConfigError, TypeError) as exc:
        run.problems.append(f"{RUN_FILES.config}: reward section invalid ({exc})")


def _check_ayss(run: Run) -> None:
    """Notes AYSS files that hold another case's indicator, or dropped rows."""
    ayss = run.ayss
    if ayss is None:
        return
    if ayss.n_dropped:
        run.problems.append(
            f"{RUN_FILES.ayss}: {ayss.n_dropped} row(s) without a finite h or indicator dropped"
        )
    expected_case = INDICATOR_NAMES.get(ayss.indicator_name or "")
    if ayss.indicator_name and expected_case is None:
        run.problems.append(f"{RUN_FILES.ayss}: unknown indicator_name {ayss.indicator_name!r}")
    elif expected_case is not None and expected_case != run.case:
        run.problems.append(
            f"{RUN_FILES.ayss}: indicator {ayss.indicator_name!r} belongs to {expected_case}, "
            f"not {run.case}"
        )
