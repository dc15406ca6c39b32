"""The follower (issue 33) in a replayed episode: SUMO files and OpenSCENARIO (real SUMO)."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import numpy.typing as npt
import pytest
import yaml

from sumo_ayss.config import AyssConfig
from sumo_ayss.evaluate import evaluate_run
from sumo_ayss.records.table import read_table
from sumo_ayss.replay import export_scenario, replay_headless
from sumo_ayss.replay.xosc import XOSC_FILE, export_xosc
from sumo_ayss.run_folder import OUTCOME_SCHEMA
from sumo_ayss.sim.export import read_fcd

pytestmark = pytest.mark.sumo


def braking_policy(obs: npt.NDArray[np.float32]) -> npt.NDArray[np.int64]:
    """The POV brakes (target 0.5·v) while more than 5 m ahead, else holds its speed."""
    return np.where(np.asarray(obs)[:, 2] > 5.0, 1, 2).astype(np.int64)


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("fol")
    env = {"case": "car_following", "vut": "pi1", "follower": {"enabled": True}}
    (folder / "config.yaml").write_text(yaml.safe_dump({"env": env, "seed": 3}))
    evaluate_run(
        folder, n_outcome=3, ayss=AyssConfig(n_samples=200), progress=False, policy=braking_policy
    )
    return folder


def test_the_outcome_table_records_the_hazards(run: Path) -> None:
    t = read_table(run / "outcome.csv", OUTCOME_SCHEMA)
    assert np.isfinite(t["follower_max_braking_mps2"]).all()
    assert set(t["rear_end"].tolist()) <= {0.0, 1.0}
    assert np.isfinite(t["unjustified_dv_mps"]).all()


def test_the_sumo_replay_carries_the_follower(run: Path, tmp_path: Path) -> None:
    out = tmp_path / "sc"
    export_scenario(run, out, outcome_row=1, policy=braking_policy)
    vehicles = {p.vehicle for p in read_fcd(out / "trajectory.fcd.xml")}
    assert vehicles == {"vut", "pov", "follower"}
    assert 'id="follower"' in (out / "vtypes.add.xml").read_text()
    info = json.loads((out / "scenario.json").read_text())
    assert info["initial_condition"]["follower_gap_m"] > 0
    assert all(info["reproduces_row"].values())
    check = replay_headless(out, out / "again.fcd.xml")
    assert check.ok and not check.missing


def test_the_openscenario_export_carries_the_follower(run: Path, tmp_path: Path) -> None:
    export_xosc(run, tmp_path, outcome_row=1, policy=braking_policy)
    doc = ET.parse(tmp_path / XOSC_FILE).getroot()
    names = {o.get("name") for o in doc.iter("ScenarioObject")}
    assert names == {"ego", "pov", "follower"}
