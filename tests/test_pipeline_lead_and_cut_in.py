"""The two-POV case ``lead_and_cut_in`` end to end on real SUMO (issue 39): training, SPCP
selection, outcome, AYSS (Δv̄ of the primary POV), cross-play with its diagonal check and
the reference drivers, preventability labels, the report, the leaderboard, and the SUMO and
OpenSCENARIO exports with both POVs; a tiny budget (the machinery, not a result)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from sumo_ayss.commands.pipeline import run_pipeline
from sumo_ayss.commands.rank import main as rank_main
from sumo_ayss.config import PROJECT_ROOT
from sumo_ayss.pipeline import load_pipeline
from sumo_ayss.records.table import read_table
from sumo_ayss.replay.record import export_scenario
from sumo_ayss.replay.xosc import export_xosc
from sumo_ayss.run_folder import AYSS_SCHEMA, CROSSPLAY_SCHEMA, OUTCOME_SCHEMA
from tests.helpers import TINY_AGENT

pytestmark = pytest.mark.sumo


def test_lead_and_cut_in_pipeline_end_to_end(tmp_path: Path) -> None:
    exp = yaml.safe_load((PROJECT_ROOT / "configs" / "lead_and_cut_in.yaml").read_text())
    exp["agent"] = TINY_AGENT
    exp["train"].update(n_eval_scenarios=5, progress_bar=False)
    (tmp_path / "lci.yaml").write_text(yaml.safe_dump(exp))
    pipe = {
        "grid": {"cases": ["lead_and_cut_in"], "vuts": ["pi1", "pi2"], "seeds": [0]},
        "experiments": {"lead_and_cut_in": "lci.yaml"},
        "out": "runs",
        "total_timesteps": 600,
        "eval_every": 300,
        "evaluate": {"n_outcome": 12, "n_ayss": 2000},
        "workers": 1,
    }
    path = tmp_path / "pipe.yaml"
    path.write_text(yaml.safe_dump(pipe))
    statuses, report, *_ = run_pipeline(load_pipeline(path), live=False)
    assert all(s.state == "done" for s in statuses)
    case = tmp_path / "runs" / "lead_and_cut_in"
    run = case / "pi2" / "seed_0"
    assert json.loads((run / "spcp.json").read_text())["step"] > 0
    # AYSS: the case's own indicator, the lead as primary in the VUT's lane.
    ayss = read_table(run / "ayss.csv", AYSS_SCHEMA)
    assert len(ayss) > 0 and set(ayss["indicator_name"].tolist()) == {"delta_v_bar_primary_mps"}
    assert np.isfinite(ayss["indicator"]).all() and (ayss["h_m"] <= 5.0).all()
    # Cross-play: the diagonal cells replay each run's own outcome episodes exactly.
    record = json.loads((case / "crossplay.json").read_text())
    assert all(d["n_equal"] == d["n"] == 12 for d in record["diagonal"])
    ref = read_table(case / "crossplay_reference.csv", CROSSPLAY_SCHEMA)
    assert sorted(set(ref["vut"].tolist())) == ["cc_driver", "fsm", "rss"]
    for table in (
        read_table(case / "crossplay.csv", CROSSPLAY_SCHEMA),
        ref,
        *(read_table(case / v / "seed_0" / "outcome.csv", OUTCOME_SCHEMA) for v in ("pi1", "pi2")),
    ):
        label = table["crash_preventable"]
        assert np.isin(label[table["collided"]], [0.0, 1.0]).all()
        assert np.isnan(label[~table["collided"]]).all()
        assert (table["near_miss_pay"] >= 0).all()
    # Safety measures per POV: the primary's per episode in outcome.csv, the supporting
    # POV's summarised in outcome.json with the share of POV failures.
    support = json.loads((run / "outcome.json").read_text())["supporting_pov"]
    assert support["n"] == 12 and 0.0 <= support["pov_failure_rate"] <= 1.0
    assert {"min_ttc_s", "min_thw_s", "max_drac_mps2"} <= set(support["measures"])
    assert report is not None
    text = report.read_text(encoding="utf-8")
    assert "Two-lane lead and cut-in (two POVs): leaderboard (crossplay mode)" in text
    assert "Δv̄ (primary POV)" in text
    with pytest.raises(SystemExit) as done:
        rank_main([str(path), "--no-run", "--no-live"])
    assert done.value.code == 0
    ranking = (tmp_path / "runs" / "ranking.csv").read_text()
    assert "lead_and_cut_in,crossplay" in ranking.replace('"', "")
    # Both POVs in the exported scenario, in both formats, reproducing the row.
    sumo = export_scenario(run, tmp_path / "sumo", outcome_row=0)
    fcd = sumo.trajectory.read_text()
    assert all(f'id="{v}"' in fcd for v in ("vut", "pov", "pov2"))
    assert all(sumo.info["reproduces_row"].values())
    # An AYSS sample replays from the case's fixed supporting POV (PairEnv.ayss_start).
    sample = export_scenario(run, tmp_path / "ayss", ayss_row=0)
    assert sample.info["reproduces_row"] == {"action": True}
    start = sample.info["initial_condition"]
    assert (start["support_gap_m"], start["support_speed_mps"], start["primary"]) == (40, 20, 0)
    assert 'id="pov2"' in sample.trajectory.read_text()
    xo = export_xosc(run, tmp_path / "xosc", outcome_row=0)
    assert "pov2" in xo.info["bodies_m"] and 'name="pov2"' in xo.xosc.read_text()
    assert all(xo.info["reproduces_row"].values())
