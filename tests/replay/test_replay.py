"""Replayable scenarios: exported SUMO files load in SUMO and replay the recording.

A tiny car-following run is trained and evaluated once (real SPCP, a few seconds); a cut-in
run folder is evaluated with a scripted policy (cut in whenever the POV is ahead in the
other lane), so that its AYSS table is never empty. Each test exports a scenario, replays it
headless with the ``sumo`` binary and compares the replayed trajectory with the recorded
one (positions within ``POSITION_TOL_M`` = 1 mm, speeds within ``SPEED_TOL_MPS`` =
1 mm/s), and with the env's own per-decision readings.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import pytest
import yaml

from sumo_ayss.config import AyssConfig, load_experiment
from sumo_ayss.evaluate import evaluate_run
from sumo_ayss.records.table import read_table
from sumo_ayss.replay import (
    POSITION_TOL_M,
    SPEED_TOL_MPS,
    export_scenario,
    main,
    replay_headless,
)
from sumo_ayss.run_folder import AYSS_SCHEMA, OUTCOME_SCHEMA
from sumo_ayss.sim.export import read_fcd
from sumo_ayss.train import train
from sumo_ayss.util.errors import ConfigError
from tests.helpers import tiny_experiment

pytestmark = pytest.mark.sumo

TINY = tiny_experiment()
#: Observation tolerance (the env's observations are float32) [m/s, m].
OBS_TOL = 1e-3


@pytest.fixture(scope="module")
def cf_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A trained (600 steps) and evaluated car-following run of pi1."""
    root = tmp_path_factory.mktemp("cf")
    (root / "tiny.yaml").write_text(yaml.safe_dump(TINY))
    run = train(load_experiment(root / "tiny.yaml").with_vut("pi1"), seed=0, out=root / "runs")
    evaluate_run(run, n_outcome=10, ayss=AyssConfig(n_samples=2000), progress=False)
    return run


def cut_in_policy(obs: npt.NDArray[np.float32]) -> npt.NDArray[np.int64]:
    """Lane change while in the other lane with the POV ahead, else target 15 m/s."""
    obs = np.asarray(obs)
    return np.where((obs[:, 3] == 0) & (obs[:, 2] > 0), 0, 16).astype(np.int64)


@pytest.fixture(scope="module")
def ci_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A cut-in run folder (config only) evaluated with :func:`cut_in_policy`."""
    run = tmp_path_factory.mktemp("ci")
    (run / "config.yaml").write_text(
        yaml.safe_dump({"env": {"case": "cut_in", "vut": "pi2"}, "seed": 3})
    )
    evaluate_run(
        run, n_outcome=4, ayss=AyssConfig(n_samples=300), progress=False, policy=cut_in_policy
    )
    return run


def check_replay(scenario: Path) -> dict[str, Any]:
    """Replay headless (through the CLI) and compare with the recording and the env."""
    assert main([str(scenario), "--headless"]) == 0
    check = replay_headless(scenario, scenario / "again.fcd.xml")
    assert check.ok and not check.missing
    assert check.max_position_error_m <= POSITION_TOL_M
    assert check.max_speed_error_mps <= SPEED_TOL_MPS
    info = json.loads((scenario / "scenario.json").read_text())
    dt = info["step_length_s"]
    assert info["decision_period_s"] == dt  # one SUMO step per decision in these runs
    replayed = {(round(p.time_s, 6), p.vehicle): p for p in read_fcd(scenario / "replayed.fcd.xml")}
    assert check.n_points == 2 * (len(info["decisions"]) + 1)
    # tau = 0 is the row's initial condition; decision k ends at tau = (k + 1)·dt.
    ic = info["initial_condition"]
    expected = [(ic["pov_speed_mps"], ic["vut_speed_mps"], ic["gap_m"])]
    expected += [
        (d["pov_speed_mps"], d["vut_speed_mps"], d["headway_m"]) for d in info["decisions"]
    ]
    for k, (v_pov, v_vut, h) in enumerate(expected):
        t = round((k + 1) * dt, 6)
        pov, vut = replayed[(t, "pov")], replayed[(t, "vut")]
        assert pov.speed_mps == pytest.approx(v_pov, abs=OBS_TOL)
        assert vut.speed_mps == pytest.approx(v_vut, abs=OBS_TOL)
        assert pov.pos_m - 5.0 - vut.pos_m == pytest.approx(h, abs=OBS_TOL)
    return info


def test_ayss_sample_replays(cf_run: Path, tmp_path: Path) -> None:
    out = tmp_path / "ayss0"
    assert main(["export", str(cf_run), "--ayss-row", "0", "--out", str(out)]) == 0
    for name in (
        "network.net.xml",
        "vtypes.add.xml",
        "trajectory.fcd.xml",
        "scenario.sumocfg",
        "README.md",
    ):
        assert (out / name).is_file(), name
    vtypes = (out / "vtypes.add.xml").read_text()
    assert 'id="vut_pi1"' in vtypes and 'minGap="5"' in vtypes and 'id="pov"' in vtypes
    info = check_replay(out)
    row = next(read_table(cf_run / "ayss.csv", AYSS_SCHEMA).rows())
    assert info["reproduces_row"] == {"action": True}
    assert info["decisions"][0]["action"] == row["action"]
    assert len(info["decisions"]) == 1  # the AYSS scenario is d = 1 decision
    assert info["initial_condition"]["gap_m"] == pytest.approx(row["h_m"])


def test_outcome_episode_replays_and_reproduces_its_row(cf_run: Path, tmp_path: Path) -> None:
    result = export_scenario(cf_run, tmp_path / "ep", outcome_row=3)
    info = check_replay(result.out)
    row = list(read_table(cf_run / "outcome.csv", OUTCOME_SCHEMA).rows())[3]
    assert info["reproduces_row"] == {"episode_return": True, "collided": True, "n_steps": True}
    assert len(info["decisions"]) == row["n_steps"] and info["episode_ended"]


def test_cut_in_replay_moves_the_pov_sideways(ci_run: Path, tmp_path: Path) -> None:
    result = export_scenario(ci_run, tmp_path / "ci", ayss_row=0, decisions=8, policy=cut_in_policy)
    info = check_replay(result.out)
    assert info["decisions"][0]["action"] == 0 and info["reproduces_row"]["action"]
    ys = [p.y_m for p in read_fcd(result.out / "replayed.fcd.xml") if p.vehicle == "pov"]
    lanes = {p.lane for p in read_fcd(result.out / "replayed.fcd.xml") if p.vehicle == "pov"}
    # Lane 1 centre y = -1.6 m, lane 0 centre y = -4.8 m: intermediate y = continuous motion.
    assert any(-4.7 < y < -1.7 for y in ys) and {"road_0", "road_1"} <= lanes


def test_gui_without_display_says_so(
    ci_run: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    out = export_scenario(ci_run, tmp_path / "gui", outcome_row=0, policy=cut_in_policy).out
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    assert main([str(out)]) == 2
    err = capsys.readouterr().err
    assert "no display" in err and "--headless" in err and "sumo-gui -c scenario.sumocfg" in err


def test_export_refuses_bad_selections(ci_run: Path, tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="exactly one of"):
        export_scenario(ci_run, tmp_path / "x", policy=cut_in_policy)
    with pytest.raises(ConfigError, match="exactly one of"):
        export_scenario(ci_run, tmp_path / "x", ayss_row=0, outcome_row=0, policy=cut_in_policy)
    with pytest.raises(ConfigError, match=r"--outcome-row must be an integer in \[0, 3\]"):
        export_scenario(ci_run, tmp_path / "x", outcome_row=4, policy=cut_in_policy)
    with pytest.raises(ConfigError, match="decisions must be an integer >= 1"):
        export_scenario(ci_run, tmp_path / "x", outcome_row=0, decisions=0, policy=cut_in_policy)
    assert main([str(tmp_path), "--headless"]) == 2  # not a scenario folder
