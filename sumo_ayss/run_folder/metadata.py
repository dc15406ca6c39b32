"""The run folder's small files (``config.yaml``, ``command.txt``, ``versions.json``,
``seeds.json``, ``spcp.json``, ``progress.json``, ``evaluate.done.json``): one writer and one
reader each, named in the table of :mod:`sumo_ayss.run_folder`.

The checkpoints' own files (``latest.json``, ``state.json``) are the trainer's
(:mod:`sumo_ayss.training.checkpoint_files`). Readers raise
:class:`~sumo_ayss.util.errors.CheckpointError` naming the file and the field;
callers that tolerate a missing or broken file (the report, the progress display) catch it.
Imports neither SUMO nor torch.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from sumo_ayss.config import (
    EnvConfig,
    ExperimentConfig,
    check_seed,
    experiment_from_dict,
    safe_load_yaml,
    write_yaml,
)
from sumo_ayss.records.jsonio import json_field, read_json
from sumo_ayss.run_folder.layout import RunFolder
from sumo_ayss.util.atomic import atomic_write_json, atomic_write_text
from sumo_ayss.util.errors import CheckpointError, ConfigError

__all__ = [
    "RunConfig",
    "Seeds",
    "SpcpChoice",
    "read_command",
    "read_done_marker",
    "read_progress",
    "read_run_config",
    "read_seeds",
    "read_spcp",
    "read_versions",
    "stored_experiment",
    "write_command",
    "write_done_marker",
    "write_progress",
    "write_provenance",
    "write_run_config",
    "write_seeds",
    "write_spcp",
    "write_versions",
]


# --------------------------------------------------------------------------- config.yaml


@dataclass(frozen=True)
class RunConfig:
    """``config.yaml``: the resolved experiment configuration of a run.

    The file holds ``seed`` and the experiment sections; the VUT is stored once, as
    ``env.vut``. Folders written before that also have a top-level ``vut`` (the same
    value); :func:`read_run_config` still reads them.

    Attributes:
        vut: The run's VUT (the file's ``env.vut``).
        seed: The training seed (top-level ``seed``), in [0, 2**31 - 1].
        experiment: The experiment sections (``env``, ``agent``, ``train``, ...), as
            written by ``ExperimentConfig.to_dict``; rebuild with ``experiment_from_dict``.
            Its ``env.vut`` is :attr:`vut` once written or read.
    """

    vut: str
    seed: int
    experiment: dict[str, Any]

    def as_dict(self) -> dict[str, Any]:
        """The file's contents: ``seed``, then the experiment sections, ``env.vut`` set."""
        experiment = dict(self.experiment)
        env = experiment.get("env") or {}
        if not isinstance(env, Mapping):
            raise ConfigError(f"env must be a mapping, got {type(env).__name__}")
        experiment["env"] = {**env, "vut": self.vut}
        return {"seed": self.seed, **experiment}


def write_run_config(path: Path, config: RunConfig) -> None:
    """Write ``config.yaml`` atomically (keys in :meth:`RunConfig.as_dict` order)."""
    write_yaml(path, config.as_dict())


def read_run_config(path: Path) -> RunConfig:
    """Read ``config.yaml``.

    The VUT is the legacy top-level ``vut`` where a folder has one, else ``env.vut``, else
    the default VUT (a hand-written file that leaves ``env.vut`` to its default).

    Raises:
        CheckpointError: ``<path>: unreadable run configuration (...)`` when the file is
            missing, not YAML, not a mapping, lacks a valid ``seed``, has an ``env`` that
            is not a mapping, or a VUT that is not a non-empty string.
    """
    try:
        data = safe_load_yaml(path.read_text(encoding="utf-8"), str(path))
        if not isinstance(data, Mapping):
            raise ConfigError("top level is not a mapping")
        data = dict(data)
        seed = check_seed(data.pop("seed"), f"{path}: seed")
        env = data.get("env") or {}
        if not isinstance(env, Mapping):
            raise ConfigError(f"env must be a mapping, got {type(env).__name__}")
        legacy = data.pop("vut", None)  # folders written before the VUT was stored once
        vut = legacy if legacy is not None else env.get("vut", EnvConfig.vut)
        if not isinstance(vut, str) or not vut:
            raise ConfigError(f"vut must be a non-empty string, got {vut!r}")
        data["env"] = {**env, "vut": vut}
    except (ConfigError, KeyError, OSError, UnicodeDecodeError, yaml.YAMLError) as e:
        raise CheckpointError(f"{path}: unreadable run configuration ({e})") from e
    return RunConfig(vut, seed, data)


def stored_experiment(
    folder: RunFolder, config: RunConfig | None = None
) -> tuple[ExperimentConfig, int]:
    """The experiment and seed a run folder's ``config.yaml`` records (the one build of an
    experiment from a stored configuration; ``config``: the file as already read).

    Raises:
        CheckpointError: If the file is missing or unreadable (:func:`read_run_config`), or
            not a valid experiment (``<file>: invalid run configuration: ...``).
    """
    stored = config if config is not None else read_run_config(folder.config)
    try:
        return experiment_from_dict(stored.experiment, folder.path), stored.seed
    except ConfigError as e:
        raise CheckpointError(f"{folder.config}: invalid run configuration: {e}") from e


# --------------------------------------------------------------------------- command.txt


def write_command(path: Path, command: str) -> None:
    """Write ``command.txt``: the shell-quoted command line (no trailing newline)."""
    atomic_write_text(path, command)


def read_command(path: Path) -> str:
    """Read ``command.txt``.

    Raises:
        CheckpointError: The file is missing or unreadable.
    """
    try:
        return path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as e:
        raise CheckpointError(f"{path}: unreadable ({e})") from e


# --------------------------------------------------------------------------- versions.json


def write_versions(path: Path, versions: Mapping[str, str]) -> None:
    """Write ``versions.json``: ``{"python": "3.11.2", "torch": "2.4.0", ...}``."""
    atomic_write_json(path, dict(versions))


def read_versions(path: Path) -> dict[str, str]:
    """Read ``versions.json`` (every value as text).

    Raises:
        CheckpointError: The file is missing, unreadable or not a JSON object.
    """
    return {str(k): str(v) for k, v in read_json(path, error=CheckpointError).items()}


# --------------------------------------------------------------------------- seeds.json


@dataclass(frozen=True)
class Seeds:
    """``seeds.json``.

    Attributes:
        train_seed: The training seed (numpy, torch, SB3).
        sumo_seed: SUMO's ``--seed`` (the training seed).
        eval_seed: Seed of the candidate-evaluation scenarios (``train.eval_seed``).
    """

    train_seed: int
    sumo_seed: int
    eval_seed: int


def write_seeds(path: Path, seeds: Seeds) -> None:
    """Write ``seeds.json``."""
    atomic_write_json(path, dataclasses.asdict(seeds))


def read_seeds(path: Path) -> Seeds:
    """Read ``seeds.json``.

    Raises:
        CheckpointError: The file is unreadable or a seed is missing or not an integer.
    """
    data = read_json(path, error=CheckpointError)
    return Seeds(
        **{
            f.name: json_field(data, f.name, int, str(path), error=CheckpointError)
            for f in dataclasses.fields(Seeds)
        }
    )


def write_provenance(
    folder: RunFolder, command: str, versions: Mapping[str, str], seeds: Seeds
) -> None:
    """Write what records how a run was made, beside its ``config.yaml``: ``command.txt``,
    ``versions.json`` and ``seeds.json`` (:func:`write_command`, :func:`write_versions`,
    :func:`write_seeds`)."""
    write_command(folder.command, command)
    write_versions(folder.versions, versions)
    write_seeds(folder.seeds, seeds)


# --------------------------------------------------------------------------- spcp.json


@dataclass(frozen=True)
class SpcpChoice:
    """``spcp.json``: the selected SPCP of a run.

    Attributes:
        step: Training step of the selected candidate.
        score: Its selection score (NaN if not a number).
        criterion: Name of the selection criterion.
        reason: The selection's own sentence.
        checkpoint: The candidate's model, relative to the run folder.
        no_signal: Every one of two or more candidates scored the same on the criterion
            (the selection could not tell them apart; False in files written before).
    """

    step: int
    score: float
    criterion: str
    reason: str
    checkpoint: str = ""
    no_signal: bool = False


def write_spcp(path: Path, selection: Any, checkpoint: str, row: Mapping[str, Any]) -> None:
    """Write ``spcp.json``: the selection's fields, the checkpoint and its ``eval.csv`` row.

    Args:
        path: ``<run>/spcp.json``.
        selection: A :class:`sumo_ayss.training.selection.Selection` (a dataclass).
        checkpoint: The candidate's model, relative to the run folder.
        row: The candidate's ``eval.csv`` row.
    """
    record = {**dataclasses.asdict(selection), "checkpoint": checkpoint, "row": dict(row)}
    atomic_write_json(path, record)


def read_spcp(path: Path) -> SpcpChoice:
    """Read ``spcp.json``.

    Raises:
        CheckpointError: The file is unreadable or ``step`` is missing or not an integer.
    """
    data = read_json(path, error=CheckpointError)
    step = json_field(data, "step", int, str(path), error=CheckpointError)
    score = data.get("score")
    return SpcpChoice(
        step=step,
        score=float(score) if isinstance(score, int | float) else math.nan,
        criterion=str(data.get("criterion", "")),
        reason=str(data.get("reason", "")),
        checkpoint=str(data.get("checkpoint", "")),
        no_signal=data.get("no_signal") is True,
    )


def write_progress(run_dir: Path, stage: str, **fields: Any) -> None:
    """Atomically (re)write ``<run_dir>/progress.json``: ``stage``, ``time`` plus ``fields``.

    Stages: ``train`` (with ``step``, ``total`` in transitions and ``rate_steps_per_s``,
    transitions per second of wall time since this process started training), ``evaluate``,
    ``done``. Only watchers (the pipeline's progress display) read it; nothing depends on it.
    """
    atomic_write_json(RunFolder(run_dir).progress, {"stage": stage, "time": time.time(), **fields})


def read_progress(run_dir: Path) -> dict[str, Any] | None:
    """``<run_dir>/progress.json``, or None when it is missing or unreadable."""
    try:
        return read_json(RunFolder(run_dir).progress, error=CheckpointError)
    except CheckpointError:
        return None


def write_done_marker(path: Path, key: str) -> None:
    """Write a stand-alone done marker (``evaluate.done.json``): ``{"inputs": key}``."""
    atomic_write_json(path, {"inputs": key})


def read_done_marker(path: Path) -> str | None:
    """The fingerprint a stand-alone done marker records; None when the file is missing.

    Raises:
        CheckpointError: The file exists but is unreadable or not a JSON object.
    """
    if not path.is_file():
        return None
    inputs = read_json(path, error=CheckpointError).get("inputs")
    return inputs if isinstance(inputs, str) else None
