"""Paths written into result files are relative to the repository where they can be."""

from __future__ import annotations

from pathlib import Path

from sumo_ayss.config import PROJECT_ROOT
from sumo_ayss.util.paths import portable_path


def test_paths_below_the_repository_become_relative() -> None:
    assert portable_path(PROJECT_ROOT / "runs" / "paper" / "cut_in") == "runs/paper/cut_in"


def test_paths_elsewhere_stay_as_given(tmp_path: Path) -> None:
    assert portable_path(tmp_path / "x") == (tmp_path / "x").as_posix()
    assert portable_path("a/../b", base=Path("/nonexistent")) == "a/../b"
