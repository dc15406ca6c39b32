"""benchmarks/leaderboard_load.py: the /proc reading of a process tree and the stages cut
from the stamped log (synthetic input), and the CPU accounting on a real process tree."""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
import time
from pathlib import Path
from types import ModuleType

import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "benchmarks" / "leaderboard_load.py"


@pytest.fixture(scope="module")
def load() -> ModuleType:
    spec = importlib.util.spec_from_file_location("leaderboard_load", SCRIPT)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["leaderboard_load"] = module  # dataclasses look their module up
    spec.loader.exec_module(module)
    return module


def _stat(pid: int, comm: str, ppid: int, ticks: tuple[int, int, int, int], rss: int) -> str:
    # fields 3.. of /proc/<pid>/stat: state ppid pgrp session tty tpgid flags minflt cminflt
    # majflt cmajflt utime stime cutime cstime priority nice threads itrealvalue starttime
    # vsize rss ...
    rest = ["S", ppid, 0, 0, 0, 0, 0, 0, 0, 0, 0, *ticks, 20, 0, 1, 0, 0, 0, rss, 0]
    return f"{pid} ({comm}) " + " ".join(str(x) for x in rest) + "\n"


def test_read_tree_sums_the_tree_only(load: ModuleType, tmp_path: Path) -> None:
    procs = {
        10: ("python", 1, (100, 20, 300, 40), 1000),  # root; a reaped child in cutime
        11: ("python (worker) x", 10, (50, 5, 0, 0), 2000),  # parentheses in its name
        12: ("sumo", 11, (7, 3, 0, 0), 500),
        13: ("other", 1, (999, 999, 999, 999), 99999),  # not in the tree
    }
    for pid, (comm, ppid, ticks, rss) in procs.items():
        (tmp_path / str(pid)).mkdir()
        (tmp_path / str(pid) / "stat").write_text(_stat(pid, comm, ppid, ticks, rss))
    (tmp_path / "self").mkdir()  # not a pid: ignored
    (tmp_path / "14").mkdir()  # vanished between listdir and read: skipped
    rss_mib, cpu_s, n = load.read_tree(10, tmp_path)
    tick, page = os.sysconf("SC_CLK_TCK"), os.sysconf("SC_PAGE_SIZE")
    assert n == 3
    assert cpu_s == pytest.approx((460 + 55 + 10) / tick)
    assert rss_mib == pytest.approx(3500 * page / 2**20)


def test_a_reaped_grandchild_stays_counted(load: ModuleType) -> None:
    # A child burns ~0.6 s of CPU in a grandchild, waits for it, then sleeps: the tree's CPU
    # counter must still hold the grandchild's time (in the child's cutime).
    burn = "import time; t = time.process_time(); exec('while time.process_time() - t < 0.6: pass')"
    code = (
        "import subprocess, sys, time; "
        f"subprocess.run([sys.executable, '-c', {burn!r}], check=True); time.sleep(30)"
    )
    child = subprocess.Popen([sys.executable, "-c", code])
    try:
        deadline = time.monotonic() + 20
        cpu = 0.0
        while time.monotonic() < deadline:
            _, cpu, n = load.read_tree(child.pid)
            if n == 1 and cpu >= 0.6:  # the grandchild is gone, its time is kept
                break
            time.sleep(0.1)
        assert n == 1
        assert cpu >= 0.6
    finally:
        child.kill()
        child.wait()


def _events() -> list[tuple[float, str]]:
    return [
        (2.0, "x: 8 jobs on 2 worker processes; each job logs to <run folder>/job.log"),
        (3.0, "x: [0/8 done; ETA (then discriminability, cross-play, the report)] a: started"),
        (10.0, "x: grid finished: 8 done, 0 failed, 8 s wall"),
        (11.0, "x: cross-play car_following: SPCP a/seed_0 vs SPCP b: 200 episodes"),
        (12.0, "x: cross-play car_following: SPCP b/seed_0 vs SPCP a: 200 episodes"),
        (20.0, "x: adaptive seeding, car_following: not settled at 4 seeds per VUT (F gate p"),
        (20.5, "x: adaptive seeding, car_following: adding seed 4 for every VUT"),
        (21.0, "x: 2 jobs on 2 worker processes; each job logs to <run folder>/job.log"),
        (30.0, "x: cross-play car_following: SPCP a/seed_4 vs SPCP b: 200 episodes"),
        (32.0, "x: adaptive seeding, car_following: settled at 5 seeds per VUT (F gate p"),
        (33.0, "x: discriminability of car_following: one-step responses of 2 VUTs"),
        (40.0, "x: report: analysing 10 run folders and drawing the figures"),
        (50.0, "x: report written to out/report/index.html"),
    ]


def test_segments_cut_the_run_at_the_stage_lines(load: ModuleType) -> None:
    samples = [load.Sample(t, 100.0 + t, 2.0 * t, 3) for t in range(0, 55)]
    segs = load.segments(_events(), samples, end_s=55.0, total_cpu_s=120.0)
    assert [(s.stage, s.start_s, s.stop_s) for s in segs] == [
        ("setup", 0.0, 2.0),
        ("grid", 2.0, 11.0),
        ("cross-play", 11.0, 20.0),
        ("adaptive look", 20.0, 21.0),
        ("grid", 21.0, 30.0),
        ("cross-play", 30.0, 32.0),
        ("adaptive look", 32.0, 33.0),
        ("discriminability", 33.0, 40.0),
        ("report", 40.0, 50.0),
        ("ranking", 50.0, 55.0),
    ]
    grid = segs[1]
    assert (grid.jobs, grid.cells) == (8, 0)
    assert grid.cpu_s == pytest.approx(18.0)  # counter 4 -> 22
    assert grid.peak_mib == pytest.approx(110.0)  # samples at 2..10 s
    assert grid.plateau_mib == pytest.approx(106.0)
    assert (segs[2].cells, segs[4].jobs, segs[5].cells) == (2, 2, 1)
    assert segs[-1].cpu_s == pytest.approx(120.0 - 100.0)  # the last: to RUSAGE_CHILDREN
    rows = {r["stage"]: r for r in load.by_stage(segs, samples)}
    assert rows["grid"]["segments"] == 2
    assert rows["grid"]["jobs"] == 10
    assert rows["grid"]["wall_s"] == pytest.approx(18.0)
    assert rows["cross-play"]["cells"] == 3
    assert rows["cross-play"]["cpu_s"] == pytest.approx(22.0)
    assert sum(r["cpu_s"] for r in rows.values()) == pytest.approx(120.0)
    assert load.adaptive_lines(_events()) == {
        "car_following": ["not settled at 4", "added seed 4", "settled at 5"]
    }


def test_the_varied_set_has_twelve_vuts_without_an_action_step(load: ModuleType) -> None:
    vuts = load.varied_vuts()
    assert len(vuts) == 12
    for spec in vuts.values():
        assert spec is None or "actionStepLength" not in spec.get("params", {})


def test_a_cross_play_row_costs_more_than_its_floats(load: ModuleType) -> None:
    sizes = load.row_bytes(2000)
    assert 33 * 24 < sizes["rows_b_per_row"] <= sizes["peak_b_per_row"] < 10_000


def test_analyse_a_run_still_going(load: ModuleType, tmp_path: Path) -> None:
    # No run.json yet: the stages so far, the last cut at the last sample; files written.
    load.write_config(tmp_path, 2, [1], "verdict", "varied")
    (tmp_path / "events.tsv").write_text("".join(f"{t}\t{line}\n" for t, line in _events()[:4]))
    rows = "".join(f"{t},{100 + t},{2.0 * t},3\n" for t in range(0, 20))
    (tmp_path / "samples.csv").write_text("t_s,rss_mib,cpu_s,n_procs\n" + rows)
    result = load.analyse(tmp_path)
    assert [r["stage"] for r in result["stages"]] == ["setup", "grid", "cross-play"]
    assert result["stages"][2]["cpu_s"] == pytest.approx(38.0 - 22.0)  # 11 s -> 19 s
    assert (tmp_path / "stages.csv").read_text().startswith("stage,segments,wall_s,cpu_s")
