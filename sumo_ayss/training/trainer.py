"""Train SPCP candidates for one (case, VUT, seed) and select the SPCP: :func:`train` and
the :class:`Trainer` (the stage's entry point is :mod:`sumo_ayss.train`).

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

The layout, file names and the one writer and reader of each file are
:mod:`sumo_ayss.run_folder`'s. The :class:`Trainer` composes the pieces in
:mod:`sumo_ayss.training` (run metadata, checkpoints, the training env(s) behind one
collector interface, the step callback); SB3's private state is reached only through
:mod:`sumo_ayss.agents.sb3_adapter`.
"""

from __future__ import annotations

import dataclasses
import logging
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import torch as th

from sumo_ayss.agents import sb3_adapter
from sumo_ayss.agents.dqn import AyssDQN
from sumo_ayss.agents.hparams import DQNHyperParams
from sumo_ayss.config import (
    ExperimentConfig,
    check_out_dir,
    check_seed,
)
from sumo_ayss.envs.odd import scenario_set
from sumo_ayss.envs.pair_env import PairEnv
from sumo_ayss.envs.vec_env import PairVecEnv
from sumo_ayss.run_folder import EVAL_SCHEMA, RunFolder, StudyFolder, write_eval_table, write_spcp
from sumo_ayss.scenarios.rollout import summarize
from sumo_ayss.training import checkpoint
from sumo_ayss.training.callback import CandidateCallback
from sumo_ayss.training.checkpoint_files import (
    LATEST_JSON,
    STATE_JSON,
    read_checkpoint_state,
    write_latest,
)
from sumo_ayss.training.collectors import (
    Collector,
    PairsCollector,
    Rollout,
    SingleEnvCollector,
    evaluate_on_vec,
    make_collector,
)
from sumo_ayss.training.config_check import check_same_config
from sumo_ayss.training.early_stop import StopDecision, rule_stops
from sumo_ayss.training.run_metadata import write_metadata
from sumo_ayss.training.selection import select_spcp
from sumo_ayss.util.atomic import atomic_copy
from sumo_ayss.util.errors import CheckpointError, ConfigError

__all__ = [
    "Trainer",
    "check_device",
    "evaluate_on_vec",
    "hparams_for_n_envs",
    "train",
]

logger = logging.getLogger(__name__)


class Trainer:
    """Owns one run: its folder, env(s), model, candidates and evaluation table.

    The concerns live in :mod:`sumo_ayss.training`: run metadata (``run_metadata``),
    checkpoints (``checkpoint``), the training env(s) (``collectors``: one env or N pairs,
    behind one interface) and the step callback (``callback``); SPCP selection is
    :func:`~sumo_ayss.training.selection.select_spcp`. Every run-folder file is written and read
    through :mod:`sumo_ayss.run_folder`; SB3's private state is touched through
    :mod:`sumo_ayss.agents.sb3_adapter` only.
    """

    def __init__(self, cfg: ExperimentConfig, seed: int, run_dir: Path) -> None:
        self.cfg = cfg
        self.seed = seed
        self.run_dir = run_dir
        self.folder = RunFolder(run_dir)
        self.ckpt_dir = self.folder.checkpoints
        self.eval_path = self.folder.eval_table
        self.scenarios = scenario_set(cfg.env, cfg.train.n_eval_scenarios, cfg.train.eval_seed)
        self.rows: list[dict[str, Any]] = []
        self.next_eval = cfg.train.eval_every
        self.n_envs = cfg.train.n_envs
        self.collector: Collector = make_collector(cfg.env, self.n_envs, seed)
        self.vec_env = self.collector.vec_env
        self.model: AyssDQN | None = None
        #: Between a candidate and its checkpoint: the candidate's folder, the env state
        #: right after the candidate (episode start(s), RNGs) and the actions taken since.
        self._pending_dir: Path | None = None
        self._anchor: dict[str, Any] = {}
        self._actions_since_anchor: list[list[int]] = []
        #: The early-stopping rule's decision once it stopped the run (else None).
        self.stopped: StopDecision | None = None

    @property
    def env(self) -> PairEnv | None:
        """The single training env (``n_envs == 1``), else None."""
        collector = self.collector
        return collector.env if isinstance(collector, SingleEnvCollector) else None

    @property
    def pair_vec(self) -> PairVecEnv | None:
        """The pairs' vec env (``n_envs > 1``), else None."""
        collector = self.collector
        return collector.pair_vec if isinstance(collector, PairsCollector) else None

    # -- folder ------------------------------------------------------------------------

    def write_metadata(self, argv: Sequence[str]) -> None:
        """Create the run folder and write its metadata (:func:`~sumo_ayss.training.
        run_metadata.write_metadata`)."""
        write_metadata(self.folder, self.cfg, self.seed, argv)

    # -- model ---------------------------------------------------------------------------

    def new_model(self) -> AyssDQN:
        th.set_num_threads(self.cfg.train.torch_threads)
        self.model = AyssDQN(
            self.vec_env,
            hparams_for_n_envs(self.cfg.agent, self.n_envs),
            seed=self.seed,
            tensorboard_log=str(self.folder.tb),
            device=check_device(self.cfg.train.device),
        )
        return self.model

    def learn(self, progress_bar: bool) -> None:
        model = self.model
        assert model is not None
        remaining = self.cfg.train.total_timesteps - model.num_timesteps
        self.check_early_stop()  # a resumed run that had already stopped stays stopped
        if remaining > 0 and self.stopped is None:
            model.learn(
                total_timesteps=remaining,
                callback=CandidateCallback(self),
                reset_num_timesteps=model.num_timesteps == 0,
                tb_log_name="dqn",
                progress_bar=progress_bar,
            )
        self.save_checkpoint()  # a candidate of the last rollout
        if model.num_timesteps >= self.next_eval:  # the last candidate, at the very end
            self.candidate(rollout=None)
            self.save_checkpoint()

    # -- candidates ----------------------------------------------------------------------

    def candidate(self, rollout: Rollout | None = None) -> None:
        """Store the model as a candidate, evaluate it, and move the schedule.

        Args:
            rollout: SB3's rollout locals when called from the step callback (one env: at an
                episode boundary, whose start is restored after the evaluation; pairs: the
                step's transitions, not stored yet, are cut into truncations); None at the
                end of ``learn``.
        """
        model = self.model
        assert model is not None
        step = model.num_timesteps
        step_dir = self.folder.step_dir(step)
        step_dir.mkdir(parents=True, exist_ok=True)
        checkpoint.atomic_model_save(model, self.folder.candidate_model(step))

        results, wall = self.collector.evaluate(model, self.scenarios, rollout)
        env_state = self.collector.anchor()
        summary = summarize(results)

        row: dict[str, Any] = {"step": step, **summary.as_dict(), "wall_s": round(wall, 3)}
        row["checkpoint"] = self.folder.checkpoint_model(step_dir)
        row = {k: row[k] for k in EVAL_SCHEMA.names}
        self.rows.append(row)
        model.logger.record("eval/mean_return", summary.mean_return)
        model.logger.record("eval/crash_rate", summary.crash_rate)
        model.logger.record("eval/mean_final_headway_m", summary.mean_final_headway_m)
        logger.info("candidate %d: mean return %.3f", step, summary.mean_return)
        while self.next_eval <= step:
            self.next_eval += self.cfg.train.eval_every

        write_eval_table(self.eval_path, self.rows)
        self.check_early_stop()
        # The resume state is written at the next rollout start (save_checkpoint), once SB3
        # has stored this step's transitions and trained on them: from here on the actions
        # are recorded, so that a resume replays them from this episode start.
        self._anchor = env_state
        self._actions_since_anchor = []
        self._pending_dir = step_dir

    def check_early_stop(self) -> None:
        """Once the early-stopping rule (:func:`~sumo_ayss.training.early_stop.rule_stops`)
        stops the run, :attr:`stopped` holds why (the callback then ends ``learn``)."""
        if self.stopped is None:
            self.stopped = rule_stops(self.cfg.train, self.rows, str(self.run_dir))

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
        model = self.model
        assert model is not None
        checkpoint.save_resume_state(
            model, step_dir, self.next_eval, self._anchor, self._actions_since_anchor
        )
        write_latest(self.folder.checkpoints / LATEST_JSON, step_dir)
        self._pending_dir = None
        checkpoint.prune_resume_files(self.ckpt_dir, step_dir)

    # -- resume --------------------------------------------------------------------------

    def has_checkpoint(self) -> bool:
        """Whether ``latest.json`` names a checkpoint to resume from."""
        return checkpoint.latest_checkpoint(self.ckpt_dir) is not None

    def clean_leftovers(self) -> None:
        """Delete what a killed run left half-done (:func:`~sumo_ayss.training.checkpoint.
        clean_leftovers`)."""
        checkpoint.clean_leftovers(self.run_dir, self.ckpt_dir)

    def resume(self) -> None:
        """Continue from the latest complete checkpoint."""
        latest = checkpoint.latest_checkpoint(self.ckpt_dir)
        if latest is None:
            raise CheckpointError(f"{self.run_dir}: no checkpoint to resume from")
        state = read_checkpoint_state(latest / STATE_JSON)
        th.set_num_threads(self.cfg.train.torch_threads)
        model = checkpoint.load_model(
            latest,
            self.vec_env,
            device=check_device(self.cfg.train.device),
            tensorboard_log=str(self.folder.tb),
        )
        checkpoint.prune_resume_files(self.ckpt_dir, latest)
        self.model = model
        try:
            self.next_eval = int(state["next_eval"])
            self.rows = checkpoint.earlier_candidates(
                self.run_dir, self.eval_path, model.num_timesteps
            )
            actions = [np.asarray(a, dtype=np.int64) for a in state["actions_since_anchor"]]
            self.collector.restore(model, state, self.seed)
            # The steps taken between the candidate and the checkpoint, replayed: the envs are
            # then where the killed run's were (SB3 holds their observation).
            for action in actions:
                obs, _, dones, _ = self.vec_env.step(action)
                sb3_adapter.set_rollout_start(model, obs, dones)  # type: ignore[arg-type]
            checkpoint.restore_rngs(state, model)
        except (KeyError, TypeError, ValueError) as e:
            raise CheckpointError(
                f"{latest / STATE_JSON}: inconsistent checkpoint state ({type(e).__name__}: {e})"
            ) from e
        checkpoint.restore_torch_rng(latest)
        logger.info("resumed %s at step %d", self.run_dir, model.num_timesteps)

    # -- selection -----------------------------------------------------------------------

    def select(self) -> dict[str, Any]:
        choice = select_spcp(self.rows, self.cfg.train.selection, str(self.run_dir))
        if self.stopped is not None:
            choice = dataclasses.replace(choice, reason=f"{choice.reason}; {self.stopped.reason}")
        row = self.rows[choice.index]
        atomic_copy(self.run_dir / row["checkpoint"], self.folder.spcp_zip)
        record = {**dataclasses.asdict(choice), "checkpoint": row["checkpoint"], "row": row}
        write_spcp(self.folder.spcp_json, choice, row["checkpoint"], row)
        return record

    def close(self) -> None:
        self.collector.close()


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
    folder = StudyFolder(out).run(cfg.env.case, cfg.env.vut, seed)
    run_dir = folder.path
    if resume:
        if not folder.config.is_file():
            raise CheckpointError(f"--resume: no run folder at {run_dir}")
        check_same_config(folder, cfg, seed)
    elif folder.checkpoints.exists():
        raise CheckpointError(
            f"{run_dir} already holds a run; pass --resume to continue it or choose another --out"
        )
    draws = cfg.env.vut_type.random_draws()
    if draws:
        logger.warning(
            "VUT %s draws random numbers in SUMO (%s): its episodes are reproducible for a "
            "given seed and path, but training's pairs and the outcome stage draw other "
            "numbers, so they agree in distribution, not episode for episode",
            cfg.env.vut,
            "; ".join(draws),
        )
    trainer = Trainer(cfg, seed, run_dir)
    try:
        if resume:
            trainer.clean_leftovers()
        if resume and trainer.has_checkpoint():
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
