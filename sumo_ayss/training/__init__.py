"""The training stage's work (:mod:`sumo_ayss.train` is its entry point), one concern each.

- :mod:`~sumo_ayss.training.trainer`: :func:`~sumo_ayss.training.trainer.train` and the
  :class:`~sumo_ayss.training.trainer.Trainer` that composes the pieces below.

- :mod:`~sumo_ayss.training.run_metadata`: what a run's metadata files hold (written by
  :mod:`sumo_ayss.run_folder`, like every run-folder file).
- :mod:`~sumo_ayss.training.checkpoint`: checkpoint serialisation, cleanup
  after a kill, and loading a checkpoint back.
- :mod:`~sumo_ayss.training.collectors`: the training env(s) behind one interface (one env,
  or N pairs in one simulation): candidate evaluation, the episode anchor, resume.
- :mod:`~sumo_ayss.training.callback`: the SB3 callback that schedules candidates.
"""
