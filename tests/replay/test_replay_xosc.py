"""OpenSCENARIO export (issue 27): the files validate against ASAM's schema and hold the
recorded episode (real SUMO; the run folders are evaluated with scripted policies)."""

from __future__ import annotations

import json
import subprocess
import sys
import xml.etree.ElementTree as ET
from importlib.resources import files
from pathlib import Path

import numpy as np
import numpy.typing as npt
import pytest
import yaml
from lxml import etree

from sumo_ayss.config import AyssConfig, load_experiment
from sumo_ayss.evaluate import evaluate_run
from sumo_ayss.records.table import read_table
from sumo_ayss.replay import main
from sumo_ayss.replay.xosc import OVERHANG_M, XODR_FILE, XOSC_FILE, export_xosc
from sumo_ayss.run_folder import OUTCOME_SCHEMA
from sumo_ayss.train import train
from tests.helpers import tiny_experiment

pytestmark = pytest.mark.sumo

#: ASAM's OpenSCENARIO 1.2 XSD, as shipped with ASAM's checker (asam-qc-openscenarioxml).
XSD = files("qc_openscenario") / "schema" / "1.2.0" / "OpenSCENARIO.xsd"


def schema() -> etree.XMLSchema:
    return etree.XMLSchema(etree.parse(str(XSD)))


def cut_in_policy(obs: npt.NDArray[np.float32]) -> npt.NDArray[np.int64]:
    """Lane change while in the other lane with the POV ahead, else target 15 m/s."""
    obs = np.asarray(obs)
    return np.where((obs[:, 3] == 0) & (obs[:, 2] > 0), 0, 16).astype(np.int64)


def _run(root: Path, case: str, policy) -> Path:
    root.mkdir(parents=True, exist_ok=True)
    (root / "config.yaml").write_text(
        yaml.safe_dump({"env": {"case": case, "vut": "pi1"}, "seed": 3})
    )
    evaluate_run(root, n_outcome=4, ayss=AyssConfig(n_samples=300), progress=False, policy=policy)
    return root


@pytest.fixture(scope="module")
def ci_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return _run(tmp_path_factory.mktemp("ci") / "run", "cut_in", cut_in_policy)


def _trajectory(doc: ET.Element, entity: str) -> tuple[list[float], list[float], list[float]]:
    group = next(
        g for g in doc.iter("ManeuverGroup") if g.find(".//EntityRef").get("entityRef") == entity
    )
    vertices = group.findall(".//Polyline/Vertex")
    t = [float(v.get("time")) for v in vertices]
    x = [float(v.find(".//WorldPosition").get("x")) for v in vertices]
    y = [float(v.find(".//WorldPosition").get("y")) for v in vertices]
    return t, x, y


def test_a_cut_in_episode_validates_and_holds_the_lane_change(ci_run: Path, tmp_path: Path) -> None:
    table = read_table(ci_run / "outcome.csv", OUTCOME_SCHEMA)
    row = int(np.flatnonzero(table["lane_changed"])[0])
    result = export_xosc(ci_run, tmp_path / "x", outcome_row=row, policy=cut_in_policy)
    assert schema().validate(etree.parse(str(result.xosc))), schema().error_log
    assert result.info["reproduces_row"] == {
        "episode_return": True,
        "collided": True,
        "n_steps": True,
    }
    doc = ET.parse(result.xosc).getroot()
    assert doc.find("RoadNetwork/LogicFile").get("filepath") == XODR_FILE
    t, x, y = _trajectory(doc, "pov")
    n = int(table["n_steps"][row])
    np.testing.assert_allclose(t, np.arange(n + 1) * 0.2)
    # the POV starts centred in the left lane (y = -1.6) and moves towards the VUT's (-4.8)
    assert y[0] == pytest.approx(-1.6) and min(y) < -1.6 - 0.5
    _, x_ego, y_ego = _trajectory(doc, "ego")
    assert set(y_ego) == {-4.8}
    # the initial gap of the row: POV rear - VUT front from the rear-axle positions
    gap0 = (x[0] - OVERHANG_M + 5.0) - 5.0 - (x_ego[0] - OVERHANG_M + 5.0)
    assert gap0 == pytest.approx(table["gap0_m"][row], abs=1e-3)
    road = ET.parse(result.xodr).getroot()
    right = road.findall(".//laneSection/right/lane")
    assert sorted(int(ln.get("id")) for ln in right) == [-2, -1]
    assert {float(ln.find("width").get("a")) for ln in right} == {3.2}


def test_a_trained_spcp_episode_through_the_cli(tmp_path: Path) -> None:
    """A real (tiny) SPCP's car-following outcome episode, exported by the CLI."""
    (tmp_path / "tiny.yaml").write_text(yaml.safe_dump(tiny_experiment()))
    exp = load_experiment(tmp_path / "tiny.yaml").with_vut("pi1")
    run = train(exp, seed=0, out=tmp_path / "runs")
    evaluate_run(run, n_outcome=3, ayss=AyssConfig(n_samples=200), progress=False)
    out = tmp_path / "x"
    assert (
        main(["export", str(run), "--outcome-row", "2", "--format", "xosc", "--out", str(out)]) == 0
    )
    assert schema().validate(etree.parse(str(out / XOSC_FILE))), schema().error_log
    _, _, y = _trajectory(ET.parse(out / XOSC_FILE).getroot(), "ego")
    assert set(y) == {-1.6}  # the one lane's centre
    info = json.loads((out / "xosc.json").read_text())
    assert all(info["reproduces_row"].values())


def test_the_schema_check_can_fail(ci_run: Path, tmp_path: Path) -> None:
    result = export_xosc(ci_run, tmp_path / "x", outcome_row=0, policy=cut_in_policy)
    doc = etree.parse(str(result.xosc))
    doc.getroot().remove(doc.getroot().find("FileHeader"))
    assert not schema().validate(doc)


def test_an_ayss_sample_is_one_decision(ci_run: Path, tmp_path: Path) -> None:
    result = export_xosc(ci_run, tmp_path / "a", ayss_row=0, policy=cut_in_policy)
    assert schema().validate(etree.parse(str(result.xosc)))
    assert result.info["decisions"] == 1 and result.info["reproduces_row"] == {"action": True}
    t, _, _ = _trajectory(ET.parse(result.xosc).getroot(), "pov")
    assert t == [0.0, 0.2]


def test_asams_checker_finds_no_issue(ci_run: Path, tmp_path: Path) -> None:
    """ASAM's OpenSCENARIO XML checker (schema, references, data types...): every check
    completes without an issue."""
    result = export_xosc(ci_run, tmp_path / "x", outcome_row=0, policy=cut_in_policy)
    report = tmp_path / "report.xqar"
    config = tmp_path / "qc.xml"
    config.write_text(
        '<?xml version="1.0" encoding="UTF-8"?>\n<Config>\n'
        f'  <Param name="InputFile" value="{result.xosc}"/>\n'
        '  <CheckerBundle application="xoscBundle">\n'
        f'    <Param name="resultFile" value="{report}"/>\n'
        "  </CheckerBundle>\n</Config>\n"
    )
    subprocess.run(
        [sys.executable, "-m", "qc_openscenario", "-c", str(config)],
        check=True,
        capture_output=True,
        timeout=120,
    )
    checkers = list(ET.parse(report).getroot().iter("Checker"))
    assert len(checkers) > 10  # the schema check and the reference and data-type checks
    assert {c.get("status") for c in checkers} == {"completed"}
    assert [i.get("description") for c in checkers for i in c.iter("Issue")] == []
