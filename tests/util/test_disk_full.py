"""A full disk (issue 38), on a real size-limited tmpfs in a private mount namespace: atomic
writes stop with an error naming the file and the bytes it needed and leave the old file
whole; a study stopped by a full disk resumes to the undisturbed result once space is freed
(``scripts/disk_full_drill.py``, here at its smallest)."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from scripts.ray_cluster import can_hide, unshare_argv
from tests.test_pipeline import PROJECT_ROOT

pytestmark = pytest.mark.skipif(
    not can_hide(),
    reason="no private mount namespace with a tmpfs on this machine (needs root or user "
    "namespaces): the full disk cannot be made",
)

ATOMIC = textwrap.dedent(
    """
    import json, os, subprocess, sys
    from pathlib import Path
    from sumo_ayss.util.atomic import atomic_write_bytes, atomic_write_text, atomic_write_with
    from sumo_ayss.util.errors import DiskFullError
    fs = Path(sys.argv[1])
    subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(fs)], check=True)
    target = fs / "table.csv"
    atomic_write_text(target, "old,content\\n")
    out = {}
    for name, write in [
        ("bytes", lambda: atomic_write_bytes(target, b"x" * 102400)),
        ("with", lambda: atomic_write_with(target, lambda t: t.write_bytes(b"y" * 102400))),
    ]:
        try:
            write()
            out[name] = None
        except DiskFullError as e:
            out[name] = str(e)
    out["old"] = target.read_text()
    out["files"] = sorted(p.name for p in fs.iterdir())
    # A run folder coming back from a Ray task that does not fit: the one there stays whole.
    from sumo_ayss.grid.ray_backend import pack, unpack
    src = Path(sys.argv[2])
    (src / "ckpt").mkdir(parents=True)
    (src / "ckpt" / "model.zip").write_bytes(os.urandom(102400))
    run = fs / "run"
    atomic_write_text(run / "eval.csv", "step\\n1\\n")
    try:
        unpack(pack(src), run)
        out["unpack"] = None
    except DiskFullError as e:
        out["unpack"] = str(e)
    out["run"] = sorted(str(p.relative_to(fs)) for p in fs.rglob("*"))
    print(json.dumps(out))
    """
)


def test_atomic_write_on_a_full_disk_names_file_and_bytes_and_keeps_the_old(
    tmp_path: Path,
) -> None:
    fs = tmp_path / "fs"
    fs.mkdir()
    done = subprocess.run(
        [*unshare_argv(), sys.executable, "-c", ATOMIC, str(fs), str(tmp_path / "src")],
        cwd=PROJECT_ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    out = json.loads(done.stdout.splitlines()[-1])
    for name in ("bytes", "with"):
        assert out[name] is not None, f"atomic_write_{name} did not raise DiskFullError"
        assert f"no space left on the file system of {fs}/table.csv" in out[name]
        assert "the file needs 102,400 bytes" in out[name]  # measured for the writer too
        assert "rerun the same command" in out[name]
    assert out["old"] == "old,content\n"  # the file written before is whole
    assert out["files"] == ["table.csv"]  # no temporary left behind
    assert out["unpack"] is not None, "unpack did not raise DiskFullError"
    assert (
        f"no space left on the file system of {fs}/run: the file needs 102,400 bytes"
        in (out["unpack"])
    )
    assert out["run"] == ["run", "run/eval.csv", "table.csv"]  # untouched, nothing half-done


@pytest.mark.sumo
@pytest.mark.timeout(900)  # three tiny one-job pipelines: ~1-2 min on 2 busy cores
def test_study_on_a_full_disk_stops_clearly_and_resumes_equal(tmp_path: Path) -> None:
    work = tmp_path / "drill"
    done = subprocess.run(
        [
            sys.executable,
            "scripts/disk_full_drill.py",
            "--work",
            str(work),
            "--vuts",
            "pi1",
            "--seeds",
            "0",
            "--n-outcome",
            "10",
            "--fractions",
            "0.3",
        ],
        cwd=PROJECT_ROOT,
        capture_output=True,
        text=True,
        timeout=880,
    )
    summary = json.loads((work / "disk_full_drill.json").read_text())
    (r,) = summary["fractions"]
    assert r["exit"] == 1 and r["error"].startswith("error: no space left on the file system of")
    assert r["read_back"]["checked"] > 0 and r["read_back"]["unreadable"] == []
    assert r["rerun_exit"] == 0 and r["differ"] == []
    assert done.returncode == 0, done.stdout[-3000:]
