"""Whether a run folder may be resumed with a requested configuration.

A resume must compute what the run started to compute: every field of the experiment and
the seed must match, except display options (:data:`~sumo_ayss.run_folder.stage.
DISPLAY_FIELDS`, e.g. the progress bar): the training stage's inputs
(:class:`~sumo_ayss.run_folder.TrainStage`). A refusal names each differing field with its
stored and requested value.
"""

from __future__ import annotations

from sumo_ayss.config import ExperimentConfig, to_dict
from sumo_ayss.run_folder import RunFolder, stored_experiment
from sumo_ayss.run_folder.stage import DISPLAY_FIELDS, flat_config
from sumo_ayss.util.errors import CheckpointError

__all__ = ["check_same_config", "config_differences"]


def config_differences(stored: ExperimentConfig, requested: ExperimentConfig) -> list[str]:
    """The dotted fields in which two experiments differ, display options left out
    (:data:`~sumo_ayss.run_folder.stage.DISPLAY_FIELDS`), each as
    ``"field: stored -> requested"``."""
    a, b = flat_config(to_dict(stored)), flat_config(to_dict(requested))
    return [
        f"{key}: {a.get(key, '(absent)')!r} -> {b.get(key, '(absent)')!r}"
        for key in sorted(set(a) | set(b))
        if key not in DISPLAY_FIELDS and a.get(key) != b.get(key)
    ]


def check_same_config(folder: RunFolder, cfg: ExperimentConfig, seed: int) -> None:
    """Raises :class:`CheckpointError` naming every field in which the run folder's stored
    configuration (and seed) differs from the requested one, display options aside, or
    when ``config.yaml`` is unreadable."""
    stored_cfg, stored_seed = stored_experiment(folder)
    diffs = config_differences(stored_cfg, cfg)
    if stored_seed != seed:
        diffs.insert(0, f"seed: {stored_seed!r} -> {seed!r}")
    if diffs:
        shown = "; ".join(diffs[:5]) + (f"; and {len(diffs) - 5} more" if len(diffs) > 5 else "")
        raise CheckpointError(
            f"--resume: {folder.path}/config.yaml differs from the requested configuration in "
            f"{shown} (stored -> requested); resume with the same config file, --vut, --seed "
            "and overrides"
        )
