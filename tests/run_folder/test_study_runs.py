"""A study's runs as read: pooling checks and typed results (run_folder/study_runs.py)."""

from __future__ import annotations

import typing

from sumo_ayss.analysis.crossplay import CrossplayInput, CrossplayMatrix
from sumo_ayss.analysis.crossplay_scoring import case_matrix
from sumo_ayss.run_folder import study_runs
from sumo_ayss.run_folder.crossplay import CrossplayTables
from sumo_ayss.run_folder.study_runs import mixing_problems
from sumo_ayss.training.trust import Training


def test_the_study_readers_return_typed_records_not_any() -> None:
    names = {"CrossplayMatrix": CrossplayMatrix, "CrossplayInput": CrossplayInput}
    assert typing.get_type_hints(case_matrix, localns=names)["return"] is CrossplayMatrix
    hints = typing.get_type_hints(study_runs.CaseRuns, localns=names)
    assert hints["crossplay"] is CrossplayTables  # stored data: the analysis scores it
    for name in study_runs.__all__:
        obj = getattr(study_runs, name)
        if callable(obj) and not isinstance(obj, type):
            assert typing.get_type_hints(obj, localns=names)["return"] is not typing.Any, name


def test_runs_that_must_not_be_pooled_are_named() -> None:
    t = Training(total_timesteps=1000, eval_every=500, config_key="k")
    ok = [("car_following", v, s, f"{v}/{s}", t) for v in ("pi1", "pi2") for s in (0, 1)]
    assert mixing_problems(ok) == []
    twice = [*ok, ("car_following", "pi1", 0, "elsewhere/pi1/0", t)]
    assert mixing_problems(twice) == [
        "car_following pi1 seed 0 appears 2 times: pi1/0, elsewhere/pi1/0"
    ]
    other = Training(total_timesteps=2000, eval_every=500, config_key="k")
    budgets = mixing_problems([*ok, ("car_following", "pi3", 0, "pi3/0", other)])
    assert len(budgets) == 1 and "different training budgets" in budgets[0]
