"""The study folder's files: one writer and one reader each, the bytes of the former
writers kept, bad files refused naming the file and the field."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from sumo_ayss.run_folder import (
    CaseFolder,
    OrderCheck,
    OrderChecks,
    StudyFolder,
    read_discriminability_json,
    write_discriminability,
    write_measures_csv,
    write_order_check,
    write_pipeline_json,
    write_ranking_csv,
)
from sumo_ayss.run_folder.study import (
    MEASURES_COLUMNS,
    RANKING_COLUMNS,
    read_measures_csv,
    read_order_check,
    read_pipeline_json,
    read_ranking_csv,
)
from sumo_ayss.util.errors import TableError

ROOT = Path(__file__).resolve().parents[2]


def _row(**cells: object) -> dict[str, object]:
    return {c: cells.get(c, "") for c in RANKING_COLUMNS}


def test_study_folder_names_every_file(tmp_path: Path) -> None:
    study = StudyFolder(tmp_path)
    names = [
        study.pipeline_json,
        study.ranking_csv,
        study.ranking_md,
        study.order_check_json,
        study.measures_csv,
        study.report_dir,
    ]
    assert [p.name for p in names] == [
        "pipeline.json",
        "ranking.csv",
        "ranking.md",
        "order_check.json",
        "measures.csv",
        "report",
    ]
    assert study.case("cut_in") == CaseFolder(tmp_path / "cut_in")


def test_ranking_csv_round_trips_every_digit(tmp_path: Path) -> None:
    path = StudyFolder(tmp_path).ranking_csv
    p = 0.0004955974822250476
    rows = [
        _row(case="cut_in", mode="crossplay", rank=1, vut="pi2", score=0.1 + 0.2, p_vs_next=p,
             significant_vs_next=True, vs_next="pi2 is safer, p < 0.001", timid=False),
        _row(case="cut_in", mode="crossplay", rank=2, vut="pi1", score=math.nan),
    ]  # fmt: skip
    write_ranking_csv(path, rows)
    back = read_ranking_csv(path)
    assert back[0]["score"] == "0.30000000000000004" and back[0]["p_vs_next"] == repr(p)
    assert back[0]["significant_vs_next"] == "True" and back[0]["timid"] == "False"
    assert back[0]["vs_next"] == "pi2 is safer, p < 0.001" and back[1]["score"] == "nan"
    write_ranking_csv(path, back)  # a script writing the rows back changes nothing
    assert read_ranking_csv(path) == back
    with pytest.raises(ValueError, match=r"ranking\.csv: rows hold columns it does not have"):
        write_ranking_csv(path, [{**rows[0], "extra": 1}])


def test_ranking_csv_of_older_studies_and_broken_files(tmp_path: Path) -> None:
    legacy = ROOT / "results" / "sensitivity_actuator" / "ranking.csv"  # before crash columns
    rows = read_ranking_csv(legacy)
    assert rows and rows[0]["vut"] == "pi2" and rows[0]["crash_rate"] == rows[0]["timid"] == ""
    path = tmp_path / "ranking.csv"
    path.write_text("case,mode,rank\ncut_in,crossplay,1\n")
    with pytest.raises(TableError, match=r"ranking\.csv: missing column\(s\) \['vut'"):
        read_ranking_csv(path)
    path.write_text(",".join(RANKING_COLUMNS) + "\ncut_in,crossplay\n")
    with pytest.raises(TableError, match=r"ranking\.csv: row 0 has 2 cells, header has 23"):
        read_ranking_csv(path)
    with pytest.raises(TableError, match=r"missing\.csv: table file not found"):
        read_ranking_csv(tmp_path / "missing.csv")


def test_order_check_round_trips_and_keeps_the_former_text(tmp_path: Path) -> None:
    check = OrderCheck(
        case="car_following",
        mode="crossplay",
        order=("b", "a"),
        expected=("a", "b"),
        tau=-1.0,
        ends_significant=False,
        ends_p=0.25,
        significant_adjacent=0,
        adjacent=1,
    )
    path = StudyFolder(tmp_path).order_check_json
    write_order_check(path, OrderChecks(("a", "b"), (check,)))
    assert read_order_check(path) == OrderChecks(("a", "b"), (check,))
    assert path.read_text() == (  # rank's former json.dumps(indent=2, sort_keys=True)
        '{\n  "cases": [\n    {\n      "adjacent": 1,\n      "case": "car_following",\n'
        '      "ends_p": 0.25,\n      "ends_significant": false,\n      "expected": [\n'
        '        "a",\n        "b"\n      ],\n      "mode": "crossplay",\n      "order": [\n'
        '        "b",\n        "a"\n      ],\n      "significant_adjacent": 0,\n'
        '      "tau": -1.0\n    }\n  ],\n  "expected": [\n    "a",\n    "b"\n  ]\n}\n'
    )
    committed = read_order_check(ROOT / "results" / "ladders" / "min_gap_a" / "order_check.json")
    assert committed.expected == ("gap15", "gap10", "gap5", "gap2") and committed.cases
    path.write_text('{"expected": ["a"], "cases": [{"case": "x", "mode": "crossplay"}]}')
    with pytest.raises(TableError, match=r"order_check\.json: cases\[0\]: missing field 'order'"):
        read_order_check(path)
    path.write_text('{"expected": "a", "cases": []}')
    with pytest.raises(TableError, match=r"order_check\.json: expected: expected a list"):
        read_order_check(path)


def test_measures_csv_and_pipeline_json_round_trip(tmp_path: Path) -> None:
    study = StudyFolder(tmp_path)
    row = {c: "" for c in MEASURES_COLUMNS} | {"case": "cut_in", "median": 1.25, "n": 3}
    write_measures_csv(study.measures_csv, [row])
    back = read_measures_csv(study.measures_csv)
    assert back == [{c: str(v) for c, v in row.items()}]
    write_pipeline_json(study.pipeline_json, {"out": ".", "grid": {"seeds": [0, 1]}})
    assert read_pipeline_json(study.pipeline_json) == {"out": ".", "grid": {"seeds": [0, 1]}}
    study.pipeline_json.write_text("[1]")
    with pytest.raises(TableError, match=r"pipeline\.json: expected a JSON object"):
        read_pipeline_json(study.pipeline_json)


def test_discriminability_files_round_trip(tmp_path: Path) -> None:
    record = {
        "case": "car_following",
        "vuts": ["pi1", "pi2"],
        "fingerprint": "0123456789abcdef",
        "h_edges_m": [0.0, 2.5, 5.0],
        "v_edges_mps": [0.0, 30.0],
        "mean_response_mps2": {"pi1": -1.0, "pi2": -1.5},
        "pairs": [
            {"a": "pi1", "b": "pi2", "share": 0.25, "share_by_h": [0.0, 0.5],
             "share_by_v_vut": [0.25], "share_by_v_pov": [None]},
        ],
    }  # fmt: skip
    folder = CaseFolder(tmp_path / "car_following")
    paths = write_discriminability(folder, record)
    assert paths == [folder.discriminability_json, folder.discriminability_csv]
    assert read_discriminability_json(folder.discriminability_json) == record
    assert folder.discriminability_csv.read_text().splitlines() == [
        "pair,dimension,bin_low,bin_high,share",
        "pi1 vs pi2,all,,,0.25",
        "pi1 vs pi2,h_m,0.0,2.5,0.0",
        "pi1 vs pi2,h_m,2.5,5.0,0.5",
        "pi1 vs pi2,v_vut_mps,0.0,30.0,0.25",
        "pi1 vs pi2,v_pov_mps,0.0,30.0,",
    ]
    folder.discriminability_json.write_text('{"vuts": []}')
    with pytest.raises(TableError, match=r"discriminability\.json: missing fields \['pairs'"):
        read_discriminability_json(folder.discriminability_json)
