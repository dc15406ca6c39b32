"""Whether a run folder may be resumed with a requested configuration.

A resume must compute what the run started to compute: every field of the experiment and
the seed must match, except display options (:data:`DISPLAY_FIELDS`, e.g. the progress
bar). A refusal names each differing field with its stored and requested value.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from sumo_ayss.config import ExperimentConfig, experiment_from_dict, to_dict
from sumo_ayss.errors import CheckpointError, ConfigError
from sumo_ayss.run_folder import RunFolder, read_run_config

__all__ = ["DISPLAY_FIELDS", "check_same_config", "config_differences"]


#: Fields that change what a run shows, never what it computes: a resume may differ in them.
DISPLAY_FIELDS = ("train.progress_bar",)


def _flat(data: Any, prefix: str = "") -> dict[str, Any]:
    """``{"train.total_timesteps": 100000, ...}``: nested mappings as dotted keys."""
    if isinstance(data, dict):
        out: dict[str, Any] = {}
        for key, value in data.items():
            out.update(_flat(value, f"{prefix}{key}."))
        return out
    return {prefix[:-1]: data}


def config_differences(stored: ExperimentConfig, requested: ExperimentConfig) -> list[str]:
    """The dotted fields in which two experiments differ, display options left out
    (:data:`DISPLAY_FIELDS`), each as ``"field: stored -> requested"``."""
    a, b = _flat(to_dict(stored)), _flat(to_dict(requested))
    return [
        f"{key}: {a.get(key, '(absent)')!r} -> {b.get(key, '(absent)')!r}"
        for key in sorted(set(a) | set(b))
        if key not in DISPLAY_FIELDS and a.get(key) != b.get(key)
    ]


def check_same_config(run_dir: Path, cfg: ExperimentConfig, seed: int) -> None:
    """Raises :class:`CheckpointError` naming every field in which the run folder's stored
    configuration (and seed) differs from the requested one, display options aside."""
    path = RunFolder(run_dir).config
    stored = read_run_config(path)
    try:
        stored_cfg = experiment_from_dict(stored.experiment, run_dir)
    except ConfigError as e:
        raise CheckpointError(f"{path}: unreadable run configuration ({e})") from e
    diffs = config_differences(stored_cfg, cfg)
    if stored.seed != seed:
        diffs.insert(0, f"seed: {stored.seed!r} -> {seed!r}")
    if diffs:
        shown = "; ".join(diffs[:5]) + (f"; and {len(diffs) - 5} more" if len(diffs) > 5 else "")
        raise CheckpointError(
            f"--resume: {run_dir}/config.yaml differs from the requested configuration in "
            f"{shown} (stored -> requested); resume with the same config file, --vut, --seed "
            "and overrides"
        )
