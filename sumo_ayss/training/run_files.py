"""Run-folder files written and read by training: metadata, ``eval.csv``, ``progress.json``.

A run folder ``<out>/<case>/<vut>/seed_<k>/`` (see :mod:`sumo_ayss.train`) holds
``config.yaml``, ``command.txt``, ``versions.json`` and ``seeds.json`` (written once, by
:func:`write_metadata`), ``eval.csv`` (one row per SPCP candidate, rewritten after each) and
``progress.json`` (for watchers). Every file is written atomically.
"""

from __future__ import annotations

import csv
import io
import json
import math
import platform
import shlex
import time
from collections.abc import Sequence
from importlib import metadata
from pathlib import Path
from typing import Any

from sumo_ayss.atomic import atomic_write_json, atomic_write_text
from sumo_ayss.config import write_yaml
from sumo_ayss.errors import CheckpointError
from sumo_ayss.experiment import ExperimentConfig
from sumo_ayss.paths import portable_python

#: The training entry point, as ``command.txt`` names it (``python -m <this>``).
ENTRY_MODULE = "sumo_ayss.train"

EVAL_COLUMNS = [
    "step",
    "mean_return",
    "std_return",
    "crash_rate",
    "lane_change_rate",
    "mean_final_headway_m",
    "n_episodes",
    "wall_s",
    "checkpoint",
]


def write_eval_table(path: Path, rows: Sequence[dict[str, Any]]) -> None:
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=EVAL_COLUMNS, lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    atomic_write_text(path, buf.getvalue())


def read_eval_table(path: Path) -> list[dict[str, Any]]:
    """The rows of ``eval.csv`` (none if it does not exist).

    Raises:
        CheckpointError: The file is unreadable, lacks a column, or has a bad cell; the
            message names the file, the line and the column.
    """
    if not path.is_file():
        return []
    try:
        with path.open(encoding="utf-8", newline="") as f:
            reader = csv.DictReader(f)
            missing = [c for c in EVAL_COLUMNS if c not in (reader.fieldnames or [])]
            if missing:
                raise CheckpointError(f"{path}: not an eval table (missing columns {missing})")
            rows = list(reader)
    except (OSError, UnicodeDecodeError, csv.Error) as e:
        raise CheckpointError(f"{path}: unreadable ({e})") from e
    for line, row in enumerate(rows, start=2):
        for key in EVAL_COLUMNS:
            if key == "checkpoint":
                continue
            cell = row[key]
            try:
                value = int(cell) if key in ("step", "n_episodes") else float(cell)
            except (TypeError, ValueError):
                raise CheckpointError(
                    f"{path}, line {line}: column {key!r} must be a number, got {cell!r}"
                ) from None
            if key not in ("std_return",) and not math.isfinite(value):
                raise CheckpointError(
                    f"{path}, line {line}: column {key!r} must be finite, got {cell!r}"
                )
            row[key] = value
    return rows


def versions() -> dict[str, str]:
    out = {"python": platform.python_version(), "platform": platform.platform()}
    for dist in (
        "sumo_ayss",
        "eclipse-sumo",
        "libsumo",
        "sumolib",
        "stable-baselines3",
        "torch",
        "gymnasium",
        "numpy",
    ):
        try:
            out[dist] = metadata.version(dist)
        except metadata.PackageNotFoundError:
            out[dist] = "not installed"
    return out


def run_dir_for(out: Path, cfg: ExperimentConfig, seed: int) -> Path:
    return out / cfg.env.case / cfg.env.vut / f"seed_{seed}"


def write_metadata(run_dir: Path, cfg: ExperimentConfig, seed: int, argv: Sequence[str]) -> None:
    """Create ``run_dir`` and write its metadata files (before any checkpoint).

    Args:
        run_dir: The run folder.
        cfg: The resolved experiment configuration.
        seed: The training seed (also SUMO's).
        argv: The command line's arguments (after ``python -m sumo_ayss.train``).
    """
    run_dir.mkdir(parents=True, exist_ok=True)
    resolved = {"vut": cfg.env.vut, "seed": seed, **cfg.to_dict()}
    # config.yaml before checkpoints/: a run killed in between must look resumable
    # (the pipeline resumes a folder with config.yaml; checkpoints/ alone is refused).
    write_yaml(run_dir / "config.yaml", resolved)
    (run_dir / "checkpoints").mkdir(exist_ok=True)
    atomic_write_text(
        run_dir / "command.txt",
        shlex.join([portable_python(), "-m", ENTRY_MODULE, *argv]),
    )
    atomic_write_json(run_dir / "versions.json", versions())
    atomic_write_json(
        run_dir / "seeds.json",
        {
            "train_seed": seed,
            "sumo_seed": seed,
            "eval_seed": cfg.train.eval_seed,
        },
    )


PROGRESS_FILE = "progress.json"
PROGRESS_EVERY_S = 2.0
"""Seconds between two rewrites of a run's ``progress.json`` during training."""


def write_progress(run_dir: Path, stage: str, **fields: Any) -> None:
    """Atomically (re)write ``run_dir/progress.json``: ``stage`` plus ``fields``.

    Stages: ``train`` (with ``step``, ``total`` in transitions and ``rate_steps_per_s``,
    transitions per second of wall time since this process started training), ``evaluate``,
    ``done``. Only watchers (the pipeline's progress display) read it; nothing depends on it.
    """
    atomic_write_json(run_dir / PROGRESS_FILE, {"stage": stage, "time": time.time(), **fields})


def read_json(path: Path) -> Any:
    """JSON from a run-folder file; a missing, unreadable or malformed file -> CheckpointError."""
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as e:
        raise CheckpointError(f"{path}: unreadable JSON ({e})") from e
