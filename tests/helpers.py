"""Shared test data: a tiny learner, for tests of the machinery rather than of learning."""

from __future__ import annotations

from typing import Any

#: Small nets that learn fast enough for a few hundred steps.
TINY_AGENT: dict[str, Any] = {
    "feature_net_arch": [32],
    "value_net_arch": [32],
    "advantage_net_arch": [32],
    "learning_starts": 100,
    "buffer_size": 5000,
    "learning_rate": 1e-3,
}

#: 600 steps, a candidate every 200, evaluated on 10 scenarios.
TINY_TRAIN: dict[str, Any] = {
    "n_eval_scenarios": 10,
    "progress_bar": False,
    "total_timesteps": 600,
    "eval_every": 200,
}


def tiny_experiment() -> dict[str, Any]:
    """A fresh experiment mapping (``agent`` + ``train``) with the tiny learner."""
    return {"agent": dict(TINY_AGENT), "train": dict(TINY_TRAIN)}
