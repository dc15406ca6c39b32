"""Cross-play's cells on the worker pool (issue 40): the same tables as one process, a resume
from the cells the parent recorded, a worker's error naming its cell. Real SUMO."""

from __future__ import annotations

import json
import re
from collections.abc import Iterator, Sequence
from pathlib import Path

import pytest
import yaml

from sumo_ayss.config import AyssConfig, load_experiment
from sumo_ayss.crossplay import case_runs, run_case
from sumo_ayss.evaluate import evaluate_run
from sumo_ayss.grid.cells import CellPool, cell_pool
from sumo_ayss.run_folder import CaseFolder, RunRecord
from sumo_ayss.scenarios.crossplay import CellDone, CellTask, Opponent, drive_cell, run_crossplay
from sumo_ayss.scenarios.outcome import DEFAULT_OUTCOME_SEED
from sumo_ayss.train import train
from sumo_ayss.util.errors import CheckpointError, ConfigError
from sumo_ayss.vuts.controller_spec import controller_imports
from tests.helpers import tiny_experiment

N = 6


class _Lines:
    """A progress callback that records every line and interrupts (as Ctrl-C does) at the
    ``stop``-th line."""

    def __init__(self, stop: int | None = None, pool: CellPool | None = None) -> None:
        self.lines: list[str] = []
        self.stop, self.pool = stop, pool
        self.pids: list[int] = []

    def __call__(self, line: str) -> None:
        self.lines.append(line)
        if len(self.lines) == self.stop:
            self.pids = _worker_pids(self.pool) if self.pool is not None else []
            raise KeyboardInterrupt

    def count(self, text: str) -> int:
        return sum(text in x for x in self.lines)


def _worker_pids(pool: CellPool) -> list[int]:
    return list(pool._pool._processes)  # type: ignore[union-attr]  # CPython's worker table


def _untimed(line: str) -> str:
    """A progress line without its seconds."""
    return re.sub(r" \([0-9.]+ s\)$", "", line)


def _outputs(folder: CaseFolder) -> dict[str, object]:
    """The case's tables as bytes, and its record without the wall time."""
    record = json.loads(folder.crossplay_json.read_text())
    assert record.pop("wall_s") > 0
    return {
        "crossplay.csv": folder.crossplay_csv.read_bytes(),
        "crossplay_reference.csv": folder.crossplay_reference_csv.read_bytes(),
        "crossplay.json": record,
    }


def _remove_outputs(folder: CaseFolder) -> None:
    for p in (folder.crossplay_csv, folder.crossplay_json, folder.crossplay_reference_csv):
        p.unlink()


@pytest.fixture(scope="module")
def tiny_runs(tmp_path_factory: pytest.TempPathFactory) -> list[RunRecord]:
    """Two VUTs, one seed each, trained and evaluated on N outcome scenarios."""
    tmp = tmp_path_factory.mktemp("cells")
    exp = tmp / "tiny.yaml"
    exp.write_text(yaml.safe_dump(tiny_experiment()))
    out = tmp / "runs"
    for vut in ("pi1", "pi2"):
        train(load_experiment(exp).with_vut(vut), seed=0, out=out)
        evaluate_run(
            out / "car_following" / vut / "seed_0",
            n_outcome=N,
            ayss=AyssConfig(n_samples=200),
            progress=False,
        )
    return case_runs(out, "car_following", ["pi1", "pi2"], [0])


def _cross(runs: list[RunRecord], progress: _Lines, pool: CellPool | None, **kw: bool) -> Path:
    folder = runs[0].path.parents[1]
    return run_case(
        runs, folder, n=N, seed=DEFAULT_OUTCOME_SEED, progress=progress, pool=pool, **kw
    )


@pytest.mark.sumo
def test_cells_on_two_workers_write_the_one_process_tables_and_resume(
    tiny_runs: list[RunRecord],
) -> None:
    folder = CaseFolder(tiny_runs[0].path.parents[1])
    here = _Lines()
    _cross(tiny_runs, here, None)  # workers=1: today's path, in this process
    assert here.count("crashes (") == 6  # 4 cells, then the reference driver's 2
    one_process = _outputs(folder)
    _remove_outputs(folder)

    with cell_pool(2) as pool:
        assert isinstance(pool, CellPool)
        pooled = _Lines()
        _cross(tiny_runs, pooled, pool)
        assert _outputs(folder) == one_process  # byte-identical tables, same record
        assert sorted(map(_untimed, pooled.lines)) == sorted(map(_untimed, here.lines))
        assert len(_worker_pids(pool)) == 2  # the cells ran on two processes

        _remove_outputs(folder)
        killed = CellPool(2)
        stop = _Lines(stop=2, pool=killed)  # killed after the second cell came back
        with pytest.raises(KeyboardInterrupt), killed:
            _cross(tiny_runs, stop, killed)
        assert not folder.crossplay_csv.exists()
        assert len(list(folder.crossplay_partial.glob("cell_*.csv"))) == 2  # the parent's
        assert len(stop.pids) == 2  # and the killed pool's workers are gone
        assert not any(Path(f"/proc/{p}").exists() for p in stop.pids)

        resumed = _Lines()
        _cross(tiny_runs, resumed, pool)
    assert resumed.count("kept from an earlier run") == 2 and resumed.count("crashes (") == 4
    assert _outputs(folder) == one_process
    assert not folder.crossplay_partial.exists()


@pytest.mark.sumo
def test_a_workers_error_is_raised_with_its_type_naming_the_cell(
    tiny_runs: list[RunRecord],
) -> None:
    spcp = tiny_runs[1].folder.spcp_zip  # pi2's SPCP, unreadable
    saved = spcp.read_bytes()
    spcp.write_bytes(b"not a zip")
    try:
        with pytest.raises(CheckpointError) as here, cell_pool(1) as none:
            _cross(tiny_runs, _Lines(), none, force=True)
        with pytest.raises(CheckpointError) as pooled, cell_pool(2) as pool:
            _cross(tiny_runs, _Lines(), pool, force=True)
    finally:
        spcp.write_bytes(saved)
    assert str(here.value).startswith("cross-play cell pi1 vs SPCP pi2/seed_0: ")
    assert "not a saved policy" in str(here.value)
    assert "vs SPCP pi2/seed_0: " in str(pooled.value)  # whichever cell met it first
    assert str(pooled.value).split(": ", 1)[1] == str(here.value).split(": ", 1)[1]


class _Refuse:
    """A runner that records the tasks handed to it and drives none."""

    def drive(self, tasks: Sequence[CellTask]) -> Iterator[CellDone]:
        self.tasks = list(tasks)
        raise _Handed


class _Handed(Exception):
    pass


@pytest.mark.sumo
def test_a_worker_drives_under_the_callers_trust(tmp_path: Path) -> None:
    """An untrusted caller's cells carry its trust to the worker, which refuses to run the
    run folder's controller (as the caller's own process would)."""
    exp = tmp_path / "exp.yaml"
    exp.write_text(
        "env:\n  vut: p\n  vuts:\n    p:\n      process:\n"
        "        command: [python, client.py]\n        signals: [speed_mps, gap_m]\n"
        "        max_accel_mps2: 3.0\n        max_decel_mps2: 6.0\n"
    )
    cfg = load_experiment(exp).env
    opponent = Opponent("p", 0, lambda env: None, "sha")
    runner = _Refuse()
    with controller_imports(False), pytest.raises(_Handed):
        run_crossplay({"p": cfg}, [opponent], n=2, seed=1, reference=None, runner=runner)
    (task,) = runner.tasks
    assert not task.trusted
    with pytest.raises(ConfigError, match=r"^cross-play cell p vs SPCP p/seed_0: .*--trust-contr"):
        drive_cell(task)  # what the worker runs, in a process that trusts by default
