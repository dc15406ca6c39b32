"""Which cross-play cells a changed study keeps: matched by VUT definition key (a renamed
VUT keeps its cells) and by SPCP SHA-256; a record without keys matches a VUT by name only
while every SPCP it recorded for it is still in the pool."""

from __future__ import annotations

from sumo_ayss.run_folder import CrossplayOpponent, CrossplayRecord, DiagonalCheck
from sumo_ayss.stages.crossplay_cells import merged_rows, plan_cells

A0, B0 = CrossplayOpponent("a", 0, "sa"), CrossplayOpponent("b", 0, "sb")


def _rows(record: CrossplayRecord) -> list[dict]:
    return [
        {"vut": v, "opponent_vut": o.vut, "opponent_seed": o.seed, "scenario": k}
        for v in record.vuts
        for o in record.opponents
        for k in range(2)
    ]


def _earlier(keys: tuple[str, ...] = ("ka", "kb")) -> CrossplayRecord:
    checks = (DiagonalCheck("a", 0, 2, 2), DiagonalCheck("b", 0, 2, 2))
    return CrossplayRecord(
        "car_following", 2, 7, (A0, B0), ("a", "b"), 1.0, "outcome", checks, keys
    )


def test_an_added_vut_drives_its_row_and_column_only() -> None:
    c0 = CrossplayOpponent("c", 0, "sc")
    asked = CrossplayRecord(
        "car_following", 2, 7, (A0, B0, c0), ("a", "b", "c"), 0.0, vut_keys=("ka", "kb", "kc")
    )
    plan = plan_cells(_earlier(), _rows(_earlier()), asked)
    assert plan.to_drive == {"a": (c0,), "b": (c0,), "c": (A0, B0, c0)}
    assert (plan.n_kept, plan.n_to_drive) == (4, 5)
    assert {(c.vut, c.seed) for c in plan.kept_checks} == {("a", 0), ("b", 0)}
    full = merged_rows(
        [*plan.kept_rows, *_rows_of(("a", "b"), (c0,)), *_rows_of(("c",), (A0, B0, c0))],
        asked.vuts,
        asked.opponents,
    )
    assert full == _rows(asked)  # the order a run over the whole request writes


def _rows_of(vuts: tuple[str, ...], opps: tuple[CrossplayOpponent, ...]) -> list[dict]:
    return [
        {"vut": v, "opponent_vut": o.vut, "opponent_seed": o.seed, "scenario": k}
        for v in vuts
        for o in opps
        for k in range(2)
    ]


def test_a_renamed_vut_keeps_its_cells_and_a_redefined_one_does_not() -> None:
    renamed = CrossplayOpponent("z", 0, "sb")  # b's SPCP, under its new name
    asked = CrossplayRecord(
        "car_following", 2, 7, (A0, renamed), ("a", "z"), 0.0, vut_keys=("ka", "kb")
    )
    plan = plan_cells(_earlier(), _rows(_earlier()), asked)
    assert plan.to_drive == {} and plan.renamed == (("b", "z"),)
    assert {r["vut"] for r in plan.kept_rows} == {"a", "z"}
    assert {r["opponent_vut"] for r in plan.kept_rows} == {"a", "z"}
    b1 = CrossplayOpponent("b", 0, "sb2")  # b redefined: retrained, another SPCP
    asked = CrossplayRecord(
        "car_following", 2, 7, (A0, b1), ("a", "b"), 0.0, vut_keys=("ka", "kb2")
    )
    plan = plan_cells(_earlier(), _rows(_earlier()), asked)
    assert plan.to_drive == {"a": (b1,), "b": (A0, b1)} and plan.n_kept == 1


def test_a_record_without_keys_matches_a_vut_by_name_while_its_spcps_stand() -> None:
    legacy = _earlier(keys=())
    c0 = CrossplayOpponent("c", 0, "sc")
    asked = CrossplayRecord(
        "car_following", 2, 7, (A0, B0, c0), ("a", "b", "c"), 0.0, vut_keys=("ka", "kb", "kc")
    )
    assert plan_cells(legacy, _rows(legacy), asked).n_kept == 4
    b1 = CrossplayOpponent("b", 0, "sb2")
    asked = CrossplayRecord("car_following", 2, 7, (A0, b1), ("a", "b"), 0.0, vut_keys=("ka", "x"))
    plan = plan_cells(legacy, _rows(legacy), asked)
    assert plan.to_drive == {"a": (b1,), "b": (A0, b1)}  # b's SPCP changed: b is new
