"""The Ray backend against a local Ray instance started by the test."""

from __future__ import annotations

from pathlib import Path

import pytest

from sumo_ayss.commands.pipeline import run_pipeline
from sumo_ayss.grid.ray_backend import pack, unpack
from sumo_ayss.pipeline import load_pipeline
from tests.test_pipeline import write_configs


def test_pack_unpack_round_trip(tmp_path: Path) -> None:
    src = tmp_path / "a"
    (src / "sub").mkdir(parents=True)
    (src / "x.txt").write_text("x")
    (src / "sub" / "y.bin").write_bytes(bytes(range(256)))
    dst = tmp_path / "b"
    dst.mkdir()
    (dst / "stale.txt").write_text("old")  # replaced, not merged
    unpack(pack(src), dst)
    assert sorted(p.relative_to(dst).as_posix() for p in dst.rglob("*")) == [
        "sub",
        "sub/y.bin",
        "x.txt",
    ]
    assert (dst / "sub" / "y.bin").read_bytes() == bytes(range(256))
    assert pack(tmp_path / "missing") == b""


@pytest.mark.sumo
@pytest.mark.timeout(900)  # starting Ray plus two tiny jobs: ~1-3 min on 2 busy cores
def test_grid_on_a_local_ray_instance(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    ray = pytest.importorskip("ray", reason="ray is not installed (pip install 'sumo_ayss[ray]')")
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        cfg = load_pipeline(write_configs(tmp_path, [0]))
        with caplog.at_level("INFO", logger="sumo_ayss.grid.ray_backend"):
            statuses, report, *_ = run_pipeline(cfg, backend="ray", live=False)
    finally:
        ray.shutdown()
    # Every job event, as on the local backend: started and done, with the grid's counts.
    for s in statuses:
        assert f"{s.spec.name}: submitted to Ray (try 1)" in caplog.text
        assert f"{s.spec.name}: done in " in caplog.text
    assert "2/2 done, 0 running, 0 queued, 0 failed" in caplog.text
    assert "grid finished: 2 done, 0 failed" in caplog.text
    assert [s.state for s in statuses] == ["done", "done"]
    for s in statuses:  # results are back in the run folders on the driver
        for name in ("spcp.json", "eval.csv", "outcome.csv", "ayss.csv", "job.log"):
            assert (s.spec.run_dir / name).is_file(), (s.spec.name, name)
    assert report is not None and report.is_file()
