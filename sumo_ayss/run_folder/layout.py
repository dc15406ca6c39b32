"""Where each file of a run folder lives: the names, once, and the folder's paths.

A run folder is ``<out>/<case>/<vut>/seed_<k>/`` (:func:`run_dir_for`). :class:`RunFolder`
gives the path of every file in it; no other module spells a file name of a run folder.
The case folder ``<out>/<case>/`` above a case's runs holds the cross-play and
discriminability files (:class:`CaseFolder`).
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from sumo_ayss.util.errors import ConfigError

__all__ = [
    "ADAPTIVE_JSON",
    "AYSS_CSV",
    "AYSS_JSON",
    "CHECKPOINTS_DIR",
    "COMMAND_TXT",
    "CONFIG_YAML",
    "CROSSPLAY_CSV",
    "CROSSPLAY_JSON",
    "DISCRIMINABILITY_CSV",
    "DISCRIMINABILITY_JSON",
    "DISCRIMINABILITY_PNG",
    "EVALUATE_DONE_JSON",
    "EVAL_CSV",
    "JOB_LOG",
    "MODEL_ZIP",
    "OUTCOME_CSV",
    "OUTCOME_JSON",
    "PROGRESS_JSON",
    "SEEDS_JSON",
    "SPCP_JSON",
    "SPCP_ZIP",
    "TB_DIR",
    "VERSIONS_JSON",
    "CaseFolder",
    "RunFolder",
    "case_dir_for",
    "find_run_dirs",
    "is_run_dir",
    "run_dir_for",
    "seed_of_dir",
]

# -- written by train ----------------------------------------------------------------------
CONFIG_YAML = "config.yaml"
"""The resolved experiment configuration (VUT: ``env.vut``) and the run's ``seed``."""
COMMAND_TXT = "command.txt"
"""The command line that started the run."""
VERSIONS_JSON = "versions.json"
"""Python, platform and package versions."""
SEEDS_JSON = "seeds.json"
"""Training seed, SUMO seed and evaluation-scenario seed."""
EVAL_CSV = "eval.csv"
"""One row per SPCP candidate (:mod:`sumo_ayss.run_folder.eval_table`)."""
SPCP_JSON = "spcp.json"
"""The selected candidate and why."""
SPCP_ZIP = "spcp.zip"
"""The selected candidate's model (a copy of its ``model.zip``)."""
PROGRESS_JSON = "progress.json"
"""Progress for watchers: stage, step, total, rate; rewritten every few seconds."""
TB_DIR = "tb"
"""TensorBoard logs."""
CHECKPOINTS_DIR = "checkpoints"
"""``step_XXXXXXXXX/`` per candidate and ``latest.json`` (the checkpoints' own files are
the trainer's: :mod:`sumo_ayss.training.checkpoint_files`)."""
MODEL_ZIP = "model.zip"
"""In a checkpoint: the candidate's model."""

# -- written by evaluate and the pipeline ------------------------------------------------------
OUTCOME_CSV = "outcome.csv"
"""One row per outcome episode (:data:`~sumo_ayss.run_folder.schemas.OUTCOME_SCHEMA`)."""
OUTCOME_JSON = "outcome.json"
"""Outcome summary: rates and means with 95 % intervals (:mod:`.summaries`)."""
AYSS_CSV = "ayss.csv"
"""One row per kept AYSS sample (:data:`~sumo_ayss.run_folder.schemas.AYSS_SCHEMA`)."""
AYSS_JSON = "ayss.json"
"""AYSS summary: filter counts, throughput, Monte Carlo settings, mean indicator."""
EVALUATE_DONE_JSON = "evaluate.done.json"
"""The pipeline's marker: the inputs the evaluation was done for."""
JOB_LOG = "job.log"
"""The pipeline job's log."""

# -- written by cross-play, in the case folder <out>/<case>/ above the run folders ----------
CROSSPLAY_CSV = "crossplay.csv"
"""One row per (VUT, opponent SPCP, scenario) (:data:`~.schemas.CROSSPLAY_SCHEMA`)."""
CROSSPLAY_REFERENCE_CSV = "crossplay_reference.csv"
"""The reference drivers against the same opponents and scenarios (same schema)."""
INEVITABLE_JSON = "inevitable.json"
"""Which of the case's scenarios are inevitable-collision states (written by cross-play)."""
CROSSPLAY_JSON = "crossplay.json"
"""Cross-play record: settings, opponents with their SPCP's SHA-256, wall time."""
CROSSPLAY_PARTIAL = "crossplay.partial"
"""The finished cells of a cross-play table not yet written whole (one file each)."""
CROSSPLAY_REFERENCE_PARTIAL = "crossplay_reference.partial"
"""The same for the reference drivers' table."""
ADAPTIVE_JSON = "adaptive.json"

# -- written by the discriminability stage, in the case folder too ------------------------
DISCRIMINABILITY_JSON = "discriminability.json"
"""Where the VUTs' one-step responses differ over the AYSS box, with the fingerprint of the
inputs (:mod:`.discriminability`)."""
DISCRIMINABILITY_CSV = "discriminability.csv"
"""The same shares as a long table: one row per (VUT pair, dimension, bin)."""
DISCRIMINABILITY_PNG = "discriminability.png"
"""Its figure (drawn by the report's discriminability section)."""

_SEED_DIR = re.compile(r"^seed_(-?\d+)$")


def run_dir_for(out: str | Path, case: str, vut: str, seed: int) -> Path:
    """The run folder ``<out>/<case>/<vut>/seed_<seed>``."""
    return Path(out) / case / vut / f"seed_{seed}"


def case_dir_for(out: str | Path, case: str) -> Path:
    """The case folder ``<out>/<case>``: the parent of the case's ``<vut>/seed_<k>`` runs."""
    return Path(out) / case


def seed_of_dir(path: Path) -> int | None:
    """The seed of a folder named ``seed_<k>``, else None."""
    match = _SEED_DIR.match(path.name)
    return int(match.group(1)) if match else None


@dataclass(frozen=True)
class RunFolder:
    """The paths of one run folder's files.

    Attributes:
        path: The run folder ``<out>/<case>/<vut>/seed_<k>/``.
    """

    path: Path

    def __post_init__(self) -> None:
        object.__setattr__(self, "path", Path(self.path))

    @property
    def config(self) -> Path:
        """``config.yaml``."""
        return self.path / CONFIG_YAML

    @property
    def command(self) -> Path:
        """``command.txt``."""
        return self.path / COMMAND_TXT

    @property
    def versions(self) -> Path:
        """``versions.json``."""
        return self.path / VERSIONS_JSON

    @property
    def seeds(self) -> Path:
        """``seeds.json``."""
        return self.path / SEEDS_JSON

    @property
    def eval_table(self) -> Path:
        """``eval.csv``."""
        return self.path / EVAL_CSV

    @property
    def spcp_json(self) -> Path:
        """``spcp.json``."""
        return self.path / SPCP_JSON

    @property
    def spcp_zip(self) -> Path:
        """``spcp.zip``."""
        return self.path / SPCP_ZIP

    @property
    def progress(self) -> Path:
        """``progress.json``."""
        return self.path / PROGRESS_JSON

    @property
    def tb(self) -> Path:
        """``tb/``."""
        return self.path / TB_DIR

    @property
    def checkpoints(self) -> Path:
        """``checkpoints/``."""
        return self.path / CHECKPOINTS_DIR

    @property
    def outcome_csv(self) -> Path:
        """``outcome.csv``."""
        return self.path / OUTCOME_CSV

    @property
    def outcome_json(self) -> Path:
        """``outcome.json``."""
        return self.path / OUTCOME_JSON

    @property
    def ayss_csv(self) -> Path:
        """``ayss.csv``."""
        return self.path / AYSS_CSV

    @property
    def ayss_json(self) -> Path:
        """``ayss.json``."""
        return self.path / AYSS_JSON

    @property
    def evaluate_done(self) -> Path:
        """``evaluate.done.json``."""
        return self.path / EVALUATE_DONE_JSON

    @property
    def job_log(self) -> Path:
        """``job.log``."""
        return self.path / JOB_LOG

    def step_dir(self, step: int) -> Path:
        """The checkpoint folder of the candidate at training step ``step``."""
        return self.checkpoints / f"step_{step:09d}"

    def candidate_model(self, step: int) -> Path:
        """The model of the candidate at training step ``step``."""
        return self.step_dir(step) / MODEL_ZIP

    def checkpoint_model(self, step_dir: Path) -> str:
        """``checkpoints/step_XXXXXXXXX/model.zip`` relative to the run folder, as written
        into ``eval.csv``'s ``checkpoint`` column."""
        return str(step_dir.relative_to(self.path) / MODEL_ZIP)


@dataclass(frozen=True)
class CaseFolder:
    """The paths of a case folder's own files (cross-play, discriminability), one level
    above its runs.

    Attributes:
        path: The case folder ``<out>/<case>/`` (:func:`case_dir_for`).
    """

    path: Path

    def __post_init__(self) -> None:
        object.__setattr__(self, "path", Path(self.path))

    @property
    def crossplay_csv(self) -> Path:
        """``crossplay.csv``."""
        return self.path / CROSSPLAY_CSV

    @property
    def crossplay_json(self) -> Path:
        """``crossplay.json``."""
        return self.path / CROSSPLAY_JSON

    @property
    def inevitable_json(self) -> Path:
        """``inevitable.json``: the scenarios no braking survives (:func:`read_inevitable`)."""
        return self.path / INEVITABLE_JSON

    @property
    def crossplay_partial(self) -> Path:
        """``crossplay.partial/``: the finished cells of a cross-play table not yet written
        whole (:class:`~.crossplay_partial.CellStore`)."""
        return self.path / CROSSPLAY_PARTIAL

    @property
    def crossplay_reference_partial(self) -> Path:
        """``crossplay_reference.partial/``: the same for ``crossplay_reference.csv``."""
        return self.path / CROSSPLAY_REFERENCE_PARTIAL

    @property
    def crossplay_reference_csv(self) -> Path:
        """``crossplay_reference.csv``: the reference drivers against the same opponents
        and scenarios (:data:`~.schemas.CROSSPLAY_SCHEMA`; they have no SPCPs of their own)."""
        return self.path / CROSSPLAY_REFERENCE_CSV

    @property
    def adaptive_json(self) -> Path:
        """``adaptive.json`` (adaptive seeding's looks, :mod:`.adaptive`)."""
        return self.path / ADAPTIVE_JSON

    @property
    def discriminability_json(self) -> Path:
        """``discriminability.json``."""
        return self.path / DISCRIMINABILITY_JSON

    @property
    def discriminability_csv(self) -> Path:
        """``discriminability.csv``."""
        return self.path / DISCRIMINABILITY_CSV

    @property
    def discriminability_png(self) -> Path:
        """``discriminability.png``."""
        return self.path / DISCRIMINABILITY_PNG


def is_run_dir(path: Path) -> bool:
    """A folder holding a run's config or evaluation table, or named ``seed_<k>``."""
    return (
        (path / CONFIG_YAML).is_file()
        or (path / EVAL_CSV).is_file()
        or seed_of_dir(path) is not None
    )


def find_run_dirs(paths: Iterable[str | Path]) -> list[Path]:
    """Run folders among ``paths`` and below them, each once, in a stable order.

    A path that is itself a run folder is taken as is; any other folder is searched
    recursively for run folders (a run folder is not searched further; hidden folders are
    skipped).

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
    if is_run_dir(root):
        return [root]
    out: list[Path] = []
    for child in sorted(p for p in root.iterdir() if p.is_dir() and not p.name.startswith(".")):
        out.extend(_walk_runs(child))
    return out
