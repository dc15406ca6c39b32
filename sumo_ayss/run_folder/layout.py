"""Where each file of a run folder lives: the names, once, and the folder's paths.

A run folder is ``<out>/<case>/<vut>/seed_<k>/`` (:meth:`~.study.StudyFolder.run`).
:class:`RunFolder` gives the path of every file in it, each file named once, as the folder's
attribute (``RunFolder.config.name`` is ``"config.yaml"``); no other module spells a file
name of a run folder.
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
    "MODEL_ZIP",
    "CaseFolder",
    "FolderFile",
    "RunFolder",
    "find_run_dirs",
    "is_run_dir",
    "seed_of_dir",
]

MODEL_ZIP = "model.zip"
"""In a checkpoint: the candidate's model."""

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

    # -- written by train
    #: The resolved experiment configuration (VUT: ``env.vut``) and the run's ``seed``.
    config = FolderFile("config.yaml")
    #: The command line that started the run.
    command = FolderFile("command.txt")
    #: Python, platform and package versions.
    versions = FolderFile("versions.json")
    #: Training seed, SUMO seed and evaluation-scenario seed.
    seeds = FolderFile("seeds.json")
    #: One row per SPCP candidate (:mod:`sumo_ayss.run_folder.eval_table`).
    eval_table = FolderFile("eval.csv")
    #: The selected candidate and why.
    spcp_json = FolderFile("spcp.json")
    #: The selected candidate's model (a copy of its ``model.zip``).
    spcp_zip = FolderFile("spcp.zip")
    #: Progress for watchers: stage, step, total, rate; rewritten every few seconds.
    progress = FolderFile("progress.json")
    #: TensorBoard logs.
    tb = FolderFile("tb")
    #: ``step_XXXXXXXXX/`` per candidate and ``latest.json`` (the checkpoints' own files are
    #: the trainer's: :mod:`sumo_ayss.training.checkpoint_files`).
    checkpoints = FolderFile("checkpoints")
    # -- written by evaluate and the pipeline
    #: One row per outcome episode (:data:`~sumo_ayss.run_folder.schemas.OUTCOME_SCHEMA`).
    outcome_csv = FolderFile("outcome.csv")
    #: Outcome summary: rates and means with 95 % intervals (:mod:`.summaries`).
    outcome_json = FolderFile("outcome.json")
    #: One row per kept AYSS sample (:data:`~sumo_ayss.run_folder.schemas.AYSS_SCHEMA`).
    ayss_csv = FolderFile("ayss.csv")
    #: The AYSS samples as moments per headway cell, committed where ``ayss.csv`` is not
    #: (:mod:`~sumo_ayss.run_folder.ayss_bins`).
    ayss_bins = FolderFile("ayss_bins.csv")
    #: AYSS summary: filter counts, throughput, Monte Carlo settings, mean indicator.
    ayss_json = FolderFile("ayss.json")
    #: The pipeline's marker: the inputs the evaluation was done for.
    evaluate_done = FolderFile("evaluate.done.json")
    #: The pipeline job's log.
    job_log = FolderFile("job.log")

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

    # -- written by cross-play
    #: One row per (VUT, opponent SPCP, scenario) (:data:`~.schemas.CROSSPLAY_SCHEMA`).
    crossplay_csv = FolderFile("crossplay.csv")
    #: Cross-play record: settings, opponents with their SPCP's SHA-256, wall time.
    crossplay_json = FolderFile("crossplay.json")
    #: The scenarios no braking survives, inevitable-collision states (:func:`read_inevitable`).
    inevitable_json = FolderFile("inevitable.json")
    #: The finished cells of a cross-play table not yet written whole, one file each
    #: (:class:`~.crossplay_partial.CellStore`).
    crossplay_partial = FolderFile("crossplay.partial")
    #: The same for ``crossplay_reference.csv``.
    crossplay_reference_partial = FolderFile("crossplay_reference.partial")
    #: The reference drivers against the same opponents and scenarios
    #: (:data:`~.schemas.CROSSPLAY_SCHEMA`; they have no SPCPs of their own).
    crossplay_reference_csv = FolderFile("crossplay_reference.csv")
    #: Adaptive seeding's looks (:mod:`.adaptive`).
    adaptive_json = FolderFile("adaptive.json")
    # -- written by the discriminability stage
    #: Where the VUTs' one-step responses differ over the AYSS box, with the fingerprint of
    #: the inputs (:mod:`.discriminability`).
    discriminability_json = FolderFile("discriminability.json")
    #: The same shares as a long table: one row per (VUT pair, dimension, bin).
    discriminability_csv = FolderFile("discriminability.csv")
    #: Its figure (drawn by the report's discriminability section).
    discriminability_png = FolderFile("discriminability.png")


def is_run_dir(path: Path) -> bool:
    """A folder holding a run's config or evaluation table, or named ``seed_<k>``."""
    folder = RunFolder(path)
    return folder.config.is_file() or folder.eval_table.is_file() or seed_of_dir(path) is not None


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
