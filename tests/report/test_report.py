"""Report stage on synthetic run folders written by the real writers (no SUMO run, no
training, no torch)."""

from __future__ import annotations

import json
import math
import re
import zlib
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pytest

from sumo_ayss.analysis.crossplay import CrossplayGap
from sumo_ayss.analysis.ranking import POV_ACCELERATION, SafetyIndex
from sumo_ayss.analysis.safety_measures import MEASURE_NAMES
from sumo_ayss.config import RewardConfig, to_dict
from sumo_ayss.modes import headline_text
from sumo_ayss.modes.crossplay import crossplay_gap_text, crossplay_result
from sumo_ayss.modes.paper import pair_sentence
from sumo_ayss.records.table import Table, write_table
from sumo_ayss.report import (
    ReportOptions,
    pair_verdict,
    vut_safety_index,
    write_report,
)
from sumo_ayss.report.__main__ import main
from sumo_ayss.run_folder import (
    AYSS_SCHEMA,
    CROSSPLAY_SCHEMA,
    OUTCOME_SCHEMA,
    CaseFolder,
    RunConfig,
    RunFolder,
    StageHeader,
    find_run_dirs,
    read_run,
    write_eval_table,
    write_outcome_json,
    write_run_config,
    write_spcp,
)
from sumo_ayss.run_folder.crossplay import load_crossplay
from sumo_ayss.run_folder.metadata import write_versions
from sumo_ayss.scenarios.outcome import MeanInterval, OutcomeSummary, Proportion
from sumo_ayss.training.selection import Selection
from sumo_ayss.vuts.catalog import BUILTIN_VUTS
from tests.helpers import modules_loaded_by

#: Mean indicator offset per VUT: pi2's SPCPs are clearly more aggressive (more negative).
OFFSET = {"pi1": 0.0, "pi2": -1.5, "pi1_again": 0.0}
#: Mean outcome reward offset per VUT: the SPCPs extract less reward from pi2 (safer).
EXPOSURE = {"pi1": 0.0, "pi2": -1.0, "pi1_again": 0.0}

FAST = ReportOptions(n_boot=400)


def scored_crossplay(runs):  # type: ignore[no-untyped-def]
    """The case's cross-play files as stored (:func:`load_crossplay`), scored by the analysis."""
    from sumo_ayss.analysis.crossplay_scoring import crossplay_input

    return crossplay_input(load_crossplay(runs), runs)


def _proportion(value: float, half: float, n: int = 200) -> Proportion:
    return Proportion(round(value * n), n, value, max(0.0, value - half), value + half, 0.95)


def _mean(value: float, half: float, n: int = 200) -> MeanInterval:
    return MeanInterval(n, value, value - half, value + half, 0.95)


def make_run(
    root: Path,
    case: str,
    vut: str,
    seed: int,
    *,
    files: Sequence[str] = ("config", "eval", "spcp", "outcome", "ayss", "versions"),
    n_samples: int = 300,
) -> Path:
    """Writes a plausible run folder ``root/case/vut/seed_<seed>`` with synthetic data,
    through the run folder's own writers (those train and evaluate call)."""
    folder = RunFolder(root / case / vut / f"seed_{seed}")
    folder.path.mkdir(parents=True)
    rng = np.random.default_rng([seed, zlib.crc32(vut.encode()), int(case == "cut_in")])
    if "config" in files:
        env = {
            "case": case,
            "vut": vut,
            "vuts": {k: to_dict(v) for k, v in BUILTIN_VUTS.items()},
            "reward": to_dict(RewardConfig()),
        }
        experiment = {"env": env, "agent": {"gamma": 0.8}, "train": {}}
        write_run_config(folder.config, RunConfig(vut, seed, experiment))
    steps = np.arange(10_000, 200_001, 10_000)
    returns = 19.0 * (1 - np.exp(-steps / 40_000)) + rng.normal(0, 0.3, steps.size)
    rows = []
    for s, r in zip(steps, returns, strict=True):
        crash = max(0.0, 0.3 * math.exp(-s / 50_000) + rng.normal(0, 0.01))
        rows.append(
            {
                "step": int(s),
                "mean_return": round(float(r), 4),
                "std_return": 2.0,
                "crash_rate": round(crash, 3),
                "lane_change_rate": 0.9 if case == "cut_in" else 0.0,
                "mean_final_headway_m": 2.1,
                "n_episodes": 100,
                "wall_s": 12.5,
                "checkpoint": folder.checkpoint_model(folder.step_dir(int(s))),
            }
        )
    if "eval" in files:
        write_eval_table(folder.eval_table, rows)
    if "spcp" in files:
        best = int(np.argmax(returns))
        choice = Selection(best, int(steps[best]), float(returns[best]), "mean_reward", "best")
        write_spcp(folder.spcp_json, choice, rows[best]["checkpoint"], rows[best])
    if "outcome" in files:
        outcome_rng = np.random.default_rng([seed, zlib.crc32(vut.encode()), 7])
        cut_in = case == "cut_in"
        summary = OutcomeSummary(
            case=case,
            n_episodes=200,
            crash_rate=_proportion(0.01 * (seed % 3), 0.01),
            lane_change_rate=_proportion(0.99, 0.01) if cut_in else None,
            mean_return=_mean(19.4 + EXPOSURE.get(vut, 0.0) + outcome_rng.normal(0.0, 0.1), 0.2),
            mean_final_headway_m=_mean(1.7 + 0.8 * (vut == "pi2"), 0.3),
            lc_no_collision_return=_mean(20.8, 0.2, 196) if cut_in else None,
            lc_no_collision_final_headway_m=_mean(0.36, 0.05, 196) if cut_in else None,
        )
        header = StageHeader(str(folder.path), case, vut, seed, None)
        settings = {"n": 200, "seed": 4242}
        write_outcome_json(folder.outcome_json, header, settings, {}, summary.as_dict(), 1.0)
        write_table(folder.outcome_csv, _outcome_table(summary, outcome_rng))
    if "ayss" in files:
        _write_ayss(folder.ayss_csv, case, vut, rng, n_samples)
    if "versions" in files:
        versions = {"python": "3.11.2", "eclipse-sumo": "1.28.0", "numpy": np.__version__}
        write_versions(folder.versions, versions)
    return folder.path


def _outcome_table(summary: OutcomeSummary, rng: np.random.Generator) -> Table:
    """Episodes whose mean return and crash count follow ``summary`` (crashes first)."""
    n, crashes = summary.n_episodes, summary.crash_rate.count
    pay = np.clip(rng.normal(summary.mean_return.mean, 0.5, n), 0.0, 24.9)
    crashed = np.arange(n) < crashes
    return Table(
        OUTCOME_SCHEMA,
        {
            "scenario": np.arange(n),
            "v_pov0_mps": np.full(n, 20.0),
            "v_vut0_mps": np.full(n, 20.0),
            "gap0_m": np.full(n, 10.0),
            "episode_return": np.where(crashed, pay - 10.0, pay),
            "collided": crashed,
            "lane_changed": np.full(n, summary.lane_change_rate is not None),
            "final_headway_m": np.full(n, summary.mean_final_headway_m.mean),
            "n_steps": np.full(n, 25),
            "near_miss_pay": pay,
            "vut_mean_speed_mps": np.full(n, 20.0),
            **{name: np.full(n, np.nan) for name in MEASURE_NAMES},
        },
    )


def make_crossplay(case_dir: Path, vuts: Sequence[str], seeds: Sequence[int], n: int = 20) -> Path:
    """A synthetic ``crossplay.csv`` in ``case_dir``: every (VUT, seed) opponent against every
    VUT on ``n`` scenarios; an opponent extracts ``19.4 + EXPOSURE[vut]`` plus its own level
    (one per opponent, shared by every VUT) and episode noise."""
    rng = np.random.default_rng(11)
    cols: dict[str, list] = {c.name: [] for c in CROSSPLAY_SCHEMA.columns}
    for o_vut in vuts:
        for o_seed in seeds:
            level = rng.normal(0.0, 1.0)
            for vut in vuts:
                for k in range(n):
                    cols["vut"].append(vut)
                    cols["opponent_vut"].append(o_vut)
                    cols["opponent_seed"].append(o_seed)
                    cols["scenario"].append(k)
                    pay = 19.4 + EXPOSURE.get(vut, 0.0) + level + rng.normal(0.0, 0.3)
                    cols["episode_return"].append(pay)
                    cols["near_miss_pay"].append(pay)
                    cols["vut_mean_speed_mps"].append(20.0)
                    cols["collided"].append(False)
    for c in CROSSPLAY_SCHEMA.columns:  # the columns the ranking does not read
        if not cols[c.name]:
            cols[c.name] = [0.0 if c.dtype == "float" else 0] * len(cols["vut"])
    path = CaseFolder(case_dir).crossplay_csv
    write_table(path, Table(CROSSPLAY_SCHEMA, {k: np.asarray(v) for k, v in cols.items()}))
    return path


def _write_ayss(path: Path, case: str, vut: str, rng: np.random.Generator, n: int) -> None:
    h = np.round(rng.uniform(0.0, 5.0, n), 4)
    seed_shift = rng.normal(0.0, 0.1)
    if case == "car_following":
        y = np.clip(-2.5 + 0.35 * h + OFFSET[vut] + seed_shift + rng.normal(0, 0.8, n), -6, 6)
        name = "pov_accel_mps2"
    else:
        y = -1.0 - 0.2 * h + OFFSET[vut] + seed_shift + rng.normal(0, 0.6, n)
        name = "delta_v_bar_mps"
    columns = {
        "sample": np.arange(n),
        "v_pov_mps": np.full(n, 20.0),
        "v_vut_mps": np.full(n, 22.0),
        "h_m": h,
        "same_lane": np.full(n, int(case == "car_following")),
        "action": np.full(n, 3),
        "target_speed_mps": np.full(n, 15.0),
        "ttc_s": np.full(n, 2.5),
        "indicator_name": np.full(n, name),
        "indicator": np.round(y, 4),
        "h_after_m": np.full(n, np.nan),
        "delta_v_bar_before_mps": np.full(n, np.nan),
    }
    write_table(path, Table(AYSS_SCHEMA, columns))


@pytest.fixture(scope="module")
def full_report(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Both cases, pi1 and pi2, three seeds each; returns report.html."""
    root = tmp_path_factory.mktemp("runs")
    for case in ("car_following", "cut_in"):
        for vut in ("pi1", "pi2"):
            for seed in range(3):
                make_run(root, case, vut, seed)
    return write_report([root], options=FAST)


def test_html_is_self_contained(full_report: Path) -> None:
    assert full_report == full_report.parent.parent / "report" / "report.html"
    text = full_report.read_text(encoding="utf-8")
    assert 'src="http' not in text and "href='http" not in text
    assert not re.search(r'href="(?!#)', text), "only in-page links are allowed"
    assert "<script" not in text.lower() and "<link" not in text.lower()
    srcs = re.findall(r'<img[^>]*\ssrc="([^"]*)"', text)
    assert srcs and all(s.startswith("data:image/png;base64,") for s in srcs)
    assert text.count("<img") == len(srcs)


def test_html_holds_every_figure_and_table(full_report: Path) -> None:
    text = full_report.read_text(encoding="utf-8")
    # Per case: reward shapes, learning curves, indicator vs headway, exposure per seed,
    # safety index.
    assert text.count("<img") == 10
    assert "Table II equivalent" in text and "Table III equivalent" in text
    assert "19.48" in text and "20.99" in text  # the paper's reference numbers
    assert "significance rule" in text and "Welch" in text and "paired t-test" in text
    assert "[exposure mode]" in text and "[paper mode]" in text and "Premise" in text
    pngs = sorted(p.name for p in full_report.parent.glob("*.png"))
    assert len(pngs) == 10 and "car_following_indicator_vs_headway.png" in pngs
    assert "cut_in_exposure_by_seed.png" in pngs


def test_verdict_names_the_safer_vut(full_report: Path) -> None:
    text = full_report.read_text(encoding="utf-8")
    assert "pi2 is safer than pi1: its SPCPs brake" in text
    assert "pi2 is safer than pi1: its SPCPs close in" in text
    verdicts = text.split('id="inputs"')[0]  # the summary at the top names it too
    assert verdicts.count("[exposure mode] pi2 is safer than pi1") == 2
    assert verdicts.count("in cut-in, exposure mode has NOT recovered a known safety order") >= 1
    assert verdicts.count("[paper mode] pi2 is safer than pi1") == 2


def test_summary_md_links_resolve(full_report: Path) -> None:
    md = full_report.parent / "summary.md"
    text = md.read_text(encoding="utf-8")
    links = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", text)
    assert len(links) == 10
    for link in links:
        assert not link.startswith(("/", "http"))
        assert (md.parent / link).is_file(), link
    assert "pi2 is safer than pi1" in text
    assert "Table II equivalent" in text and "Table III equivalent" in text


def test_missing_ayss_is_reported_not_fatal(tmp_path: Path) -> None:
    for vut in ("pi1", "pi2"):
        for seed in range(3):
            files: tuple[str, ...] = ("config", "eval", "spcp", "outcome", "versions")
            if (vut, seed) != ("pi2", 2):
                files += ("ayss",)
            make_run(tmp_path, "car_following", vut, seed, files=files)
    make_run(tmp_path, "car_following", "pi2", 9, files=("config", "eval"))
    out = write_report([tmp_path], tmp_path / "out", options=FAST)
    text = out.read_text(encoding="utf-8")
    assert "car_following/pi2/seed_2: ayss.csv missing" in text
    assert "car_following/pi2/seed_9: outcome.json missing" in text
    assert "outcome.json missing" in (tmp_path / "out" / "summary.md").read_text()
    assert "pi2 is safer than pi1" in text  # the remaining seeds still decide


def test_no_ayss_at_all_gives_no_verdict(tmp_path: Path) -> None:
    make_run(tmp_path, "cut_in", "pi1", 0, files=("config", "eval", "spcp"))
    out = write_report([tmp_path / "cut_in" / "pi1" / "seed_0"], tmp_path / "out", options=FAST)
    text = out.read_text(encoding="utf-8")
    assert "No verdict yet" in text and "ayss.csv missing" in text
    assert text.count("<img") == 3  # reward shapes, learning curves, (empty) indicator plot


def test_same_vut_under_two_seed_sets_is_no_difference(tmp_path: Path) -> None:
    first = [read_run(make_run(tmp_path, "car_following", "pi1", s)) for s in range(3)]
    second = [read_run(make_run(tmp_path, "car_following", "pi1_again", s)) for s in (3, 4, 5)]
    a = vut_safety_index(first, FAST, rng=1)
    b = vut_safety_index(second, FAST, rng=2)
    assert a is not None and b is not None
    pair = pair_verdict(
        a, b, name_a="pi1 (seeds 0-2)", name_b="pi1 (seeds 3-5)", indicator=POV_ACCELERATION
    )
    assert not pair.significant and pair.safer is None
    assert pair_sentence(pair).startswith("No significant difference")
    text = write_report([tmp_path], tmp_path / "out", options=FAST).read_text(encoding="utf-8")
    assert re.search(
        r"No significant difference in safety between (pi1 and pi1_again|pi1_again and pi1)", text
    )
    assert "is safer than" not in text


def _index(point: float, seed_points: Sequence[float], replicates: np.ndarray) -> SafetyIndex:
    return SafetyIndex(
        point=point,
        lo=float(np.quantile(replicates, 0.025)),
        hi=float(np.quantile(replicates, 0.975)),
        n_seeds=len(seed_points),
        n_samples=300,
        bins_used=(True,) * 10,
        replicates=replicates,
        indicator_samples=-np.asarray(seed_points, dtype=float),
        seed_points=tuple(seed_points),
    )


def test_bootstrap_alone_is_not_significant() -> None:
    rng = np.random.default_rng(0)
    # Narrow bootstraps 0.5 apart, but the seeds spread widely: Welch p is large.
    a = _index(2.5, (1.0, 2.5, 4.0), 2.5 + rng.normal(0, 0.05, 400))
    b = _index(2.0, (0.5, 2.0, 3.5), 2.0 + rng.normal(0, 0.05, 400))
    pair = pair_verdict(a, b, name_a="A", name_b="B", indicator=POV_ACCELERATION)
    assert pair.verdict.significant and pair.verdict.p_seed_welch > 0.05
    assert not pair.significant and pair.safer is None
    assert pair_sentence(pair).startswith("No significant difference")
    assert "bootstrap interval alone excludes 0" in pair_sentence(pair)
    # With tight seeds both tests agree and A is called safer.
    c = _index(2.5, (2.45, 2.5, 2.55), 2.5 + rng.normal(0, 0.05, 400))
    d = _index(2.0, (1.95, 2.0, 2.05), 2.0 + rng.normal(0, 0.05, 400))
    pair = pair_verdict(c, d, name_a="A", name_b="B", indicator=POV_ACCELERATION)
    assert pair.significant and pair.safer == "A"
    text = pair_sentence(pair)
    assert text.startswith("A is safer than B") and "Welch test: p" in text


def test_outcome_reader_refuses_shapes_no_writer_produces(tmp_path: Path) -> None:
    run_dir = make_run(tmp_path, "cut_in", "pi1", 0, files=("config",))
    outcome = {  # estimates at the top level, aliased keys: not what evaluate writes
        "n_episodes": 200,
        "crash_rate": {"mean": 0.02, "ci": [0.005, 0.05]},
        "lane_change_rate": 0.98,
        "mean_return": {"value": 20.1, "lo": 19.9, "hi": 20.3},
    }
    (RunFolder(run_dir).outcome_json).write_text(json.dumps(outcome))
    run = read_run(run_dir)
    assert run.outcome is None
    text = " | ".join(run.problems)
    assert "outcome.json unreadable" in text and "missing field 'summary'" in text
    assert run.reward == RewardConfig() and run.seed == 0 and run.case == "cut_in"
    assert "ayss.csv missing" in run.problems and "eval.csv missing" in run.problems


def test_unreadable_files_are_reported_not_fatal(tmp_path: Path) -> None:
    run_dir = make_run(tmp_path, "car_following", "pi1", 0, files=())
    (RunFolder(run_dir).outcome_json).write_text("{not json")
    (RunFolder(run_dir).ayss_csv).write_text("h_m,indicator,indicator_name\n1.0,-2.0,x\nnan,1,x\n")
    (RunFolder(run_dir).eval_table).write_text("step,other\n1,2\n")
    run = read_run(run_dir)
    assert run.case == "car_following" and run.vut == "pi1" and run.seed == 0
    assert run.outcome is None and run.eval_curve is None and run.ayss is None
    text = " | ".join(run.problems)
    assert "outcome.json unreadable" in text and "eval.csv unreadable" in text
    assert "ayss.csv unreadable" in text and "missing column(s)" in text
    assert "config.yaml missing" in text


def test_ayss_of_the_other_case_is_reported(tmp_path: Path) -> None:
    run_dir = make_run(tmp_path, "car_following", "pi1", 0, files=("config",))
    _write_ayss(RunFolder(run_dir).ayss_csv, "cut_in", "pi1", np.random.default_rng(0), 10)
    run = read_run(run_dir)
    assert run.ayss is not None and len(run.ayss) == 10
    assert any("belongs to cut_in, not car_following" in p for p in run.problems)


def test_find_run_dirs_skips_the_report_folder(tmp_path: Path) -> None:
    make_run(tmp_path, "car_following", "pi1", 0)
    make_run(tmp_path, "car_following", "pi2", 0)
    (tmp_path / "report").mkdir()
    (tmp_path / "report" / "summary.md").write_text("# old report\n")
    found = find_run_dirs([tmp_path, tmp_path / "car_following" / "pi1" / "seed_0"])
    assert [p.relative_to(tmp_path.resolve()).as_posix() for p in found] == [
        "car_following/pi1/seed_0",
        "car_following/pi2/seed_0",
    ]


def test_cli_writes_report(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    make_run(tmp_path, "car_following", "pi1", 0)
    make_run(tmp_path, "car_following", "pi2", 0)
    main([str(tmp_path), "--out", str(tmp_path / "r"), "--title", "My title", "--n-boot", "200"])
    printed = capsys.readouterr().out.strip()
    assert printed == str(tmp_path / "r" / "report.html")
    assert "<title>My title</title>" in Path(printed).read_text(encoding="utf-8")
    with pytest.raises(SystemExit, match="not a folder"):
        main([str(tmp_path / "nope")])


def test_report_imports_neither_torch_nor_libsumo() -> None:
    forbidden = {"torch", "libsumo", "matplotlib.pyplot"}
    loaded = modules_loaded_by("import sumo_ayss.report")
    assert not loaded & forbidden, sorted(loaded & forbidden)
    assert not any(m.startswith(("torch.", "libsumo.")) for m in loaded)


def test_report_has_no_import_fallbacks() -> None:
    """A figure is never dropped silently because an import failed."""
    import ast

    import sumo_ayss.report

    root = Path(sumo_ayss.report.__file__).parent
    for path in sorted(root.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ExceptHandler) and node.type is not None:
                names = {n.id for n in ast.walk(node.type) if isinstance(n, ast.Name)}
                assert not names & {"ImportError", "ModuleNotFoundError"}, (
                    f"{path.name}:{node.lineno} catches an ImportError"
                )


def test_crossplay_mode_without_a_table_says_so_then_shows_exposure(full_report: Path) -> None:
    text = full_report.read_text(encoding="utf-8")
    verdicts = text.split('id="inputs"')[0]
    missing = (
        "[crossplay mode] no cross-play table for this case (run python -m sumo_ayss.crossplay "
        "&lt;config&gt;)"
    )
    assert verdicts.count(missing) == 2
    assert "Ranking (exposure mode), safest first" in verdicts  # labelled, not silent
    assert "(i) Cross-play ranking" in text and "Cross-play table missing" in text


def test_crossplay_section_and_headline_from_the_case_table(tmp_path: Path) -> None:
    root = tmp_path / "runs"
    for vut in ("pi1", "pi2"):
        for seed in range(3):
            make_run(root, "car_following", vut, seed)
    make_crossplay(root / "car_following", ["pi1", "pi2"], range(3))
    html = write_report([root], options=FAST)
    text = html.read_text(encoding="utf-8")
    verdicts = text.split('id="inputs"')[0]
    assert "[crossplay mode] pi2 is safer than pi1: the pooled SPCPs bring about" in verdicts
    assert "Ranking (crossplay mode), safest first: pi2 &gt; pi1" in verdicts
    assert "Ranking (exposure mode), safest first: pi2" in verdicts
    assert "(i) Cross-play ranking" in text and "paired t-test over training-seed blocks" in text
    assert "Ranking by cross-play harm H" in text
    assert (html.parent / "car_following_crossplay_by_opponent.png").is_file()
    md = (html.parent / "summary.md").read_text(encoding="utf-8")
    assert "car_following_crossplay_by_opponent.png" in md


def test_crossplay_needs_two_vuts_and_a_table_of_these_runs(tmp_path: Path) -> None:
    from sumo_ayss.modes import analyse_case
    from sumo_ayss.run_folder import group_runs

    root = tmp_path / "runs"
    dirs = [make_run(root, "cut_in", "pi1", s) for s in range(2)]
    one = analyse_case("cut_in", group_runs([read_run(d) for d in dirs])["cut_in"], FAST)
    gap = crossplay_result(one).gap
    assert gap == CrossplayGap("one_vut", vut="pi1") and not crossplay_result(one).rows
    assert "one VUT only (pi1)" in crossplay_gap_text(gap)
    assert headline_text(one).startswith("[crossplay mode] no cross-play for this case")
    assert one.ranking_mode == "exposure" and one.verdict.kind == "warning"
    dirs += [make_run(root, "cut_in", "pi2", s) for s in range(2)]
    make_crossplay(root / "cut_in", ["pi1", "pi2"], range(3))  # a seed these runs lack
    runs = group_runs([read_run(d) for d in dirs])["cut_in"]
    stale = analyse_case("cut_in", runs, FAST, crossplay=scored_crossplay(runs))
    gap = crossplay_result(stale).gap
    assert gap is not None and stale.ranking_mode == "exposure"
    assert (gap.reason, gap.n_runs) == ("not_these_runs", 4)
    assert "is not of these runs" in crossplay_gap_text(gap)
    without = analyse_case("cut_in", runs, FAST)  # no table handed in
    gap = crossplay_result(without).gap
    assert gap == CrossplayGap("not_found")
    assert "no cross-play table for this case" in crossplay_gap_text(gap)


def test_the_loader_hands_analysis_the_crossplay_table_or_why_there_is_none(tmp_path: Path) -> None:
    """analysis/ reads no file: :func:`load_crossplay` reads the case's crossplay.csv."""
    from sumo_ayss.modes import analyse_case
    from sumo_ayss.run_folder import group_runs

    root = tmp_path / "runs"
    dirs = [make_run(root, "cut_in", v, s) for v in ("pi1", "pi2") for s in range(2)]
    runs = group_runs([read_run(d) for d in dirs])["cut_in"]
    assert scored_crossplay(runs).matrix is None and not scored_crossplay(runs).missing  # no table
    path = make_crossplay(root / "cut_in", ["pi1", "pi2"], range(2))
    stored = load_crossplay(runs)  # the reader returns the stored columns, no harm
    assert stored.table is not None and stored.path == path and "harm" not in stored.table.columns
    found = scored_crossplay(runs)
    assert found.matrix is not None and found.path == path and found.matrix.vuts == ("pi1", "pi2")
    a = analyse_case("cut_in", runs, FAST, crossplay=found)
    result = crossplay_result(a)
    assert result.matrix is found.matrix and result.path == path and result.rows
    path.write_text("vut,opponent_vut\npi1,pi1\n")
    broken = scored_crossplay(runs)
    assert broken.matrix is None and "unreadable" in broken.missing
    a = analyse_case("cut_in", runs, FAST, crossplay=broken)
    gap = crossplay_result(a).gap
    assert gap == CrossplayGap("not_found", loader=broken.missing)
    assert crossplay_gap_text(gap) == broken.missing and broken.problem in a.problems
    other = make_run(tmp_path / "elsewhere", "cut_in", "pi2", 5)
    mixed = group_runs([read_run(d) for d in [*dirs, other]])["cut_in"]
    assert "several case folders" in scored_crossplay(mixed).missing
