"""Where each file of a run folder lives: the names, once, and the folder's paths.

A run folder is ``<out>/<case>/<vut>/seed_<k>/`` (:meth:`~.study.StudyFolder.run`).
:class:`RunFolder` gives the path of every file in it; no other module spells a file name of
a run folder.
The case folder ``<out>/<case>/`` above a case's runs holds the cross-play and
discriminability files (:class:`CaseFolder`).
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, overload

from sumo_ayss.util.errors import ConfigError

__all__ = [
    "ADAPTIVE_JSON",
    "AYSS_BINS_CSV",
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
    "FolderFile",
    "RunFolder",
    "find_run_dirs",
    "is_run_dir",
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
AYSS_BINS_CSV = "ayss_bins.csv"
"""The AYSS samples as moments per headway cell, committed where ``ayss.csv`` is not
(:mod:`~sumo_ayss.run_folder.ayss_bins`)."""
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


def seed_of_dir(path: Path) -> int | None:
    """The seed of a folder named ``seed_<k>``, else None."""
    match = _SEED_DIR.match(path.name)
    return int(match.group(1)) if match else None


class FolderFile:
    """A file of a folder record (:class:`RunFolder`, :class:`CaseFolder`, a study's), named
    once: on a folder the attribute is the file's path, ``folder.path / name``; on the class
    it is this descriptor, whose :attr:`name` is the file's name (``RunFolder.outcome_json.name``
    is ``"outcome.json"``)."""

    def __init__(self, name: str) -> None:
        self.name = name

    @overload
    def __get__(self, folder: None, owner: type | None = None) -> FolderFile: ...

    @overload
    def __get__(self, folder: object, owner: type | None = None) -> Path: ...

    def __get__(self, folder: Any, owner: type | None = None) -> Path | FolderFile:
        if folder is None:
            return self
        path: Path = folder.path / self.name
        return path


@dataclass(frozen=True)
class RunFolder:
    """The paths of one run folder's files.

    Attributes:
        path: The run folder ``<out>/<case>/<vut>/seed_<k>/``.
    """

    path: Path

    def __post_init__(self) -> None:
        object.__setattr__(self, "path", Path(self.path))

    config = FolderFile(CONFIG_YAML)
    command = FolderFile(COMMAND_TXT)
    versions = FolderFile(VERSIONS_JSON)
    seeds = FolderFile(SEEDS_JSON)
    eval_table = FolderFile(EVAL_CSV)
    spcp_json = FolderFile(SPCP_JSON)
    spcp_zip = FolderFile(SPCP_ZIP)
    progress = FolderFile(PROGRESS_JSON)
    tb = FolderFile(TB_DIR)
    checkpoints = FolderFile(CHECKPOINTS_DIR)
    outcome_csv = FolderFile(OUTCOME_CSV)
    outcome_json = FolderFile(OUTCOME_JSON)
    ayss_csv = FolderFile(AYSS_CSV)
    ayss_bins = FolderFile(AYSS_BINS_CSV)
    ayss_json = FolderFile(AYSS_JSON)
    evaluate_done = FolderFile(EVALUATE_DONE_JSON)
    job_log = FolderFile(JOB_LOG)

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
        path: The case folder ``<out>/<case>/`` (:meth:`~.study.StudyFolder.case`).
    """

    path: Path

    def __post_init__(self) -> None:
        object.__setattr__(self, "path", Path(self.path))

    crossplay_csv = FolderFile(CROSSPLAY_CSV)
    crossplay_json = FolderFile(CROSSPLAY_JSON)
    #: ``inevitable.json``: the scenarios no braking survives (:func:`read_inevitable`).
    inevitable_json = FolderFile(INEVITABLE_JSON)
    #: ``crossplay.partial/``: the finished cells of a cross-play table not yet written whole
    #: (:class:`~.crossplay_partial.CellStore`).
    crossplay_partial = FolderFile(CROSSPLAY_PARTIAL)
    #: ``crossplay_reference.partial/``: the same for ``crossplay_reference.csv``.
    crossplay_reference_partial = FolderFile(CROSSPLAY_REFERENCE_PARTIAL)
    #: ``crossplay_reference.csv``: the reference drivers against the same opponents and scenarios
    #: (:data:`~.schemas.CROSSPLAY_SCHEMA`; they have no SPCPs of their own).
    crossplay_reference_csv = FolderFile(CROSSPLAY_REFERENCE_CSV)
    #: ``adaptive.json`` (adaptive seeding's looks, :mod:`.adaptive`).
    adaptive_json = FolderFile(ADAPTIVE_JSON)
    discriminability_json = FolderFile(DISCRIMINABILITY_JSON)
    discriminability_csv = FolderFile(DISCRIMINABILITY_CSV)
    discriminability_png = FolderFile(DISCRIMINABILITY_PNG)


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
