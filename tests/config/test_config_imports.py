"""Reading a configuration stays light: no torch, libsumo, SB3, and no user code."""

from __future__ import annotations

from sumo_ayss.config import PROJECT_ROOT
from tests.helpers import loaded_among

HEAVY = ("torch", "libsumo", "traci", "stable_baselines3", "matplotlib")

SCRIPT = """
import json, sys
from pathlib import Path
import sumo_ayss.config as config
import sumo_ayss.agents.hparams
import sumo_ayss.config.report
root = Path(sys.argv[1])
pipe = config.load_pipeline(root / "configs" / "paper.yaml")
for case, path in pipe.experiments.items():
    config.load_experiment(path)
print(json.dumps(sorted({m.split(".")[0] for m in sys.modules})))
"""


def test_reading_configs_imports_no_heavy_module() -> None:
    """Parse the paper's pipeline and experiments in a fresh interpreter; list its imports."""
    bad = loaded_among(SCRIPT.replace("sys.argv[1]", repr(str(PROJECT_ROOT))), HEAVY)
    assert bad == [], bad
