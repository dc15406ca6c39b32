"""A run's metadata, written once when training starts.

What goes into ``config.yaml``, ``command.txt``, ``versions.json`` and ``seeds.json``; the
files themselves are written by :mod:`sumo_ayss.run_folder`'s writers (the one writer of
each file).
"""

from __future__ import annotations

import platform
import shlex
from collections.abc import Sequence
from importlib import metadata

from sumo_ayss.config import ExperimentConfig
from sumo_ayss.run_folder import (
    RunConfig,
    RunFolder,
    Seeds,
    write_provenance,
    write_run_config,
)
from sumo_ayss.util.paths import portable_python

#: The training entry point, as ``command.txt`` names it (``python -m <this>``).
ENTRY_MODULE = "sumo_ayss.train"


def versions() -> dict[str, str]:
    """Python, platform and package versions (``versions.json``)."""
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


def write_metadata(
    folder: RunFolder, cfg: ExperimentConfig, seed: int, argv: Sequence[str]
) -> None:
    """Create the run folder and write its metadata files (before any checkpoint).

    Args:
        folder: The run folder.
        cfg: The resolved experiment configuration.
        seed: The training seed (also SUMO's).
        argv: The command line's arguments (after ``python -m sumo_ayss.train``).
    """
    folder.path.mkdir(parents=True, exist_ok=True)
    # config.yaml before checkpoints/: a run killed in between must look resumable
    # (the pipeline resumes a folder with config.yaml; checkpoints/ alone is refused).
    write_run_config(folder.config, RunConfig(cfg.env.vut, seed, cfg.to_dict()))
    folder.checkpoints.mkdir(exist_ok=True)
    command = shlex.join([portable_python(), "-m", ENTRY_MODULE, *argv])
    write_provenance(folder, command, versions(), Seeds(seed, seed, cfg.train.eval_seed))
