"""Leaderboard rows: ordered by safety index, with intervals and verdicts against the next."""

from __future__ import annotations

import json
from contextlib import nullcontext
from pathlib import Path

import pytest
import yaml

from sumo_ayss.commands.rank import main
from sumo_ayss.config import PROJECT_ROOT
from sumo_ayss.config.report import ReportOptions
from sumo_ayss.modes.paper import paper_result
from sumo_ayss.rank import analyse, order_check, ranking_rows, write_ranking
from sumo_ayss.run_folder import read_run
from sumo_ayss.run_folder.study import read_order_check, read_ranking_csv
from tests.report.test_report import EXPOSURE, OFFSET, make_crossplay, make_run


def _three_vuts(tmp_path: Path, monkeypatch) -> list[Path]:
    monkeypatch.setitem(OFFSET, "cautious", -3.0)  # its SPCPs brake hardest: safest VUT
    monkeypatch.setitem(EXPOSURE, "cautious", -2.5)  # and extract the least reward
    return [
        make_run(tmp_path, "car_following", vut, seed)
        for vut in ("pi1", "pi2", "cautious")
        for seed in range(3)
    ]


def test_paper_mode_ranking_of_three_vuts_is_ordered_with_intervals(tmp_path, monkeypatch):
    dirs = _three_vuts(tmp_path, monkeypatch)
    all_rows = ranking_rows(analyse(dirs, ReportOptions(mode="paper", n_boot=400)))
    assert [r["mode"] for r in all_rows] == ["paper"] * 3 + ["exposure"] * 3  # chosen first
    rows = all_rows[:3]
    assert [r["vut"] for r in rows] == ["cautious", "pi2", "pi1"]
    assert [r["rank"] for r in rows] == [1, 2, 3]
    for r in rows:
        assert r["lo"] <= r["score"] <= r["hi"] and r["n_seeds"] == 3 and r["mode"] == "paper"
    points = [r["score"] for r in rows]
    assert points == sorted(points, reverse=True)
    assert rows[0]["significant_vs_next"] is True
    assert all(r["vs_next"].startswith("[paper mode] ") for r in rows[:-1])
    assert rows[-1]["vs_next"] == ""
    csv_path, md_path = write_ranking(rows, tmp_path)
    assert csv_path.read_text().splitlines()[0].startswith("case,mode,rank,vut,score")
    assert "| car_following | paper | 1 | cautious |" in md_path.read_text()


def test_exposure_mode_ranks_by_outcome_reward_and_checks_a_known_order(tmp_path, monkeypatch):
    dirs = _three_vuts(tmp_path, monkeypatch)
    analyses = analyse(dirs, ReportOptions(mode="exposure", n_boot=200))
    rows = ranking_rows(analyses)
    assert [r["vut"] for r in rows] == ["cautious", "pi2", "pi1"]
    assert all(r["mode"] == "exposure" for r in rows)
    scores = [r["score"] for r in rows]
    assert scores == sorted(scores)  # lower exposure = safer
    assert rows[0]["significant_vs_next"] is True and "[exposure mode]" in rows[0]["vs_next"]
    check = order_check(analyses[0], ["cautious", "pi2", "pi1"])
    assert check is not None
    assert check.tau == 1.0 and check.ends_significant
    assert check.significant_adjacent == 2 and check.adjacent == 2
    wrong = order_check(analyses[0], ["pi1", "pi2", "cautious"])
    assert wrong is not None and wrong.tau == -1.0 and not wrong.ends_significant
    assert order_check(analyses[0], ["pi1", "pi2"]) is None
    _, md = write_ranking(rows, tmp_path, [check], ["cautious", "pi2", "pi1"])
    assert "Kendall tau = 1.00" in md.read_text()
    assert read_order_check(tmp_path / "order_check.json").cases == (check,)


def _pipe_yaml(tmp_path: Path, expected: list[str], **extra) -> Path:
    pipe = tmp_path / "pipe.yaml"
    pipe.write_text(
        yaml.safe_dump(
            {
                "grid": {"cases": ["car_following"], "vuts": expected, "seeds": [0, 1, 2]},
                "experiments": {
                    "car_following": str(PROJECT_ROOT / "configs" / "car_following.yaml")
                },
                "vuts": {"cautious": {"model": "IDM", "params": {"minGap": 12.0}}},
                "out": "runs",
                "expected_order": expected,
                **extra,
            }
        )
    )
    return pipe


def test_rank_after_the_pipeline_reads_and_analyses_each_case_once(tmp_path, monkeypatch, capsys):
    """``rank`` with the pipeline: the pipeline reads each run folder and the cross-play
    table once and analyses each case once (one bootstrap per VUT) for its report, and rank
    ranks those analyses; the rows equal ``--no-run``'s, which also computes once."""
    import sumo_ayss.analysis.case as case_mod
    import sumo_ayss.modes.analyse as analyse_mod
    import sumo_ayss.pipeline as pipeline_mod
    import sumo_ayss.run_folder.crossplay as crossplay_mod
    import sumo_ayss.run_folder.record as record_mod
    from sumo_ayss.grid.progress import JobStatus

    dirs = _three_vuts(tmp_path / "runs", monkeypatch)
    expected = ["cautious", "pi2", "pi1"]
    make_crossplay(tmp_path / "runs" / "car_following", expected, [0, 1, 2])
    pipe = _pipe_yaml(tmp_path, expected, report={"n_boot": 300})
    # The grid's jobs are the finished folders above (no training here).
    monkeypatch.setattr(
        pipeline_mod,
        "run_grid_local",
        lambda jobs, *a, **k: [JobStatus(spec=j, state="done") for j in jobs],
    )
    monkeypatch.setattr(pipeline_mod, "discriminability_beside", lambda cfg: nullcontext())
    # The folders above are made by hand with the default experiment, not the grid's budget.
    monkeypatch.setattr("sumo_ayss.grid.study.check_same_study", lambda cfg, jobs: None)
    counts: dict[str, list[str]] = {"ayss": [], "crossplay": [], "bootstrap": [], "case": []}

    def counted(key, real, label):
        def wrapper(*a, **k):
            counts[key].append(label(*a, **k))
            return real(*a, **k)

        return wrapper

    monkeypatch.setattr(
        record_mod,
        "_ayss_samples",
        counted("ayss", record_mod._ayss_samples, lambda p: str(p.parent)),
    )
    monkeypatch.setattr(
        crossplay_mod,
        "read_crossplay_table",
        counted("crossplay", crossplay_mod.read_crossplay_table, lambda p, *a: str(p)),
    )
    monkeypatch.setattr(
        case_mod,
        "vut_safety_index",
        counted("bootstrap", case_mod.vut_safety_index, lambda runs, *a: runs[0].vut),
    )
    monkeypatch.setattr(
        analyse_mod, "analyse_case", counted("case", analyse_mod.analyse_case, lambda c, *a, **k: c)
    )
    with pytest.raises(SystemExit) as done:
        main([str(pipe), "--no-live", "--mode", "paper"])
    assert done.value.code == 0
    assert sorted(counts["ayss"]) == sorted(str(d.resolve()) for d in dirs)  # each once
    assert len(counts["crossplay"]) == 1
    assert sorted(counts["bootstrap"]) == sorted(expected)  # one bootstrap per VUT
    assert counts["case"] == ["car_following"]
    assert (tmp_path / "runs" / "report" / "summary.md").is_file()
    with_pipeline = (tmp_path / "runs" / "ranking.csv").read_text()
    modes = [line.split(",")[1] for line in with_pipeline.splitlines()[1:]]
    assert modes == ["paper"] * 3 + ["crossplay"] * 3 + ["exposure"] * 3

    for seen in counts.values():
        seen.clear()
    with pytest.raises(SystemExit):
        main([str(pipe), "--no-run", "--no-live", "--mode", "paper"])
    assert len(counts["ayss"]) == 9 and len(counts["crossplay"]) == 1
    assert len(counts["bootstrap"]) == 3 and counts["case"] == ["car_following"]
    assert (tmp_path / "runs" / "ranking.csv").read_text() == with_pipeline
    capsys.readouterr()


def test_paper_rows_only_in_paper_mode_even_from_the_pipelines_analyses(tmp_path, monkeypatch):
    """The pipeline's analyses carry the paper mode (its report shows it); rank lists paper
    rows in paper mode only, as ``--no-run`` (which skips the bootstrap otherwise) does."""
    from sumo_ayss.modes import analyse_cases
    from sumo_ayss.run_folder import case_runs

    dirs = _three_vuts(tmp_path, monkeypatch)
    options = ReportOptions(mode="exposure", n_boot=200)
    full = analyse_cases(case_runs([read_run(d) for d in dirs]), options)  # paper mode computed
    assert paper_result(full[0]).ranking
    assert ranking_rows(full) == ranking_rows(analyse(dirs, options))
    assert {r["mode"] for r in ranking_rows(full)} == {"exposure"}


def test_rank_no_run_checks_the_known_order_in_every_mode_available(tmp_path, monkeypatch, capsys):
    """``rank --no-run`` on existing folders: a row set and an order check per (case, mode);
    cross-play rows where the case's crossplay.csv exists, and no cross-play is run."""
    _three_vuts(tmp_path / "runs", monkeypatch)
    expected = ["cautious", "pi2", "pi1"]
    pipe = _pipe_yaml(tmp_path, expected)
    with pytest.raises(SystemExit) as done:  # no crossplay.csv yet: exposure only
        main([str(pipe), "--no-run", "--no-live"])
    assert done.value.code == 0
    checks = json.loads((tmp_path / "runs" / "order_check.json").read_text())["cases"]
    assert [c["mode"] for c in checks] == ["exposure"]
    assert not (tmp_path / "runs" / "car_following" / "crossplay.csv").exists()
    make_crossplay(tmp_path / "runs" / "car_following", expected, [0, 1, 2])
    with pytest.raises(SystemExit):
        main([str(pipe), "--no-run", "--no-live", "--mode", "paper"])
    checks = json.loads((tmp_path / "runs" / "order_check.json").read_text())["cases"]
    assert [c["mode"] for c in checks] == ["paper", "crossplay", "exposure"]
    for c in checks:
        assert c["case"] == "car_following" and c["order"] == expected and c["tau"] == 1.0
        assert {"ends_significant", "ends_p", "significant_adjacent", "adjacent"} <= set(c)
    with (tmp_path / "runs" / "ranking.csv").open() as f:
        modes = [line.split(",")[1] for line in f.readlines()[1:]]
    assert modes == ["paper"] * 3 + ["crossplay"] * 3 + ["exposure"] * 3
    main_md = (tmp_path / "runs" / "ranking.md").read_text()
    assert "| car_following | crossplay | 1 | cautious |" in main_md
    assert "[crossplay mode] cautious is safer than pi2" in main_md
    capsys.readouterr()


def test_ranking_md_shows_a_tie_as_a_shared_rank_and_in_the_known_order_line(tmp_path) -> None:
    from sumo_ayss.run_folder import OrderCheck

    def row(rank: int, vut: str, sig: bool | str) -> dict:
        return {
            "case": "cut_in",
            "mode": "crossplay",
            "rank": rank,
            "vut": vut,
            "score": 0.1 * rank,
            "lo": float("nan"),
            "hi": float("nan"),
            "n_seeds": 4,
            "unit": "harm",
            "p_vs_next": 0.3,
            "significant_vs_next": sig,
            "vs_next": "",
            "crash_rate": "",
            "crash_lo": "",
            "crash_hi": "",
            "crashes": "",
            "episodes": "",
            "mobility_mps": "",
            "timid": "",
        }

    rows = [row(1, "b", True), row(2, "a", False), row(3, "c", "")]
    check = OrderCheck(
        "cut_in", "crossplay", ("b", "a", "c"), ("b", "a", "c"), 1.0, True, 0.01, 1, 2
    )
    _, md = write_ranking(rows, tmp_path, [check], ("b", "a", "c"))
    text = md.read_text()
    assert "| cut_in | crossplay | 1 | b |" in text
    assert "| cut_in | crossplay | 2–3 | a |" in text and "| cut_in | crossplay | 2–3 | c |" in text
    assert "Ranking: b > a ≈ c." in text


def test_ranking_files_show_hazards_only_where_recorded(tmp_path: Path) -> None:
    """Issue 33: the hazard columns and the OVER-BRAKING flag in ranking.csv and ranking.md
    where a study recorded them (a follower); a study without keeps its columns exactly."""
    from sumo_ayss.analysis.harm import VutOutcome
    from sumo_ayss.rank import _hazard_cells
    from sumo_ayss.run_folder.study import RANKING_COLUMNS, RANKING_HAZARD_COLUMNS

    def row(rank: int, vut: str, o: VutOutcome | None) -> dict:
        cells = {c: "" for c in RANKING_COLUMNS}
        cells.update(case="car_following", mode="crossplay", rank=rank, vut=vut, score=0.3,
                     lo=0.2, hi=0.4, n_seeds=4, unit="harm", significant_vs_next="")  # fmt: skip
        return {**cells, **_hazard_cells(o)}

    h = {"unjustified_braking": 0.52, "unjustified_dv_mps": 1.14, "rear_end": 0.01,
         "rear_end_unjustified": 0.005, "follower_max_braking_mps2": 4.8}  # fmt: skip
    flagged = VutOutcome(3, 100, 0.01, 0.08, 12.4, False, h, overbraking=True)
    plain = VutOutcome(3, 100, 0.01, 0.08, 13.3, False, {**h, "unjustified_braking": 0.16})
    bare = VutOutcome(3, 100, 0.01, 0.08, 13.3, False)  # no follower: nothing recorded
    csv_path, md = write_ranking([row(1, "ob", flagged), row(2, "pi2", plain)], tmp_path / "a")
    header = csv_path.read_text().splitlines()[0].split(",")
    assert header == [*RANKING_COLUMNS, *RANKING_HAZARD_COLUMNS]
    back = read_ranking_csv(csv_path)
    assert back[0]["overbraking"] == "True" and back[1]["overbraking"] == "False"
    assert back[0]["unjustified_braking_rate"] == "0.52" and back[0]["rear_end_rate"] == "0.01"
    text = md.read_text()
    assert "| unjustified braking | hazards caused |" in text.splitlines()[0]
    assert "| 52 %, 1.14 m/s (OVER-BRAKING) | rear-ends 1.0 % (caused 0.5 %), follower 4.8" in text
    assert "| 16 %, 1.14 m/s | rear-ends" in text
    csv_path, md = write_ranking([row(1, "pi1", bare), row(2, "pi2", None)], tmp_path / "b")
    assert csv_path.read_text().splitlines()[0].split(",") == list(RANKING_COLUMNS)
    assert "unjustified" not in md.read_text() and "OVER-BRAKING" not in md.read_text()
