"""Train SPCP candidates for one (case, VUT, seed) and select the SPCP.

    python -m sumo_ayss.train --config configs/car_following.yaml --vut pi1 --seed 0
    python -m sumo_ayss.train --config configs/car_following.yaml --vut pi1 --seed 0 --resume

Every ``train.eval_every`` steps the model is stored as an SPCP candidate and evaluated on
``train.n_eval_scenarios`` fixed initial conditions (``train.eval_seed``: the same for every
VUT and seed), in the process's one SUMO simulation: the training env itself is borrowed at
an episode boundary and put back exactly where it was. At the end the SPCP is selected by
``train.selection``.

With ``train.n_envs > 1`` the transitions come from that many VUT-POV pairs in one SUMO
simulation (:class:`~sumo_ayss.envs.vec_env.PairVecEnv`). Their episodes never end together,
so a candidate is evaluated as soon as ``eval_every`` is reached, on the pairs themselves
(``n_envs`` scenarios at a time; the same episodes as the single env would run), and the
pairs' unfinished training episodes are then cut: their last transitions are stored as
time-limit truncations (bootstrapped, not terminal) and every pair starts a fresh episode.

Run folder ``<out>/<case>/<vut>/seed_<k>/``:

    config.yaml        the exact resolved configuration (with the seed; the VUT is env.vut)
    command.txt        the command line
    versions.json      Python, package, SUMO, torch, SB3, gymnasium, numpy versions
    seeds.json         training seed, SUMO seed, evaluation-scenario seed
    eval.csv           one row per candidate (step, mean_return, crash_rate, ...)
    checkpoints/       step_XXXXXXXX/model.zip per candidate; the latest also holds the
                       replay buffer and RNG state; latest.json points at it
    spcp.json, spcp.zip  the selected candidate and why
    progress.json      training progress for watchers (stage, step, total, rate), rewritten
                       atomically every few seconds
    tb/                TensorBoard logs

Every file is written atomically (temporary file + rename), and ``latest.json`` is written
last, so a kill at any moment leaves a resumable folder.
"""

from __future__ import annotations

import argparse
import dataclasses
import logging
import math
import platform
import random
import shlex
import shutil
import sys
import time
from collections.abc import Sequence
from importlib import metadata
from pathlib import Path
from typing import Any

import numpy as np
import torch as th
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.monitor import Monitor
from stable_baselines3.common.vec_env import DummyVecEnv, VecEnv, VecMonitor

from sumo_ayss.agents.dqn import AyssDQN
from sumo_ayss.agents.greedy import GreedyPolicy
from sumo_ayss.agents.hparams import DQNHyperParams
from sumo_ayss.agents.weights import read_policy_state
from sumo_ayss.atomic import atomic_copy, atomic_write_with, remove_stale_temporaries
from sumo_ayss.cli import prog
from sumo_ayss.config import (
    ExperimentConfig,
    check_out_dir,
    check_seed,
    experiment_from_dict,
    load_experiment,
    to_dict,
)
from sumo_ayss.envs import make_env
from sumo_ayss.envs.odd import InitialCondition, sample_initial_conditions
from sumo_ayss.envs.pair_env import PairEnv
from sumo_ayss.envs.vec_env import EpisodeTrace, PairVecEnv
from sumo_ayss.errors import AyssError, CheckpointError, ConfigError
from sumo_ayss.paths import portable_python
from sumo_ayss.run_folder import (
    CHECKPOINTS_DIR,
    EVAL_COLUMNS,
    MODEL_ZIP,
    REPLAY_PKL,
    RESUME_FILES,
    RESUME_MODEL_ZIP,
    STATE_JSON,
    TORCH_RNG_PT,
    RunConfig,
    RunFolder,
    Seeds,
    read_checkpoint_state,
    read_eval_table,
    read_latest,
    read_run_config,
    run_dir_for,
    write_checkpoint_state,
    write_command,
    write_eval_table,
    write_latest,
    write_progress,
    write_run_config,
    write_seeds,
    write_spcp,
    write_versions,
)
from sumo_ayss.scenarios.rollout import EpisodeResult, Policy, run_episodes, summarize
from sumo_ayss.selection import select_spcp

logger = logging.getLogger(__name__)


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


# ---------------------------------------------------------------------- the trainer


class Trainer:
    """Owns one run: its folder, env, model, candidates and evaluation table."""

    def __init__(self, cfg: ExperimentConfig, seed: int, run_dir: Path) -> None:
        self.cfg = cfg
        self.seed = seed
        self.run_dir = run_dir
        self.folder = RunFolder(run_dir)
        self.ckpt_dir = self.folder.checkpoints
        self.eval_path = self.folder.eval_table
        self.scenarios = sample_initial_conditions(
            cfg.env.odd, cfg.train.n_eval_scenarios, cfg.train.eval_seed
        )
        self.rows: list[dict[str, Any]] = []
        self.next_eval = cfg.train.eval_every
        self.n_envs = cfg.train.n_envs
        #: The single env (``n_envs == 1``) or the pairs' vec env (``n_envs > 1``).
        self.env: PairEnv | None = None
        self.pair_vec: PairVecEnv | None = None
        self.vec_env: VecEnv
        if self.n_envs == 1:
            env = self.env = make_env(cfg.env, sumo_seed=seed)
            self.vec_env = DummyVecEnv([lambda: Monitor(env)])
        else:
            self.pair_vec = PairVecEnv(cfg.env, self.n_envs, sumo_seed=seed)
            self.vec_env = VecMonitor(self.pair_vec)
        self.model: AyssDQN | None = None
        #: Between a candidate and its checkpoint: the candidate's folder, the env state
        #: right after the candidate (episode start(s), RNGs) and the actions taken since.
        self._pending_dir: Path | None = None
        self._anchor: dict[str, Any] = {}
        self._actions_since_anchor: list[list[int]] = []

    # -- folder ------------------------------------------------------------------------

    def write_metadata(self, argv: Sequence[str]) -> None:
        self.run_dir.mkdir(parents=True, exist_ok=True)
        resolved = RunConfig(self.cfg.env.vut, self.seed, self.cfg.to_dict())
        # config.yaml before checkpoints/: a run killed in between must look resumable
        # (the pipeline resumes a folder with config.yaml; checkpoints/ alone is refused).
        write_run_config(self.folder.config, resolved)
        self.ckpt_dir.mkdir(exist_ok=True)
        write_command(
            self.folder.command,
            shlex.join([portable_python(), "-m", __spec__.name, *argv])
            if __spec__
            else shlex.join(argv),
        )
        write_versions(self.folder.versions, versions())
        write_seeds(self.folder.seeds, Seeds(self.seed, self.seed, self.cfg.train.eval_seed))

    # -- model ---------------------------------------------------------------------------

    def new_model(self) -> AyssDQN:
        th.set_num_threads(self.cfg.train.torch_threads)
        self.model = AyssDQN(
            self.vec_env,
            hparams_for_n_envs(self.cfg.agent, self.n_envs),
            seed=self.seed,
            tensorboard_log=str(self.run_dir / "tb"),
            device=check_device(self.cfg.train.device),
        )
        return self.model

    def learn(self, progress_bar: bool) -> None:
        model = self.model
        assert model is not None
        remaining = self.cfg.train.total_timesteps - model.num_timesteps
        if remaining > 0:
            model.learn(
                total_timesteps=remaining,
                callback=_CandidateCallback(self),
                reset_num_timesteps=model.num_timesteps == 0,
                tb_log_name="dqn",
                progress_bar=progress_bar,
            )
        self.save_checkpoint()  # a candidate of the last rollout
        if model.num_timesteps >= self.next_eval:  # the last candidate, at the very end
            self.candidate(at_episode_boundary=False)
            self.save_checkpoint()

    # -- candidates ----------------------------------------------------------------------

    def candidate(
        self, at_episode_boundary: bool = True, rollout: dict[str, Any] | None = None
    ) -> None:
        """Store the model as a candidate, evaluate it, checkpoint, and move the schedule.

        Args:
            at_episode_boundary: (one env) the env has just started an episode, whose start
                is restored after the evaluation.
            rollout: (``n_envs > 1``) SB3's rollout locals when called from the callback:
                the step's transitions, not stored yet, are cut into truncations there.
        """
        model = self.model
        assert model is not None
        step = model.num_timesteps
        step_dir = self.folder.step_dir(step)
        step_dir.mkdir(parents=True, exist_ok=True)
        _atomic_model_save(model, step_dir / MODEL_ZIP)

        t0 = time.perf_counter()
        if self.pair_vec is not None:
            results = evaluate_on_vec(self.pair_vec, GreedyPolicy(model), self.scenarios)
            wall = time.perf_counter() - t0
            self._restart_pairs(rollout)
            env_state = self._pairs_state()
        else:
            # Borrow the training env: evaluation resets it to fixed initial conditions (this
            # does not consume its RNG); afterwards the current episode's start is restored
            # exactly, so the observation SB3 holds stays true.
            env = self.env
            assert env is not None
            current_ic = env.initial_condition
            results = run_episodes(env, GreedyPolicy(model), self.scenarios)
            wall = time.perf_counter() - t0
            if at_episode_boundary and current_ic is not None:
                env.reset(options={"initial_condition": current_ic})
            ic_dict = dataclasses.asdict(current_ic) if current_ic is not None else None
            env_state = {"initial_condition": ic_dict, "env_rng": env.np_random.bit_generator.state}
        summary = summarize(results)

        row: dict[str, Any] = {"step": step, **summary.as_dict(), "wall_s": round(wall, 3)}
        row["checkpoint"] = self.folder.checkpoint_model(step_dir)
        row = {k: row[k] for k in EVAL_COLUMNS}
        self.rows.append(row)
        model.logger.record("eval/mean_return", summary.mean_return)
        model.logger.record("eval/crash_rate", summary.crash_rate)
        model.logger.record("eval/mean_final_headway_m", summary.mean_final_headway_m)
        logger.info("candidate %d: mean return %.3f", step, summary.mean_return)
        while self.next_eval <= step:
            self.next_eval += self.cfg.train.eval_every

        write_eval_table(self.eval_path, self.rows)
        # The resume state is written at the next rollout start (save_checkpoint), once SB3
        # has stored this step's transitions and trained on them: from here on the actions
        # are recorded, so that a resume replays them from this episode start.
        self._anchor = env_state
        self._actions_since_anchor = []
        self._pending_dir = step_dir

    def record_actions(self, actions: Any) -> None:
        """Note a step's actions (between a candidate and its checkpoint, for the replay)."""
        if self._pending_dir is not None:
            self._actions_since_anchor.append(np.asarray(actions).reshape(-1).tolist())

    def save_checkpoint(self) -> None:
        """Write the resume state of the last candidate, if one is pending.

        Called where SB3's state is consistent: at the start of a rollout (the previous
        step's transitions are stored and trained on, ``num_timesteps`` counts exactly the
        buffer's transitions, a new ``train_freq`` cycle begins) and at the end of ``learn``.
        The env state is the candidate's episode start(s) plus the actions taken since,
        which a resume replays (SUMO is deterministic for a VUT without random parameters).
        """
        step_dir = self._pending_dir
        if step_dir is None:
            return
        self._save_resume_state(step_dir)
        write_latest(self.folder.latest, step_dir)
        self._pending_dir = None
        self._prune_resume_files(step_dir)

    def _prune_resume_files(self, keep: Path) -> None:
        """Keep the replay buffer and full model of the latest checkpoint only (the buffer is
        ~6 MB per 100k transitions).

        Run after ``latest.json`` moves on and again at resume, so a kill between the two
        leaves no orphan behind for good.
        """
        for name in RESUME_FILES:
            for path in self.ckpt_dir.glob(f"step_*/{name}"):
                if path.parent != keep:
                    path.unlink(missing_ok=True)

    def _restart_pairs(self, rollout: dict[str, Any] | None) -> None:
        """After an evaluation on the pairs: a fresh training episode on every pair.

        Each pair's unfinished episode is cut. Called from the callback (``rollout``: SB3's
        rollout locals), the step's transitions are not stored yet: a pair whose episode was
        still running gets ``done`` with its observation as ``terminal_observation`` and
        ``TimeLimit.truncated`` (so the replay buffer bootstraps it, as at a time limit), and
        the observation SB3 continues from becomes the fresh episode's first.
        """
        model = self.model
        assert model is not None and self.pair_vec is not None
        obs = self.vec_env.reset()  # VecMonitor too: its running episode sums restart
        assert isinstance(obs, np.ndarray)
        if rollout is None:
            model._last_obs = obs
            model._last_episode_starts = np.ones((self.n_envs,), dtype=bool)
            return
        new_obs, dones, infos = rollout["new_obs"], rollout["dones"], rollout["infos"]
        for i in range(self.n_envs):
            if not dones[i]:
                infos[i]["terminal_observation"] = new_obs[i].copy()
                infos[i]["TimeLimit.truncated"] = True
                dones[i] = True
        new_obs[:] = obs  # in place: SB3 stores and continues from these very arrays

    def _pairs_state(self) -> dict[str, Any]:
        """Resume state of the pairs: their current episode starts and RNGs."""
        assert self.pair_vec is not None
        return {
            "initial_conditions": [
                dataclasses.asdict(ic) if ic is not None else None
                for ic in self.pair_vec.initial_conditions
            ],
            "env_rngs": [env.np_random.bit_generator.state for env in self.pair_vec.envs],
        }

    def _save_resume_state(self, step_dir: Path) -> None:
        model = self.model
        assert model is not None
        _atomic_model_save(model, step_dir / RESUME_MODEL_ZIP)
        atomic_write_with(step_dir / REPLAY_PKL, model.save_replay_buffer)
        state = {
            "num_timesteps": model.num_timesteps,
            "next_eval": self.next_eval,
            **self._anchor,
            "actions_since_anchor": self._actions_since_anchor,
            "numpy_rng": _jsonable(np.random.get_state()),  # noqa: NPY002 (SB3 uses it)
            "python_rng": _jsonable(random.getstate()),
            # SB3 explores with the model's action space's own RNG; its load reseeds it.
            "action_space_rng": model.action_space.np_random.bit_generator.state,
        }
        torch_state = th.get_rng_state()
        atomic_write_with(step_dir / TORCH_RNG_PT, lambda tmp: th.save(torch_state, tmp))
        write_checkpoint_state(step_dir / STATE_JSON, state)

    def _latest(self) -> Path | None:
        path = self.folder.latest
        if not path.is_file():
            return None
        _, name = read_latest(path)
        latest = self.ckpt_dir / name
        if not latest.is_dir():
            raise CheckpointError(f"{path} points at {name}, which does not exist")
        return latest

    # -- resume --------------------------------------------------------------------------

    def clean_leftovers(self) -> None:
        """Delete what a killed run left half-done: temporary files, and checkpoint folders
        newer than ``latest.json`` (a kill during a checkpoint; the resumed run redoes them).
        """
        for path in remove_stale_temporaries(self.run_dir):
            logger.info("removed temporary file %s", path)
        latest = self._latest()
        for step_dir in sorted(self.ckpt_dir.glob("step_*")):
            if step_dir.is_dir() and (latest is None or step_dir.name > latest.name):
                shutil.rmtree(step_dir)
                logger.info("removed unfinished checkpoint %s", step_dir)

    def resume(self) -> None:
        """Continue from the latest complete checkpoint."""
        latest = self._latest()
        if latest is None:
            raise CheckpointError(f"{self.run_dir}: no checkpoint to resume from")
        state = read_checkpoint_state(latest / STATE_JSON)
        th.set_num_threads(self.cfg.train.torch_threads)
        # Resuming trusts the folder: SB3's loader unpickles parts of model.zip and replay.pkl
        # (see "Trust model" in the README); evaluating and reporting never do.
        try:
            model = AyssDQN.load(
                str(latest / RESUME_MODEL_ZIP),
                env=self.vec_env,
                device=check_device(self.cfg.train.device),
                tensorboard_log=str(self.run_dir / "tb"),
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
        self._prune_resume_files(latest)
        self.model = model
        try:
            self.next_eval = int(state["next_eval"])
            self.rows = [
                r for r in read_eval_table(self.eval_path) if r["step"] <= model.num_timesteps
            ]
            for row in self.rows:  # every earlier candidate must still be a readable policy
                ckpt = Path(str(row["checkpoint"]))
                if ckpt.is_absolute() or ".." in ckpt.parts or ckpt.parts[:1] != (CHECKPOINTS_DIR,):
                    raise CheckpointError(
                        f"{self.eval_path}: step {row['step']}: checkpoint must be a path "
                        f"under checkpoints/, got {str(ckpt)!r}"
                    )
                read_policy_state(self.run_dir / ckpt)
            actions = [np.asarray(a, dtype=np.int64) for a in state["actions_since_anchor"]]
            if self.pair_vec is not None:
                self._resume_pairs(state)
            else:
                # Put the env back at the checkpoint's episode start, with its RNG where it
                # was (through the Monitor wrapper, which must see the reset too).
                assert isinstance(self.vec_env, DummyVecEnv) and self.env is not None
                monitor = self.vec_env.envs[0]
                monitor.reset(seed=self.seed)  # starts SUMO and creates the env RNG
                self.env.np_random.bit_generator.state = state["env_rng"]
                ic = state["initial_condition"]
                obs, _ = monitor.reset(
                    options={"initial_condition": InitialCondition(**ic)} if ic else None
                )
                model._last_obs = obs[None, :]  # type: ignore[assignment]
                model._last_episode_starts = np.ones((1,), dtype=bool)
            # The steps taken between the candidate and the checkpoint, replayed: the envs are
            # then where the killed run's were (SB3 holds their observation).
            for action in actions:
                obs, _, dones, _ = self.vec_env.step(action)
                model._last_obs = obs  # type: ignore[assignment]
                model._last_episode_starts = dones
            np.random.set_state(_tuple_state(state["numpy_rng"]))  # noqa: NPY002 (SB3 uses it)
            random.setstate(_tuple_state(state["python_rng"]))
            model.action_space.np_random.bit_generator.state = state["action_space_rng"]
        except (KeyError, TypeError, ValueError) as e:
            raise CheckpointError(
                f"{latest / STATE_JSON}: inconsistent checkpoint state ({type(e).__name__}: {e})"
            ) from e
        try:
            th.set_rng_state(th.load(latest / TORCH_RNG_PT, weights_only=True))
        except Exception as e:
            raise CheckpointError(f"{latest / TORCH_RNG_PT}: unreadable ({e})") from e
        logger.info("resumed %s at step %d", self.run_dir, model.num_timesteps)

    def _resume_pairs(self, state: dict[str, Any]) -> None:
        """Restart every pair at its checkpointed episode start, RNGs where they were."""
        model = self.model
        assert model is not None and self.pair_vec is not None
        ics = state["initial_conditions"]
        self.vec_env.set_options(
            [{"initial_condition": InitialCondition(**ic)} if ic else {} for ic in ics]
        )
        obs = self.vec_env.reset()  # starts SUMO; given starts do not use the pairs' RNGs
        for env, rng_state in zip(self.pair_vec.envs, state["env_rngs"], strict=True):
            env.np_random.bit_generator.state = rng_state
        model._last_obs = obs  # type: ignore[assignment]
        model._last_episode_starts = np.ones((self.n_envs,), dtype=bool)

    # -- selection -----------------------------------------------------------------------

    def select(self) -> dict[str, Any]:
        choice = select_spcp(self.rows, self.cfg.train.selection)
        row = self.rows[choice.index]
        atomic_copy(self.run_dir / row["checkpoint"], self.folder.spcp_zip)
        record = {**dataclasses.asdict(choice), "checkpoint": row["checkpoint"], "row": row}
        write_spcp(self.folder.spcp_json, choice, row["checkpoint"], row)
        return record

    def close(self) -> None:
        self.vec_env.close()
        if self.env is not None:
            self.env.close()


PROGRESS_EVERY_S = 2.0
"""Seconds between two rewrites of a run's ``progress.json`` during training."""


class _CandidateCallback(BaseCallback):
    """Calls :meth:`Trainer.candidate` once ``eval_every`` is reached.

    One env: at the first episode end after it (the env is borrowed and restored there).
    Several pairs: at once (their episodes never end together; they are cut and restarted).
    The candidate's resume checkpoint follows at the next rollout start
    (:meth:`Trainer.save_checkpoint`); the steps in between are recorded for its replay.
    Every :data:`PROGRESS_EVERY_S` seconds it also rewrites ``progress.json``.
    """

    def __init__(self, trainer: Trainer) -> None:
        super().__init__()
        self.trainer = trainer
        self._t0 = time.monotonic()
        self._step0: int | None = None
        self._next_progress = 0.0

    def _write_progress(self) -> None:
        now = time.monotonic()
        if self._step0 is None:
            self._step0 = self.num_timesteps
        elapsed = now - self._t0
        rate = (self.num_timesteps - self._step0) / elapsed if elapsed > 0 else 0.0
        write_progress(
            self.trainer.run_dir,
            "train",
            step=int(self.num_timesteps),
            total=int(self.trainer.cfg.train.total_timesteps),
            rate_steps_per_s=round(rate, 2),
        )
        self._next_progress = now + PROGRESS_EVERY_S

    def _on_training_start(self) -> None:
        self._t0 = time.monotonic()
        self._step0 = self.num_timesteps
        self._write_progress()

    def _on_training_end(self) -> None:
        self._write_progress()

    def _on_rollout_start(self) -> None:
        self.trainer.save_checkpoint()

    def _on_step(self) -> bool:
        if time.monotonic() >= self._next_progress:
            self._write_progress()
        trainer = self.trainer
        trainer.record_actions(self.locals["actions"])
        if self.num_timesteps < trainer.next_eval:
            return True
        if trainer.pair_vec is not None:
            trainer.candidate(at_episode_boundary=False, rollout=self.locals)
        elif bool(self.locals["dones"][0]):
            trainer.candidate()
        return True


def check_device(device: str) -> str:
    """Return ``device`` (``train.device``) if torch can use it, else raise :class:`ConfigError`.

    Args:
        device: ``"cpu"``, ``"cuda"`` or ``"cuda:<index>"``.

    Raises:
        ConfigError: a CUDA device was asked for and torch has no CUDA (CPU-only build, no
            driver, no GPU) or fewer GPUs than the index.
    """
    if device.startswith("cuda"):
        if not th.cuda.is_available():
            raise ConfigError(
                f"train.device is {device!r} but torch {th.__version__} sees no CUDA device "
                f"(torch built with CUDA {th.version.cuda}); use train.device: cpu"
            )
        index = int(device.partition(":")[2] or 0)
        if index >= th.cuda.device_count():
            raise ConfigError(
                f"train.device is {device!r} but torch sees {th.cuda.device_count()} CUDA "
                f"device(s): cuda:0 .. cuda:{th.cuda.device_count() - 1}"
            )
    return device


def hparams_for_n_envs(hparams: DQNHyperParams, n_envs: int) -> DQNHyperParams:
    """Learner settings that keep ``hparams.update_to_data_ratio`` with ``n_envs`` envs.

    SB3 counts ``train_freq`` in vec-env steps, each adding ``n_envs`` transitions, so the
    same settings would do ``n_envs`` times fewer gradient steps per transition. This returns
    the smallest ``(train_freq, gradient_steps)`` with ``gradient_steps / (train_freq ·
    n_envs) = hparams.gradient_steps / hparams.train_freq`` (e.g. 4 and 1 become 1 and 2 for
    8 envs); ``n_envs == 1`` returns ``hparams`` unchanged. Everything else SB3 already counts
    in transitions (``learning_starts``, ``buffer_size``, ``target_update_interval``).
    """
    if n_envs == 1:
        return hparams
    per_step = n_envs * hparams.gradient_steps
    g = math.gcd(hparams.train_freq, per_step)
    return dataclasses.replace(
        hparams, train_freq=hparams.train_freq // g, gradient_steps=per_step // g
    )


def evaluate_on_vec(
    vec: PairVecEnv, policy: Policy, scenarios: Sequence[InitialCondition]
) -> list[EpisodeResult]:
    """:func:`~sumo_ayss.scenarios.rollout.run_episodes` on the pairs of ``vec``, N at a time.

    Each episode equals the single env's from the same initial condition under the same
    actions (:meth:`PairVecEnv.run_scenarios`); a greedy network policy called on a batch of
    N observations may differ from one called on one observation in the last float bits,
    which can only matter at exact ties of two actions' Q-values. ``vec`` needs a
    :meth:`~PairVecEnv.reset` afterwards.
    """
    return [_episode_result(trace) for trace in vec.run_scenarios(policy, scenarios)]


def _episode_result(trace: EpisodeTrace) -> EpisodeResult:
    """The :class:`EpisodeResult` of a trace, as ``run_episode`` tabulates an episode."""
    total = 0.0
    changed = False
    for reward, info in zip(trace.rewards, trace.infos, strict=True):
        total += float(reward)
        changed = changed or bool(info.get("lane_change_started", False))
    last = trace.infos[-1]
    return EpisodeResult(
        total, bool(last["collision"]), float(last["headway_m"]), len(trace.rewards), changed
    )


def _atomic_model_save(model: AyssDQN, path: Path) -> None:
    atomic_write_with(path, model.save)


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


# ---------------------------------------------------------------------- entry point


def train(
    cfg: ExperimentConfig,
    seed: int,
    out: Path,
    *,
    resume: bool = False,
    argv: Sequence[str] = (),
) -> Path:
    """Train one (case, VUT, seed) into its run folder; return the folder."""
    check_device(cfg.train.device)  # before the run folder exists
    seed = check_seed(seed, "--seed")
    check_out_dir(Path(out), "--out")
    run_dir = run_dir_for(out, cfg.env.case, cfg.env.vut, seed)
    config_file = RunFolder(run_dir).config
    if resume:
        if not config_file.is_file():
            raise CheckpointError(f"--resume: no run folder at {run_dir}")
        _check_same_config(run_dir, cfg, seed)
    elif RunFolder(run_dir).checkpoints.exists():
        raise CheckpointError(
            f"{run_dir} already holds a run; pass --resume to continue it or choose another --out"
        )
    trainer = Trainer(cfg, seed, run_dir)
    try:
        if resume:
            trainer.clean_leftovers()
        if resume and trainer._latest() is not None:
            trainer.resume()
        else:
            trainer.write_metadata(argv)
            trainer.new_model()  # SB3 seeds the env: its first reset uses ``seed``
        trainer.learn(progress_bar=cfg.train.progress_bar)
        choice = trainer.select()
        logger.info("SPCP: %s", choice["reason"])
    finally:
        trainer.close()
    return run_dir


def _check_same_config(run_dir: Path, cfg: ExperimentConfig, seed: int) -> None:
    path = RunFolder(run_dir).config
    stored = read_run_config(path)
    try:
        stored_cfg = experiment_from_dict(stored.experiment, run_dir)
    except ConfigError as e:
        raise CheckpointError(f"{path}: unreadable run configuration ({e})") from e
    stored_seed = stored.seed
    if stored_seed != seed or to_dict(stored_cfg) != to_dict(cfg):
        raise CheckpointError(
            f"--resume: {run_dir}/config.yaml differs from the requested configuration; "
            "resume with the same config file, --vut and --seed"
        )


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(
        prog=prog("python -m sumo_ayss.train"), description=__doc__.splitlines()[0]
    )
    parser.add_argument("--config", type=Path, default=None, help="experiment YAML")
    parser.add_argument("--vut", default=None, help="VUT name (overrides env.vut)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=Path, default=Path("runs"), help="runs root folder")
    parser.add_argument("--resume", action="store_true", help="continue a killed run")
    parser.add_argument(
        "--total-timesteps", type=int, default=None, help="override train.total_timesteps"
    )
    parser.add_argument("--eval-every", type=int, default=None, help="override train.eval_every")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.add_argument(
        "--device", default=None, help="override train.device (cpu, cuda, cuda:<index>)"
    )
    return parser.parse_args(argv)


def main(argv: Sequence[str] | None = None) -> None:
    argv = list(sys.argv[1:] if argv is None else argv)
    args = parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(name)s: %(message)s")
    try:
        cfg = load_experiment(args.config).with_vut(args.vut)
        overrides: dict[str, Any] = {}
        if args.total_timesteps is not None:
            overrides["total_timesteps"] = args.total_timesteps
        if args.eval_every is not None:
            overrides["eval_every"] = args.eval_every
        if args.no_progress:
            overrides["progress_bar"] = False
        if args.device is not None:
            overrides["device"] = args.device
        cfg = dataclasses.replace(cfg, train=dataclasses.replace(cfg.train, **overrides))
        run_dir = train(cfg, args.seed, args.out, resume=args.resume, argv=argv)
    except AyssError as e:
        sys.exit(f"error: {e}")
    print(run_dir)


if __name__ == "__main__":
    main()
