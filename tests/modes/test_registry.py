"""The ranking-mode registry: the built-in modes, lookups, and a mode added as a plug-in."""

from __future__ import annotations

import dataclasses
import subprocess
import sys

import pytest

from sumo_ayss.config.report import DEFAULT_MODE as CONFIG_DEFAULT_MODE
from sumo_ayss.config.report import ReportOptions
from sumo_ayss.modes import (
    CROSSPLAY,
    DEFAULT_MODE,
    EXPOSURE,
    PAPER,
    Mode,
    check_mode,
    get_mode,
    mode_names,
    register_mode,
    unregister_mode,
)
from sumo_ayss.modes.exposure import ExposureMode
from sumo_ayss.rank import analyse, ranking_rows
from sumo_ayss.util.errors import ConfigError
from tests.report.test_report import make_run


def test_built_in_modes_in_registry_order_with_the_default_first() -> None:
    assert mode_names()[:3] == ("crossplay", "exposure", "paper")
    assert DEFAULT_MODE == CROSSPLAY.name == ReportOptions().mode == CONFIG_DEFAULT_MODE
    assert get_mode("paper") is PAPER
    assert CROSSPLAY.runs_crossplay and not EXPOSURE.runs_crossplay
    assert PAPER.needs_safety_index and not CROSSPLAY.needs_safety_index


def test_an_unknown_mode_is_refused_with_the_registered_ones_named() -> None:
    with pytest.raises(ConfigError, match=r"unknown mode 'exposur'.*'exposure'"):
        get_mode("exposur")
    with pytest.raises(ConfigError, match=r"report\.mode must be one of .*'exposure'"):
        check_mode("nonsense")
    with pytest.raises(ConfigError, match=r"report\.mode must be a mode's name"):
        ReportOptions(mode="Not a name")
    assert ReportOptions(mode="nonsense").mode == "nonsense"  # the stages check the registry


def test_a_mode_is_an_object_without_callable_fields() -> None:
    """Its behaviour is methods; its fields are data (no callables, no lambdas)."""
    for mode in (CROSSPLAY, EXPOSURE, PAPER):
        assert isinstance(mode, Mode)
        assert not any(callable(getattr(mode, f.name)) for f in dataclasses.fields(mode))
    with pytest.raises(TypeError, match="abstract"):
        Mode(name="x", description="", score_name="", interval_name="", digits=1)  # type: ignore[abstract]


def test_registering_another_record_under_a_taken_name_needs_replace() -> None:
    with pytest.raises(ConfigError, match="already registered"):
        register_mode(dataclasses.replace(EXPOSURE, digits=4))
    assert register_mode(EXPOSURE) is EXPOSURE  # the same record again: a no-op


def test_a_new_mode_is_one_record_that_config_and_rank_pick_up(tmp_path) -> None:
    """A mode registered at run time (here: exposure's ranking under another name and
    unit) is accepted by ``report.mode``, heads the ranking and tags its rows."""

    @dataclasses.dataclass(frozen=True)
    class OwnHarm(ExposureMode):
        def unit(self, a: object) -> str:
            return "harm (plug-in)"

    fields = {f.name: getattr(EXPOSURE, f.name) for f in dataclasses.fields(EXPOSURE)}
    mode = OwnHarm(**{**fields, "name": "own_harm"})
    register_mode(mode)
    try:
        dirs = [make_run(tmp_path, "car_following", v, s) for v in ("pi1", "pi2") for s in (0, 1)]
        rows = ranking_rows(analyse(dirs, ReportOptions(mode="own_harm", n_boot=50)))
        assert [r["mode"] for r in rows] == ["own_harm"] * 2 + ["exposure"] * 2
        assert {r["unit"] for r in rows[:2]} == {"harm (plug-in)"}
        assert [r["vut"] for r in rows[:2]] == [r["vut"] for r in rows[2:]]
    finally:
        unregister_mode("own_harm")
    assert "own_harm" not in mode_names()


def test_the_case_analysis_holds_the_cases_data_and_one_result_per_mode(tmp_path) -> None:
    """No field of :class:`CaseAnalysis` is one mode's: each built-in mode keeps its own
    result (its own type, in ``modes/``) under its name in ``results``."""
    from sumo_ayss.analysis.case import CaseAnalysis
    from sumo_ayss.modes.crossplay import CrossplayResult, crossplay_result
    from sumo_ayss.modes.exposure import ExposureResult
    from sumo_ayss.modes.paper import PaperResult

    names = {f.name for f in dataclasses.fields(CaseAnalysis)}
    assert names == {
        *("case", "info", "runs", "options", "tables", "bootstrap"),  # the case's data
        *("verdict", "problems", "mode", "results"),
    }
    assert not any(n.startswith(m) for n in names for m in mode_names())
    dirs = [make_run(tmp_path, "car_following", v, s) for v in ("pi1", "pi2") for s in (0, 1)]
    (a,) = analyse(dirs, ReportOptions(mode="exposure", n_boot=50))
    assert list(a.results) == list(mode_names())
    kinds = {"crossplay": CrossplayResult, "exposure": ExposureResult, "paper": PaperResult}
    assert all(isinstance(a.results[name], kind) for name, kind in kinds.items())
    assert crossplay_result(a).gap is not None  # no cross-play table handed in
    a.results.pop("crossplay")
    with pytest.raises(ConfigError, match="no crossplay-mode result"):
        crossplay_result(a)


def test_the_registry_loads_without_the_analysis() -> None:
    """The configuration validates ``report.mode`` here: importing it stays light (the
    hooks import the analysis, and scipy with it, when called)."""
    code = (
        "import sys, sumo_ayss.modes; "
        "print(sorted(m for m in ('scipy', 'sumo_ayss.analysis') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_the_pipeline_refuses_an_unknown_mode_before_any_job(tmp_path) -> None:
    """The configuration imports no mode; the pipeline checks ``report.mode`` first."""
    from sumo_ayss.commands.pipeline import run_pipeline
    from sumo_ayss.config import load_pipeline

    cfg = load_pipeline("configs/ladders/min_gap.yaml", out=tmp_path / "study")
    bad = dataclasses.replace(cfg, report=dataclasses.replace(cfg.report, mode="exposur"))
    with pytest.raises(ConfigError, match=r"report\.mode must be one of .*did you mean 'exposure'"):
        run_pipeline(bad, live=False)
    assert not (tmp_path / "study").exists()
