"""Checkpoint serialisation: what a candidate's folder holds, and reading it back to resume.

``checkpoints/step_XXXXXXXXX/`` holds the candidate's ``model.zip`` (a plain SB3 zip, the
policy that evaluation and selection use). The *latest* checkpoint also holds what a resume
needs (:data:`~sumo_ayss.training.checkpoint_files.RESUME_FILES`, ``state.json``,
``torch_rng.pt``): the
full model with its optimizer, the replay buffer, the counters, the episode anchor (the env
state at the candidate plus the actions taken since) and every RNG. ``latest.json`` points at
it and is written last, so a kill at any moment leaves a resumable folder.

The file names, ``state.json`` and ``latest.json`` are
:mod:`sumo_ayss.training.checkpoint_files`'s (their one writer and reader), ``eval.csv``
:mod:`sumo_ayss.run_folder`'s; this module holds what goes into them and the SB3/torch
serialisation of the model, the buffer and torch's RNG.
"""

from __future__ import annotations

import logging
import random
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import torch as th
from stable_baselines3.common.vec_env import VecEnv

from sumo_ayss.agents.dqn import AyssDQN
from sumo_ayss.agents.weights import read_policy_state
from sumo_ayss.run_folder import RunFolder, read_eval_table
from sumo_ayss.training.checkpoint_files import (
    LATEST_JSON,
    REPLAY_PKL,
    RESUME_FILES,
    RESUME_MODEL_ZIP,
    STATE_JSON,
    TORCH_RNG_PT,
    read_latest,
    write_checkpoint_state,
)
from sumo_ayss.util.atomic import atomic_write_with, remove_stale_temporaries
from sumo_ayss.util.errors import CheckpointError

logger = logging.getLogger(__name__)


def atomic_model_save(model: AyssDQN, path: Path) -> None:
    """Save ``model`` (SB3 zip) to ``path`` atomically."""
    atomic_write_with(path, model.save)


def save_resume_state(
    model: AyssDQN,
    step_dir: Path,
    next_eval: int,
    anchor: dict[str, Any],
    actions_since_anchor: list[list[int]],
) -> None:
    """Write what a resume needs into ``step_dir`` (model, buffer, counters, RNGs).

    Args:
        model: The learner, at a consistent point (a rollout start or the end of ``learn``).
        step_dir: The candidate's checkpoint folder.
        next_eval: The step [transitions] of the next candidate.
        anchor: The env state at the candidate (episode start(s), env RNGs), JSON-able.
        actions_since_anchor: One list of actions (one per env) per vec-env step since.
    """
    atomic_model_save(model, step_dir / RESUME_MODEL_ZIP)
    atomic_write_with(step_dir / REPLAY_PKL, model.save_replay_buffer)
    state = {
        "num_timesteps": model.num_timesteps,
        "next_eval": next_eval,
        **anchor,
        "actions_since_anchor": actions_since_anchor,
        "numpy_rng": _jsonable(np.random.get_state()),  # noqa: NPY002 (SB3 uses it)
        "python_rng": _jsonable(random.getstate()),
        # SB3 explores with the model's action space's own RNG; its load reseeds it.
        "action_space_rng": model.action_space.np_random.bit_generator.state,
    }
    torch_state = th.get_rng_state()
    atomic_write_with(step_dir / TORCH_RNG_PT, lambda tmp: th.save(torch_state, tmp))
    write_checkpoint_state(step_dir / STATE_JSON, state)


def prune_resume_files(ckpt_dir: Path, keep: Path) -> None:
    """Keep the replay buffer and full model of the latest checkpoint only (the buffer is
    ~6 MB per 100k transitions).

    Run after ``latest.json`` moves on and again at resume, so a kill between the two
    leaves no orphan behind for good.
    """
    for name in RESUME_FILES:
        for path in ckpt_dir.glob(f"step_*/{name}"):
            if path.parent != keep:
                path.unlink(missing_ok=True)


def latest_checkpoint(ckpt_dir: Path) -> Path | None:
    """The folder ``latest.json`` points at; None without ``latest.json``.

    Raises:
        CheckpointError: ``latest.json`` is unreadable or points at no checkpoint folder.
    """
    path = ckpt_dir / LATEST_JSON
    if not path.is_file():
        return None
    _, name = read_latest(path)
    latest = ckpt_dir / name
    if not latest.is_dir():
        raise CheckpointError(f"{path} points at {name}, which does not exist")
    return latest


def clean_leftovers(run_dir: Path, ckpt_dir: Path) -> None:
    """Delete what a killed run left half-done: temporary files, and checkpoint folders
    newer than ``latest.json`` (a kill during a checkpoint; the resumed run redoes them).
    """
    for path in remove_stale_temporaries(run_dir):
        logger.info("removed temporary file %s", path)
    latest = latest_checkpoint(ckpt_dir)
    for step_dir in sorted(ckpt_dir.glob("step_*")):
        if step_dir.is_dir() and (latest is None or step_dir.name > latest.name):
            shutil.rmtree(step_dir)
            logger.info("removed unfinished checkpoint %s", step_dir)


def load_model(latest: Path, env: VecEnv, device: str, tensorboard_log: str) -> AyssDQN:
    """The full model of checkpoint ``latest``, with its replay buffer, on ``env``.

    Raises:
        CheckpointError: The model or the buffer is unreadable.
    """
    # Resuming trusts the folder: SB3's loader unpickles parts of model.zip and replay.pkl
    # (see "Trust model" in the README); evaluating and reporting never do.
    try:
        model = AyssDQN.load(
            str(latest / RESUME_MODEL_ZIP),
            env=env,
            device=device,
            tensorboard_log=tensorboard_log,
        )
    except Exception as e:  # zipfile, pickle, torch: any corruption
        raise CheckpointError(
            f"{latest / RESUME_MODEL_ZIP}: unreadable checkpoint ({type(e).__name__}: {e})"
        ) from e
    try:
        model.load_replay_buffer(latest / REPLAY_PKL)
    except Exception as e:
        raise CheckpointError(
            f"{latest / REPLAY_PKL}: unreadable replay buffer ({type(e).__name__}: {e})"
        ) from e
    return model


def earlier_candidates(run_dir: Path, eval_path: Path, step: int) -> list[dict[str, Any]]:
    """The rows of ``eval.csv`` up to ``step``, each candidate checked to be a readable policy.

    Raises:
        CheckpointError: A row's checkpoint is outside ``checkpoints/`` or unreadable.
    """
    rows = [r for r in read_eval_table(eval_path) if r["step"] <= step]
    for row in rows:  # every earlier candidate must still be a readable policy
        ckpt = Path(str(row["checkpoint"]))
        if (
            ckpt.is_absolute()
            or ".." in ckpt.parts
            or ckpt.parts[:1] != (RunFolder(run_dir).checkpoints.name,)
        ):
            raise CheckpointError(
                f"{eval_path}: step {row['step']}: checkpoint must be a path "
                f"under checkpoints/, got {str(ckpt)!r}"
            )
        read_policy_state(run_dir / ckpt)
    return rows


def restore_rngs(state: dict[str, Any], model: AyssDQN) -> None:
    """Put numpy's, Python's and the action space's RNGs where ``state`` has them."""
    np.random.set_state(_tuple_state(state["numpy_rng"]))  # noqa: NPY002 (SB3 uses it)
    random.setstate(_tuple_state(state["python_rng"]))
    model.action_space.np_random.bit_generator.state = state["action_space_rng"]


def restore_torch_rng(latest: Path) -> None:
    """Put torch's RNG where checkpoint ``latest`` has it."""
    try:
        th.set_rng_state(th.load(latest / TORCH_RNG_PT, weights_only=True))
    except Exception as e:
        raise CheckpointError(f"{latest / TORCH_RNG_PT}: unreadable ({e})") from e


def _jsonable(obj: Any) -> Any:
    if isinstance(obj, np.ndarray):
        return {"__ndarray__": obj.tolist(), "dtype": str(obj.dtype)}
    if isinstance(obj, tuple | list):
        return [_jsonable(x) for x in obj]
    return obj


def _tuple_state(obj: Any) -> Any:
    if isinstance(obj, dict) and "__ndarray__" in obj:
        return np.array(obj["__ndarray__"], dtype=obj["dtype"])
    if isinstance(obj, list):
        return tuple(_tuple_state(x) for x in obj)
    return obj
