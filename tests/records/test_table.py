"""Table schemas, atomic CSV/JSON writers and the validating reader (no SUMO)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from sumo_ayss.analysis.hazards import HAZARD_NAMES
from sumo_ayss.analysis.safety_measures import MEASURE_NAMES
from sumo_ayss.records.jsonio import read_json, write_json
from sumo_ayss.records.table import Table, read_table, schema_markdown, table_from_rows, write_table
from sumo_ayss.run_folder import AYSS_SCHEMA, OUTCOME_SCHEMA
from sumo_ayss.util.errors import AyssError, TableError


def outcome_rows() -> list[dict[str, object]]:
    return [
        {
            "scenario": i,
            "v_pov0_mps": 20.0 + i,
            "v_vut0_mps": 25.5,
            "gap0_m": 0.1 * (i + 1),
            "episode_return": -10.0 if i == 1 else 12.345678901234567,
            "collided": i == 1,
            "lane_changed": False,
            "final_headway_m": -0.3 if i == 1 else 1.7,
            "n_steps": 7 if i == 1 else 25,
            "near_miss_pay": 3.25 if i == 1 else 12.345678901234567,
            "vut_mean_speed_mps": 1.0 / 3.0 + i,
            **_measures(i),
            "crash_preventable": 1.0 if i == 1 else 0.0,
            **{name: 0.5 + i for name in HAZARD_NAMES},
            "follower_min_ttc_s": math.inf if i == 2 else 3.0,
        }
        for i in range(3)
    ]


def _measures(i: int) -> dict[str, float]:
    """Safety-measure columns, an infinite TTC among them (NaN: see the AYSS table)."""
    values = {name: 1.0 / 7.0 + i for name in MEASURE_NAMES}
    return {**values, "min_ttc_s": math.inf if i == 0 else 2.5}


def ayss_table() -> Table:
    return Table(
        AYSS_SCHEMA,
        {
            "sample": [0, 4],
            "v_pov_mps": [20.0, 1.0 / 3.0],
            "v_vut_mps": [10.0, 30.0],
            "h_m": [1.5, 4.999],
            "same_lane": [0, 0],
            "action": [0, 0],
            "target_speed_mps": [20.0, 1.0 / 3.0],
            "ttc_s": [math.inf, 0.1690],
            "indicator_name": ["delta_v_bar_mps", "delta_v_bar_mps"],
            "indicator": [3.2, -29.0],
            "h_after_m": [3.4, math.nan],
            "delta_v_bar_before_mps": [4.0, -28.7],
        },
    )


def test_schemas_document_every_column() -> None:
    for schema in (OUTCOME_SCHEMA, AYSS_SCHEMA):
        text = schema_markdown(schema)
        for col in schema.columns:
            assert f"`{col.name}`" in text
            assert col.unit and col.meaning
    assert "inf allowed" in schema_markdown(AYSS_SCHEMA)  # ttc_s


def test_round_trip_is_exact(tmp_path: Path) -> None:
    outcome = table_from_rows(OUTCOME_SCHEMA, outcome_rows())
    write_table(tmp_path / "outcome.csv", outcome)
    back = read_table(tmp_path / "outcome.csv", OUTCOME_SCHEMA)
    assert back.equals(outcome)
    assert list(back.rows()) == outcome_rows()  # floats round-trip bit for bit
    assert back["collided"].dtype == np.bool_ and back["n_steps"].dtype == np.int64

    ayss = ayss_table()
    write_table(tmp_path / "ayss.csv", ayss)
    back = read_table(tmp_path / "ayss.csv", AYSS_SCHEMA)
    assert back.equals(ayss)
    assert math.isinf(back["ttc_s"][0]) and math.isnan(back["h_after_m"][1])
    # Written atomically: no temporary file is left behind.
    assert {p.name for p in tmp_path.iterdir()} == {"outcome.csv", "ayss.csv"}


def test_empty_table_round_trips(tmp_path: Path) -> None:
    empty = Table(AYSS_SCHEMA, {c: [] for c in AYSS_SCHEMA.names})
    write_table(tmp_path / "a.csv", empty)
    assert len(read_table(tmp_path / "a.csv", AYSS_SCHEMA)) == 0


def test_header_order_may_differ_but_not_the_set(tmp_path: Path) -> None:
    path = tmp_path / "o.csv"
    write_table(path, table_from_rows(OUTCOME_SCHEMA, outcome_rows()))
    lines = path.read_text().splitlines()
    cells = [line.split(",") for line in lines]
    path.write_text("\n".join(",".join(row[::-1]) for row in cells) + "\n")
    assert read_table(path, OUTCOME_SCHEMA).equals(table_from_rows(OUTCOME_SCHEMA, outcome_rows()))


def _write_and_corrupt(tmp_path: Path, old: str, new: str, count: int = 1) -> Path:
    path = tmp_path / "ayss.csv"
    write_table(path, ayss_table())
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new, count))
    return path


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        (",indicator,", ",", r"missing column\(s\) \['indicator'\]"),  # header only: ragged too
        ("h_after_m", "h_after", r"missing column\(s\) \['h_after_m'\].*unexpected.*'h_after'"),
        (",3.2,", ",fast,", r"column 'indicator', row 0: expected float, got 'fast'"),
        (",-29.0,", ",nan,", r"column 'indicator', row 1: NaN not allowed"),
        (",-29.0,", ",inf,", r"column 'indicator', row 1: inf not allowed"),
        ("\n4,", "\n4.5,", r"column 'sample', row 1: expected int, got '4.5'"),
        (
            "delta_v_bar_mps,3.2",
            "speed,3.2",
            r"column 'indicator_name', row 0: 'speed' is not one of",
        ),
    ],
)
def test_corrupted_tables_are_refused_naming_the_column(
    tmp_path: Path, old: str, new: str, message: str
) -> None:
    path = _write_and_corrupt(tmp_path, old, new)
    with pytest.raises(TableError, match=message) as info:
        read_table(path, AYSS_SCHEMA)
    assert isinstance(info.value, AyssError) and isinstance(info.value, ValueError)
    assert str(path) in str(info.value)


def test_ragged_rows_bad_bools_and_missing_files_are_refused(tmp_path: Path) -> None:
    path = tmp_path / "o.csv"
    write_table(path, table_from_rows(OUTCOME_SCHEMA, outcome_rows()))
    lines = path.read_text().splitlines()
    path.write_text("\n".join([*lines[:2], lines[2] + ",9", *lines[3:]]) + "\n")
    n = len(OUTCOME_SCHEMA.columns)
    with pytest.raises(TableError, match=f"row 1 has {n + 1} cells, header has {n}"):
        read_table(path, OUTCOME_SCHEMA)
    rows = [line.split(",") for line in lines]
    rows[1][OUTCOME_SCHEMA.names.index("collided")] = "2"
    path.write_text("\n".join(",".join(r) for r in rows) + "\n")
    with pytest.raises(TableError, match="column 'collided', row 0: expected bool, got '2'"):
        read_table(path, OUTCOME_SCHEMA)
    with pytest.raises(TableError, match="not found"):
        read_table(tmp_path / "nope.csv", OUTCOME_SCHEMA)
    (tmp_path / "empty.csv").write_text("")
    with pytest.raises(TableError, match="empty file"):
        read_table(tmp_path / "empty.csv", OUTCOME_SCHEMA)


def test_tables_are_validated_when_built() -> None:
    rows = outcome_rows()
    with pytest.raises(TableError, match=r"missing column\(s\) \['n_steps'\]"):
        table_from_rows(OUTCOME_SCHEMA, [{k: v for k, v in rows[0].items() if k != "n_steps"}])
    cols = {c: [r[c] for r in rows] for c in OUTCOME_SCHEMA.names}
    with pytest.raises(TableError, match="differ in length"):
        Table(OUTCOME_SCHEMA, {**cols, "n_steps": [1, 2]})
    with pytest.raises(TableError, match=r"column 'gap0_m'.*NaN not allowed"):
        Table(OUTCOME_SCHEMA, {**cols, "gap0_m": [1.0, math.nan, 2.0]})
    with pytest.raises(TableError, match="column 'v_pov0_mps': expected float"):
        Table(OUTCOME_SCHEMA, {**cols, "v_pov0_mps": ["a", "b", "c"]})


def test_json_summary_is_strict_json(tmp_path: Path) -> None:
    path = tmp_path / "s.json"
    write_json(path, {"b": np.float64(1.5), "a": [math.nan, math.inf, np.int64(3)], "t": (1, 2)})
    text = path.read_text()
    assert json.loads(text) == {"a": [None, None, 3], "b": 1.5, "t": [1, 2]}
    assert text.index('"a"') < text.index('"b"')  # sorted keys, stable diffs
    assert read_json(path)["b"] == 1.5
    (tmp_path / "bad.json").write_text("{not json")
    with pytest.raises(TableError, match="not valid JSON"):
        read_json(tmp_path / "bad.json")
    with pytest.raises(TableError, match="not found"):
        read_json(tmp_path / "missing.json")


def test_a_file_written_before_a_late_column_reads_it_as_not_recorded(tmp_path: Path) -> None:
    """``near_miss_pay`` and ``vut_mean_speed_mps`` came later (issue 22), the safety
    measures later still (issue 27), the crash label (issue 32), the hazards last (issue 33):
    an older outcome.csv without them reads, with NaN there ("not labelled"); any other
    missing column is refused."""
    path = tmp_path / "old.csv"
    write_table(path, table_from_rows(OUTCOME_SCHEMA, outcome_rows()))
    late = 2 + len(MEASURE_NAMES) + 1 + len(HAZARD_NAMES)
    lines = [line.split(",")[:-late] for line in path.read_text().splitlines()]
    path.write_text("\n".join(",".join(r) for r in lines) + "\n")
    old = read_table(path, OUTCOME_SCHEMA)
    assert np.isnan(old["near_miss_pay"]).all() and np.isnan(old["vut_mean_speed_mps"]).all()
    assert all(np.isnan(old[name]).all() for name in MEASURE_NAMES)
    assert np.isnan(old["crash_preventable"]).all()
    assert all(np.isnan(old[name]).all() for name in HAZARD_NAMES)
    assert old["episode_return"].tolist() == [r["episode_return"] for r in outcome_rows()]
    path.write_text("\n".join(",".join(r[:-1]) for r in lines) + "\n")  # n_steps gone too
    with pytest.raises(TableError, match=r"missing column\(s\) \['n_steps'\]"):
        read_table(path, OUTCOME_SCHEMA)
