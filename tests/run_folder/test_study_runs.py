"""A study's runs as read: typed results (run_folder/study_runs.py; the pooling check is
training/trust.py's, tests/training/test_trust.py)."""

from __future__ import annotations

import typing

from sumo_ayss.analysis.crossplay import CrossplayInput, CrossplayMatrix
from sumo_ayss.analysis.crossplay_scoring import case_matrix
from sumo_ayss.run_folder import study_runs
from sumo_ayss.run_folder.crossplay import CrossplayTables


def test_the_study_readers_return_typed_records_not_any() -> None:
    names = {"CrossplayMatrix": CrossplayMatrix, "CrossplayInput": CrossplayInput}
    assert typing.get_type_hints(case_matrix, localns=names)["return"] is CrossplayMatrix
    hints = typing.get_type_hints(study_runs.CaseRuns, localns=names)
    assert hints["crossplay"] is CrossplayTables  # stored data: the analysis scores it
    for name in study_runs.__all__:
        obj = getattr(study_runs, name)
        if callable(obj) and not isinstance(obj, type):
            assert typing.get_type_hints(obj, localns=names)["return"] is not typing.Any, name
