"""The files of a checkpoint folder that only training writes and reads back to resume.

``checkpoints/step_XXXXXXXXX/`` holds the candidate's ``model.zip`` (the run folder's:
:meth:`~sumo_ayss.run_folder.RunFolder.candidate_model`, named in ``eval.csv``). The latest
checkpoint also holds the resume state (:data:`RESUME_FILES`, :data:`STATE_JSON`,
:data:`TORCH_RNG_PT`), and ``checkpoints/latest.json`` (:data:`LATEST_JSON`, written last)
names it. This module holds those names and the one writer and reader of the two JSON files
(through :func:`sumo_ayss.records.jsonio.read_json`, raising
:class:`~sumo_ayss.util.errors.CheckpointError` naming the file and the field); the SB3/torch
serialisation is :mod:`sumo_ayss.training.checkpoint`. Imports neither SUMO nor torch.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from sumo_ayss.records.jsonio import json_field, read_json
from sumo_ayss.util.atomic import atomic_write_json
from sumo_ayss.util.errors import CheckpointError

__all__ = [
    "LATEST_JSON",
    "REPLAY_PKL",
    "RESUME_FILES",
    "RESUME_MODEL_ZIP",
    "STATE_JSON",
    "TORCH_RNG_PT",
    "read_checkpoint_state",
    "read_latest",
    "write_checkpoint_state",
    "write_latest",
]

LATEST_JSON = "latest.json"
"""In ``checkpoints/``: names the latest complete checkpoint (written last)."""
RESUME_MODEL_ZIP = "resume_model.zip"
"""In the latest checkpoint: the full model for a resume."""
REPLAY_PKL = "replay.pkl"
"""In the latest checkpoint: the replay buffer."""
STATE_JSON = "state.json"
"""In the latest checkpoint: counters, env state and RNG states."""
TORCH_RNG_PT = "torch_rng.pt"
"""In the latest checkpoint: torch's RNG state."""
RESUME_FILES = (REPLAY_PKL, RESUME_MODEL_ZIP)
"""Files of a checkpoint that only the latest keeps (what a resume needs beyond model.zip)."""


def write_latest(path: Path, step_dir: Path) -> None:
    """Write ``checkpoints/latest.json``: ``{"step": 80016, "dir": "step_000080016"}``."""
    atomic_write_json(path, {"step": int(step_dir.name.split("_")[1]), "dir": step_dir.name})


def read_latest(path: Path) -> tuple[int, str]:
    """Read ``checkpoints/latest.json``: ``(step, folder name)``.

    Raises:
        CheckpointError: The file is unreadable, ``dir`` does not name a ``step_*`` folder
            (no path), or ``step`` is not an integer.
    """
    data = read_json(path, error=CheckpointError)
    name = data.get("dir")
    if not isinstance(name, str) or Path(name).name != name or not name.startswith("step_"):
        raise CheckpointError(f"{path}: 'dir' must name a step_* folder, got {name!r}")
    step = json_field(data, "step", int, str(path), error=CheckpointError)
    return step, name


def write_checkpoint_state(path: Path, state: Mapping[str, Any]) -> None:
    """Write a checkpoint's ``state.json`` (counters, env state, RNG states)."""
    atomic_write_json(path, dict(state))


def read_checkpoint_state(path: Path) -> dict[str, Any]:
    """Read a checkpoint's ``state.json``; it must hold ``num_timesteps`` and ``next_eval``.

    Raises:
        CheckpointError: The file is unreadable or not a checkpoint state.
    """
    data = read_json(path, error=CheckpointError)
    for key in ("num_timesteps", "next_eval"):
        json_field(data, key, object, f"{path}: not a checkpoint state", error=CheckpointError)
    return data
