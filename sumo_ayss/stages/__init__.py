"""What a stage has done and what it must (re)do: the resume logic above the stored files.

- :mod:`~sumo_ayss.stages.contract`: one contract for every stage: the fingerprint of the
  inputs asked for now against what its done marker records, and its outputs present
  (:func:`is_done`, a :class:`Stage` per stage).
- :mod:`~sumo_ayss.stages.crossplay_cells`: which cells of a recorded cross-play table a
  new request keeps, and which it must drive.

The markers and tables themselves are read and written by :mod:`sumo_ayss.run_folder`; a
run's identity (what the training stage's fingerprint is over) is
:mod:`sumo_ayss.config.identity`. Imports neither SUMO nor torch.
"""

from __future__ import annotations

from sumo_ayss.stages.contract import (
    AyssStage,
    CrossplayStage,
    DiscriminabilityStage,
    EvaluateStage,
    OutcomeStage,
    Stage,
    TrainStage,
    is_done,
)
from sumo_ayss.stages.crossplay_cells import CellPlan, merged_rows, plan_cells
from sumo_ayss.util.fingerprint import fingerprint

__all__ = [
    "AyssStage",
    "CellPlan",
    "CrossplayStage",
    "DiscriminabilityStage",
    "EvaluateStage",
    "OutcomeStage",
    "Stage",
    "TrainStage",
    "fingerprint",
    "is_done",
    "merged_rows",
    "plan_cells",
]
