"""The run record: everything a run folder holds, read once, typed, handed on.

:func:`read_run` reads a run folder ``<out>/<case>/<vut>/seed_<k>/`` through the one reader
of each file (:mod:`sumo_ayss.run_folder`) into a frozen :class:`RunRecord`. Every stage
that starts from a run folder takes that record: evaluate and cross-play (the run's
experiment, seed and SPCP), the report and rank (its tables, reduced to the arrays the
analysis needs), replay and the scripts. No other module builds its own view of a run.

Reading never raises for a missing or unreadable file: the field stays None and
:attr:`RunRecord.problems` gets a sentence naming the file, so a report on a run that has
not been evaluated yet says what is missing. A stage that cannot do without a file asks the
record for it and gets a :class:`~sumo_ayss.util.errors.CheckpointError` naming the file
(:attr:`RunRecord.experiment`).

The record holds what is stored: scoring the outcome episodes (harm, crashes, mobility) is
the analysis's (:func:`sumo_ayss.analysis.harm.run_episodes`). Imports neither SUMO nor
torch, nor the analysis.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import TypeVar

import numpy as np
from numpy.typing import NDArray

from sumo_ayss.cases import case_of_indicator
from sumo_ayss.config import ExperimentConfig, RewardConfig, build
from sumo_ayss.config.env import decisions_of
from sumo_ayss.config.identity import config_key
from sumo_ayss.records.table import Table, read_table
from sumo_ayss.run_folder.ayss_bins import AyssCells, read_ayss_bins
from sumo_ayss.run_folder.eval_table import EVAL_SCHEMA
from sumo_ayss.run_folder.layout import RunFolder, seed_of_dir
from sumo_ayss.run_folder.metadata import (
    RunConfig,
    SpcpChoice,
    read_run_config,
    read_spcp,
    stored_experiment,
)
from sumo_ayss.run_folder.metadata import read_versions as _read_versions
from sumo_ayss.run_folder.schemas import AYSS_SCHEMA, OUTCOME_SCHEMA
from sumo_ayss.run_folder.summaries import Outcome, OutcomeRecord, read_outcome_json
from sumo_ayss.training.trust import Training, all_same, training_of
from sumo_ayss.util.errors import AyssError, CheckpointError, ConfigError
from sumo_ayss.vuts.catalog import stored_description

__all__ = ["AyssSamples", "RunRecord", "read_run"]

_T = TypeVar("_T")
#: The names of the files a problem line starts with (named once, by the folder record).
_CONFIG_YAML, _EVAL_CSV, _AYSS_CSV = (
    RunFolder.config.name,
    RunFolder.eval_table.name,
    RunFolder.ayss_csv.name,
)


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


@dataclass(frozen=True, eq=False)
class RunRecord:
    """One run folder, read once (:func:`read_run`); a field is None when its file is
    missing or unreadable, and :attr:`problems` says which.

    Attributes:
        folder: The run folder's paths.
        case: The case name (``config.yaml``'s ``env.case``, else from the folder path).
        vut: VUT name (``config.yaml``, else the folder path).
        seed: Training seed (also the run's SUMO seed), or None if unknown.
        config: ``config.yaml`` as stored, or None.
        vut_description: The VUT's description from the catalog in ``config.yaml``.
        reward: The run's reward configuration, or None.
        decisions_per_episode: Decisions per episode (``config.yaml``'s episode length over
            its decision period), or None; with the reward, what scores the outcome episodes
            (:func:`sumo_ayss.analysis.harm.run_episodes`: the analysis scores, not the reader).
        eval_curve: The candidate evaluations (``eval.csv``, :data:`~.eval_table.EVAL_SCHEMA`),
            rows sorted by step, or None; ``n_dropped`` counts the damaged rows left out.
        spcp: The selected SPCP (``spcp.json``), or None.
        outcome_record: The outcome summary with its settings (``outcome.json``), or None.
        outcome_table: The outcome episodes (``outcome.csv``), or None.
        ayss: The AYSS samples (``ayss.csv``), or None.
        ayss_bins: The samples' per-cell moments (``ayss_bins.csv``), or None; read by the
            AYSS figures, table and paper mode where ``ayss.csv`` is absent
            (:func:`sumo_ayss.analysis.ayss_cells.run_cells`).
        versions: Package versions the run used (``versions.json``), or empty.
        training: Training budget and SPCP state (from ``config.yaml``, ``eval.csv`` and
            ``spcp.json``; :func:`sumo_ayss.training.trust.training_of`).
        problems: One sentence per missing or unreadable file, each starting with the
            file's name.
    """

    folder: RunFolder
    case: str
    vut: str
    seed: int | None
    config: RunConfig | None = None
    vut_description: str = ""
    reward: RewardConfig | None = None
    decisions_per_episode: int | None = None
    eval_curve: Table | None = None
    spcp: SpcpChoice | None = None
    outcome_record: OutcomeRecord | None = None
    outcome_table: Table | None = None
    ayss: AyssSamples | None = None
    ayss_bins: AyssCells | None = None
    versions: Mapping[str, str] = field(default_factory=dict)
    training: Training = field(default_factory=Training)
    problems: tuple[str, ...] = ()

    @property
    def path(self) -> Path:
        """The run folder."""
        return self.folder.path

    @property
    def outcome(self) -> Outcome | None:
        """The outcome summary (``outcome.json``), or None."""
        return self.outcome_record.outcome if self.outcome_record is not None else None

    @property
    def label(self) -> str:
        """``"pi1 seed 0"``."""
        return f"{self.vut} seed {self.seed if self.seed is not None else '?'}"

    @cached_property
    def experiment(self) -> ExperimentConfig:
        """The run's experiment, rebuilt from ``config.yaml`` (its ``env.vut`` is the run's
        VUT); for the stages that run the SPCP. Builds no env and imports no user
        controller (that happens inside ``controller_imports``, when an env is built).

        Raises:
            CheckpointError: If ``config.yaml`` is missing, unreadable or not a valid
                experiment; the message names the file.
        """
        return stored_experiment(self.folder, self._stored_config())[0]

    @property
    def config_seed(self) -> int:
        """The training seed in ``config.yaml`` (also the run's SUMO seed).

        Raises:
            CheckpointError: As :attr:`experiment`, without a readable ``config.yaml``.
        """
        return self._stored_config().seed

    def _stored_config(self) -> RunConfig:
        """:attr:`config`, or the reason there is none as a :class:`CheckpointError`."""
        if self.config is not None:
            return self.config
        if not self.folder.config.is_file():
            raise CheckpointError(f"{self.path}: not a run folder (no {_CONFIG_YAML})")
        return read_run_config(self.folder.config)  # raises the reader's own message


def _eval_table(path: Path) -> Table:
    """``eval.csv`` with its rows sorted by step (a damaged row left out: ``n_dropped``)."""
    table = read_table(path, EVAL_SCHEMA, error=CheckpointError, skip_bad_rows=True)
    order = np.argsort(table["step"], kind="stable")
    return Table(EVAL_SCHEMA, {n: table[n][order] for n in EVAL_SCHEMA.names}, table.n_dropped)


def _ayss_samples(path: Path) -> AyssSamples:
    table = read_table(path, AYSS_SCHEMA)
    names = Counter(str(n) for n in table["indicator_name"])
    return AyssSamples(
        h=np.asarray(table["h_m"], dtype=np.float64),
        indicator=np.asarray(table["indicator"], dtype=np.float64),
        indicator_name=names.most_common(1)[0][0] if names else None,
    )


# --------------------------------------------------------------------------- reading


class _Reader:
    """Reads a run's files, collecting a sentence for each that could not be read."""

    def __init__(self) -> None:
        self.problems: list[str] = []

    def attempt(
        self, file: Path, reader: Callable[[Path], _T], *, needed: bool = True
    ) -> _T | None:
        """``reader(file)``; None and a sentence when the file is missing (if ``needed``)
        or unreadable."""
        if not file.is_file():
            if needed:
                self.problems.append(f"{file.name} missing")
            return None
        try:
            return reader(file)
        except (AyssError, OSError, ValueError) as exc:
            self.problems.append(f"{file.name} unreadable ({exc})")
            return None


def read_run(path: str | Path) -> RunRecord:
    """Read one run folder; never raises for missing or unreadable files.

    Args:
        path: The run folder ``<out>/<case>/<vut>/seed_<k>/``.

    Returns:
        The :class:`RunRecord`; each file that is missing or cannot be parsed leaves its
        field None and adds a sentence to :attr:`RunRecord.problems`.
    """
    folder = RunFolder(Path(path).resolve())
    run_dir = folder.path
    r = _Reader()
    case, vut, seed = (
        run_dir.parent.parent.name or "unknown",
        run_dir.parent.name or "unknown",
        seed_of_dir(run_dir),
    )
    config = description = reward = decisions = None
    if not folder.config.is_file():
        r.problems.append(f"{_CONFIG_YAML} missing (case, VUT and seed taken from the folder path)")
    else:
        try:
            config = read_run_config(folder.config)
        except AyssError as exc:
            r.problems.append(f"{_CONFIG_YAML} unreadable ({exc})")
    if config is not None:
        env = config.experiment["env"]  # a mapping: read_run_config checks it
        case, vut, seed = str(env.get("case", case)), config.vut, config.seed
        description = stored_description(env, vut)
        try:
            # Only the reward section is rebuilt: a report does not need the experiment.
            reward = build(RewardConfig, env.get("reward") or {}, "env.reward", run_dir)
        except (ConfigError, TypeError) as exc:
            r.problems.append(f"{_CONFIG_YAML}: reward section invalid ({exc})")
        else:
            try:
                decisions = decisions_of(env)
            except (ConfigError, TypeError, ValueError, ArithmeticError) as exc:
                r.problems.append(f"{_CONFIG_YAML}: episode timing invalid ({exc})")

    curve = r.attempt(folder.eval_table, _eval_table)
    rows, n_dropped = (list(curve.rows()), curve.n_dropped) if curve is not None else ([], 0)
    if n_dropped:
        r.problems.append(
            f"{_EVAL_CSV}: {n_dropped} candidate row(s) without a finite step or mean_return "
            "dropped"
        )
    spcp = r.attempt(folder.spcp_json, read_spcp)
    outcome_record = r.attempt(folder.outcome_json, read_outcome_json)
    # outcome.csv is the exposure mode's input: its absence is a problem only where the
    # run could be scored (a reward and an episode timing).
    table = r.attempt(
        folder.outcome_csv, lambda p: read_table(p, OUTCOME_SCHEMA), needed=decisions is not None
    )
    ayss_bins = r.attempt(folder.ayss_bins, read_ayss_bins, needed=False)  # optional
    ayss = r.attempt(folder.ayss_csv, _ayss_samples, needed=ayss_bins is None)
    versions = r.attempt(folder.versions, _read_versions, needed=False)  # optional
    if curve is not None and len(curve) == 0 and not n_dropped:
        r.problems.append(f"{_EVAL_CSV}: no rows (header only), so no learning curve")
    no_signal = (spcp.criterion, spcp.score) if spcp is not None and spcp.no_signal else None
    returns = curve["mean_return"] if curve is not None else np.array([])
    if (same := all_same(returns, no_signal)) is not None:
        r.problems.append(f"{_EVAL_CSV}: {same}")
    if ayss is not None and len(ayss) == 0:
        r.problems.append(f"{_AYSS_CSV}: no rows (header only), so no AYSS sample")
    labels = [(_AYSS_CSV, ayss.indicator_name if ayss is not None else None)]
    labels.append((folder.ayss_bins.name, ayss_bins.indicator_name if ayss_bins else None))
    for name, label in labels:
        expected_case = case_of_indicator(label) if label else None
        if expected_case is not None and expected_case != case:
            r.problems.append(f"{name}: indicator {label!r} belongs to {expected_case}, not {case}")
    return RunRecord(
        folder=folder,
        case=case,
        vut=vut,
        seed=seed,
        config=config,
        vut_description=description or "",
        reward=reward,
        decisions_per_episode=decisions,
        eval_curve=curve,
        spcp=spcp,
        outcome_record=outcome_record,
        outcome_table=table,
        ayss=ayss,
        ayss_bins=ayss_bins,
        versions=versions or {},
        training=training_of(
            None if config is None else config.experiment.get("train") or {},
            "" if config is None else config_key(config.as_dict()),
            rows,
            spcp.step if spcp is not None else None,
            None if config is None else config.experiment.get("agent"),
        ),
        problems=tuple(r.problems),
    )
