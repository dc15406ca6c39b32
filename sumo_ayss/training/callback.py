"""The SB3 callback that schedules SPCP candidates, checkpoints and progress reports."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any, Protocol

from stable_baselines3.common.callbacks import BaseCallback

from sumo_ayss.agents import sb3_adapter
from sumo_ayss.config import ExperimentConfig
from sumo_ayss.run_folder import write_progress
from sumo_ayss.training.collectors import Collector, Rollout


class Trainer(Protocol):
    """What the callback asks of the training loop (:class:`sumo_ayss.training.trainer.Trainer`)."""

    run_dir: Path
    cfg: ExperimentConfig
    next_eval: int
    collector: Collector

    @property
    def stopped(self) -> object | None: ...

    def save_checkpoint(self) -> None: ...

    def record_actions(self, actions: Any) -> None: ...

    def candidate(self, rollout: Rollout | None = None) -> None: ...


PROGRESS_EVERY_S = 2.0
"""Seconds between two rewrites of a run's ``progress.json`` during training."""


class CandidateCallback(BaseCallback):
    """Calls :meth:`Trainer.candidate` once ``eval_every`` is reached.

    One env: at the first episode end after it (the env is borrowed and restored there).
    Several pairs: at once (their episodes never end together; they are cut and restarted).
    The collector decides (:meth:`~sumo_ayss.training.collectors.Collector.
    ready_for_candidate`). The candidate's resume checkpoint follows at the next rollout
    start (:meth:`Trainer.save_checkpoint`); the steps in between are recorded for its
    replay. Once the early-stopping rule has stopped the run (:attr:`Trainer.stopped`),
    it ends ``learn``. Every :data:`PROGRESS_EVERY_S` seconds it also rewrites
    ``progress.json``.
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
        trainer.record_actions(sb3_adapter.rollout_actions(self.locals))
        if self.num_timesteps < trainer.next_eval:
            return True
        if trainer.collector.ready_for_candidate(self.locals):
            trainer.candidate(rollout=self.locals)
        return trainer.stopped is None  # False ends ``learn``: the early-stopping rule
