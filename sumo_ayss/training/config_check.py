"""Whether a run folder may be resumed with a requested configuration.

A resume must compute what the run started to compute: the run's identity
(:func:`~sumo_ayss.config.identity.run_identity`: every field of the experiment, the
seed and the run's own VUT's definition; not the other VUTs of the study's catalog, not the
VUT's name, not display options such as the progress bar) must match: the training stage's
inputs (:class:`~sumo_ayss.run_folder.TrainStage`). A refusal names each differing field
with its stored and requested value.
"""

from __future__ import annotations

from sumo_ayss.config import ExperimentConfig
from sumo_ayss.config.identity import identity_differences
from sumo_ayss.run_folder import RunFolder, stored_experiment
from sumo_ayss.util.errors import CheckpointError

__all__ = ["check_same_config", "config_differences", "stored_differences"]


def config_differences(stored: ExperimentConfig, requested: ExperimentConfig) -> list[str]:
    """The dotted fields in which two experiments' run identities differ (seed aside), each
    as ``"field: stored -> requested"``; the run's own VUT's definition is named
    ``env.vuts[env.vut]``."""
    return identity_differences(stored, 0, requested, 0)


def stored_differences(folder: RunFolder, cfg: ExperimentConfig, seed: int) -> list[str]:
    """The fields in which the run folder's stored identity (``config.yaml``) differs from
    the requested one, the seed first.

    Raises:
        CheckpointError: ``config.yaml`` is missing or unreadable.
    """
    stored_cfg, stored_seed = stored_experiment(folder)
    return identity_differences(stored_cfg, stored_seed, cfg, seed)


def check_same_config(folder: RunFolder, cfg: ExperimentConfig, seed: int) -> None:
    """Raises :class:`CheckpointError` naming every field in which the run folder's stored
    identity differs from the requested one (:func:`stored_differences`), or when
    ``config.yaml`` is unreadable."""
    diffs = stored_differences(folder, cfg, seed)
    if diffs:
        shown = "; ".join(diffs[:5]) + (f"; and {len(diffs) - 5} more" if len(diffs) > 5 else "")
        raise CheckpointError(
            f"--resume: {folder.path}/config.yaml differs from the requested configuration in "
            f"{shown} (stored -> requested); resume with the same config file, --vut, --seed "
            "and overrides"
        )
