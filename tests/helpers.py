"""Shared test data: a tiny learner, for tests of the machinery rather than of learning."""

from __future__ import annotations

import json
import subprocess
import sys
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


def modules_loaded_by(code: str) -> set[str]:
    """Every module in ``sys.modules`` after running ``code`` in a fresh interpreter."""
    script = f"{code}\nimport json, sys\nprint(json.dumps(sorted(sys.modules)))"
    out = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, check=True, timeout=120
    )
    return set(json.loads(out.stdout.strip().splitlines()[-1]))


def loaded_among(code: str, forbidden: tuple[str, ...] | set[str]) -> list[str]:
    """The ``forbidden`` modules (exact names, or any submodule of a top-level name) that
    ``code`` loads in a fresh interpreter."""
    loaded = modules_loaded_by(code)
    return sorted(m for m in loaded if m in forbidden or m.split(".")[0] in forbidden)
