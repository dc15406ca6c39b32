"""The pipeline's own sections: ``grid``, ``experiments``, ``evaluate`` (with ``ayss``),
``report``, ``vuts``, ``out`` and the parallelism (see :mod:`sumo_ayss.pipeline`)."""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

from sumo_ayss.cases import case_names, default_grid_cases
from sumo_ayss.config.ayss import AyssConfig
from sumo_ayss.config.budget import BUDGETS, DEFAULT_BUDGET
from sumo_ayss.config.env import PROJECT_ROOT, Case
from sumo_ayss.config.mapping import build
from sumo_ayss.config.report import ReportOptions
from sumo_ayss.config.yaml_io import read_yaml
from sumo_ayss.util.frozen import FrozenMap
from sumo_ayss.util.validation import (
    check_choice,
    check_int,
    check_number,
    check_seed,
    require,
    suggest,
)
from sumo_ayss.vuts.catalog import VehicleType
from sumo_ayss.vuts.reference_types import DEFAULT_REFERENCE, REFERENCE_VUTS


@dataclass(frozen=True)
class GridConfig:
    """The grid of jobs. Section ``grid``."""

    SECTION: ClassVar[str] = "grid"

    cases: tuple[Case, ...] = field(default_factory=default_grid_cases)
    """Registered cases (:mod:`sumo_ayss.cases`); default: those of the default grid (the
    paper's two and any registered with ``default_grid``)."""
    vuts: tuple[str, ...] = ("pi1", "pi2")
    seeds: tuple[int, ...] | None = None
    """Training seeds, each run by every VUT; None (the default): the pipeline's budget
    decides (seeds 0 .. n-1, :mod:`sumo_ayss.config.budget`; read them as
    :attr:`PipelineConfig.seeds`)."""

    def __post_init__(self) -> None:
        for name in ("cases", "vuts", "seeds"):
            values = getattr(self, name)
            if values is None:
                continue  # seeds: the pipeline's budget decides
            require(len(values) > 0, f"grid.{name} must not be empty")
            require(len(set(values)) == len(values), f"grid.{name} has duplicates: {list(values)}")
        for i, case in enumerate(self.cases):
            check_choice(f"grid.cases[{i}]", case, case_names())
        for seed in self.seeds or ():
            check_seed(seed, "grid.seeds[]")


@dataclass(frozen=True)
class EvaluateConfig:
    """The outcome and AYSS stages of every job. Section ``evaluate``."""

    SECTION: ClassVar[str] = "evaluate"

    n_outcome: int = 200
    """Outcome episodes per job (paper: 200)."""
    ayss: AyssConfig = field(default_factory=AyssConfig)
    """Monte Carlo settings of the AYSS stage (section ``evaluate.ayss``)."""
    n_ayss: int | None = None
    """Shorthand for ``ayss.n_samples`` (Monte Carlo draws), or None: ``ayss`` decides."""
    reference: str | None = DEFAULT_REFERENCE
    """The reference driver that replays every crash of the outcome and cross-play stages
    to label it preventable or not (``cc_driver``, ``fsm``, ``rss``;
    :mod:`sumo_ayss.scenarios.preventability`); None (YAML ``null``): no labels."""
    reference_rows: tuple[str, ...] = tuple(REFERENCE_VUTS)
    """Reference drivers that drive against the pooled opponents in cross-play
    (``crossplay_reference.csv``): every VUT is then compared with each (the careful human
    first). Empty: none."""

    def __post_init__(self) -> None:
        s = self.SECTION
        require(self.n_outcome >= 1, f"{s}.n_outcome must be >= 1, got {self.n_outcome}")
        if self.reference is not None:
            check_choice(f"{s}.reference", self.reference, sorted(REFERENCE_VUTS))
        object.__setattr__(self, "reference_rows", tuple(self.reference_rows))
        for i, name in enumerate(self.reference_rows):
            check_choice(f"{s}.reference_rows[{i}]", name, sorted(REFERENCE_VUTS))
        if self.n_ayss is None or self.n_ayss == self.ayss.n_samples:
            return
        require(self.n_ayss >= 1, f"{s}.n_ayss must be >= 1, got {self.n_ayss}")
        require(
            self.ayss.n_samples == AyssConfig().n_samples,
            f"{s}.n_ayss ({self.n_ayss}) and {s}.ayss.n_samples ({self.ayss.n_samples}) "
            "differ; give one of them",
        )
        object.__setattr__(self, "ayss", dataclasses.replace(self.ayss, n_samples=self.n_ayss))


def _default_experiments() -> dict[str, Path]:
    """``configs/<case>.yaml`` of every registered case."""
    return {case: PROJECT_ROOT / "configs" / f"{case}.yaml" for case in case_names()}


@dataclass(frozen=True)
class PipelineConfig:
    """A whole batch: grid, experiment file per case, output folder, parallelism."""

    grid: GridConfig = field(default_factory=GridConfig)
    experiments: Mapping[str, Path] = field(default_factory=_default_experiments)
    """Experiment YAML per case; default: ``configs/<case>.yaml`` of every registered case."""
    out: Path = Path("runs") / "paper"
    budget: str | None = DEFAULT_BUDGET
    """A named budget (:data:`~sumo_ayss.config.budget.BUDGETS`: ``fast``, the default,
    ``verdict``, ``quick`` or ``paper``) that sets ``total_timesteps``, ``eval_every``,
    ``grid.seeds``, the AYSS draws and (``fast``) the learning rate where they are not
    given; None: every experiment's ``train`` section as its file says."""
    total_timesteps: int | None = None
    """Transitions per run for every experiment; None: the budget's (or the experiment's)."""
    eval_every: int | None = None
    """Transitions between SPCP candidates; None: the budget's (or the experiment's)."""
    learning_rate: float | None = None
    """Every experiment's ``agent.learning_rate`` (Adam, > 0); None: the budget's where it
    names one (``fast``), else the experiment's."""
    early_stop_patience: int | None = None
    """Every experiment's ``train.early_stop_patience`` (stop a run once its candidates stop
    moving, :mod:`sumo_ayss.analysis.early_stop`); None: the experiment's (off by default)."""
    early_stop_margin_se: float | None = None
    """Every experiment's ``train.early_stop_margin_se``; None: the experiment's."""
    max_seeds: int | None = None
    """Adaptive seeding: a case whose cross-play ranking has not settled after ``grid.seeds``
    gets one more seed per VUT at a time (the next integer after the last seed), up to this
    many seeds per VUT (:mod:`sumo_ayss.grid.adaptive`). None: the budget's cap when the budget
    also chose the seeds (``fast``: 7), else ``len(grid.seeds)``, a fixed grid."""
    evaluate: EvaluateConfig = field(default_factory=EvaluateConfig)
    vuts: Mapping[str, VehicleType] = field(default_factory=dict)
    """Extra VUTs (catalog syntax, as in ``env.vuts``) added to every case's experiment, so
    that a leaderboard defines its VUTs once for all cases."""
    report: ReportOptions = field(default_factory=ReportOptions)
    """Statistical settings and analysis mode of the report and the ranking."""
    expected_order: tuple[str, ...] = ()
    """A known safety order of the grid's VUTs, safest first (validation studies such as
    ladders): ``rank`` then reports Kendall's τ of its ranking against it and whether the
    two ends differ significantly. Empty: no known order."""
    workers: int = 0
    retries: int = 1
    follower: bool | None = None
    """A follower behind the VUT in every case's evaluation episodes (true) or in none
    (false; the paper's protocol); None: as each experiment's ``env.follower.enabled``
    says (the shipped ``configs/<case>.yaml``: on)."""

    def __post_init__(self) -> None:
        if self.budget is not None:
            check_choice("budget", self.budget, BUDGETS)
            b = BUDGETS[self.budget]
            if self.total_timesteps is None:
                object.__setattr__(self, "total_timesteps", b.total_timesteps)
            if self.eval_every is None:
                object.__setattr__(self, "eval_every", b.eval_every)
            if self.learning_rate is None and b.learning_rate is not None:
                object.__setattr__(self, "learning_rate", b.learning_rate)
            ev = self.evaluate
            if (
                b.n_ayss is not None
                and ev.n_ayss is None
                and ev.ayss.n_samples == AyssConfig().n_samples
            ):
                ayss = dataclasses.replace(ev.ayss, n_samples=b.n_ayss)
                evaluate = dataclasses.replace(ev, n_ayss=b.n_ayss, ayss=ayss)
                object.__setattr__(self, "evaluate", evaluate)
        if self.grid.seeds is None:
            n = BUDGETS[self.budget].seeds if self.budget is not None else 3
            object.__setattr__(self, "grid", dataclasses.replace(self.grid, seeds=tuple(range(n))))
            if self.max_seeds is None and self.budget is not None:
                object.__setattr__(self, "max_seeds", BUDGETS[self.budget].max_seeds)
        n_seeds = len(self.seeds)
        if self.max_seeds is None:
            object.__setattr__(self, "max_seeds", n_seeds)
        require(
            isinstance(self.max_seeds, int)
            and not isinstance(self.max_seeds, bool)
            and n_seeds <= self.max_seeds <= MAX_SEEDS_CAP,
            f"max_seeds must be an integer from the {n_seeds} seeds of grid.seeds to "
            f"{MAX_SEEDS_CAP} (absent: the budget's cap, or a fixed grid), got {self.max_seeds!r}",
        )
        for name in ("total_timesteps", "eval_every"):
            value = getattr(self, name)
            require(
                value is None or (isinstance(value, int) and value >= 1),
                f"{name} must be an integer >= 1 (or absent: the budget's or the experiment's), "
                f"got {value!r}",
            )
        if self.total_timesteps is not None and self.eval_every is not None:
            require(
                self.eval_every <= self.total_timesteps,
                f"eval_every ({self.eval_every}) must be <= total_timesteps "
                f"({self.total_timesteps}): a run needs at least one SPCP candidate (a "
                "smaller total_timesteps than the budget's needs a smaller eval_every too)",
            )
        if self.learning_rate is not None:
            check_number("learning_rate", self.learning_rate, low=0.0, low_open=True)
        check_int("early_stop_patience", self.early_stop_patience, 1, none_ok=True)
        if self.early_stop_margin_se is not None:
            check_number("early_stop_margin_se", self.early_stop_margin_se, 0.0)
        require(self.workers >= 0, f"workers must be >= 0, got {self.workers}")
        require(self.retries >= 0, f"retries must be >= 0, got {self.retries}")
        if self.expected_order:
            require(
                sorted(self.expected_order) == sorted(self.grid.vuts),
                f"expected_order must list exactly the grid's VUTs {sorted(self.grid.vuts)}, "
                f"got {list(self.expected_order)}",
            )
        object.__setattr__(self, "vuts", FrozenMap(self.vuts))
        for name, vt in self.vuts.items():
            vt.validate(f"vuts.{name}")
        known = case_names()
        for case in self.experiments:
            require(
                case in known,
                f"experiments.{case}: unknown case{suggest(case, known)}; allowed: {list(known)}",
            )
        for case in self.grid.cases:
            require(
                case in self.experiments,
                f"experiments has no file for case {case!r}; given: {sorted(self.experiments)}",
            )

    @property
    def seeds(self) -> tuple[int, ...]:
        """The grid's training seeds (given, or the budget's)."""
        assert self.grid.seeds is not None  # resolved in __post_init__
        return self.grid.seeds

    @property
    def added_seeds(self) -> tuple[int, ...]:
        """The seeds adaptive seeding may add, in order: the integers after the last of
        ``grid.seeds``, ``max_seeds - len(grid.seeds)`` of them (empty: a fixed grid)."""
        assert self.max_seeds is not None  # resolved in __post_init__
        last = max(self.seeds)
        return tuple(range(last + 1, last + 1 + self.max_seeds - len(self.seeds)))

    @property
    def n_workers(self) -> int:
        return self.workers or os.cpu_count() or 1


MAX_SEEDS_CAP = 64
"""The most seeds per VUT adaptive seeding may reach."""


def load_pipeline(path: str | Path | None, **overrides: Any) -> PipelineConfig:
    """Pipeline YAML over defaults, then ``overrides`` (None values are ignored).

    ``budget`` replaces the YAML's budget before the budget fills the settings the YAML
    leaves open; the other overrides replace resolved fields: fields of
    :class:`PipelineConfig` and ``seeds`` (``grid.seeds``), ``n_outcome``
    (``evaluate.n_outcome``) and ``n_ayss`` (``evaluate.n_ayss``, which then also sets
    ``evaluate.ayss.n_samples``). They enter the resolved configuration that the pipeline
    writes (``pipeline.json``, each run's ``config.yaml``), so a run made with command-line
    overrides is reproduced from its files.
    """
    clean = {k: v for k, v in overrides.items() if v is not None}
    data: dict[str, Any] = {} if path is None else dict(read_yaml(Path(path)) or {})
    if "budget" in clean:
        budget = clean.pop("budget")
        data["budget"] = None if budget == "none" else budget
    seeds = clean.pop("seeds", None)
    if seeds is not None:  # before the budget resolves: named seeds make a fixed grid
        data["grid"] = {**(data.get("grid") or {}), "seeds": [int(x) for x in seeds]}
    if "max_seeds" in clean:
        data["max_seeds"] = clean.pop("max_seeds")
    base = PROJECT_ROOT if path is None else Path(path).resolve().parent
    cfg = build(PipelineConfig, data, "", base) if data else PipelineConfig()
    evaluate = cfg.evaluate
    n_outcome = clean.pop("n_outcome", None)
    if n_outcome is not None:
        evaluate = dataclasses.replace(evaluate, n_outcome=n_outcome)
    n_ayss = clean.pop("n_ayss", None)
    if n_ayss is not None:
        require(n_ayss >= 1, f"evaluate.n_ayss must be >= 1, got {n_ayss}")
        ayss = dataclasses.replace(evaluate.ayss, n_samples=n_ayss)
        evaluate = dataclasses.replace(evaluate, n_ayss=n_ayss, ayss=ayss)
    if evaluate is not cfg.evaluate:
        clean["evaluate"] = evaluate
    return dataclasses.replace(cfg, **clean) if clean else cfg
