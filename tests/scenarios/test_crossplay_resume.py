"""Cross-play interrupted mid-case resumes from its finished cells (issue 38), real SUMO."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from sumo_ayss.config import AyssConfig, load_experiment
from sumo_ayss.crossplay import case_runs, run_case
from sumo_ayss.evaluate import evaluate_run
from sumo_ayss.run_folder import CaseFolder
from sumo_ayss.scenarios.outcome import DEFAULT_OUTCOME_SEED
from sumo_ayss.train import train
from sumo_ayss.vuts.reference_types import DEFAULT_REFERENCE
from tests.helpers import tiny_experiment

N = 6


class _StopAfter:
    """A progress callback that records every line and interrupts (as Ctrl-C does) at the
    ``stop``-th line whose text starts with ``prefix``."""

    def __init__(self, stop: int | None = None, prefix: str = "") -> None:
        self.lines: list[str] = []
        self.stop, self.prefix = stop, prefix

    def __call__(self, line: str) -> None:
        self.lines.append(line)
        hits = [x for x in self.lines if x.startswith(self.prefix)]
        if self.stop is not None and len(hits) == self.stop:
            raise KeyboardInterrupt

    def kept(self, prefix: str = "") -> int:
        return sum(
            x.startswith(prefix) and x.endswith("kept from an earlier run") for x in self.lines
        )

    def driven(self, prefix: str = "") -> int:
        return sum(x.startswith(prefix) and "crashes" in x for x in self.lines)


@pytest.mark.sumo
def test_an_interrupted_crossplay_resumes_from_its_finished_cells(tmp_path: Path) -> None:
    exp = tmp_path / "tiny.yaml"
    exp.write_text(yaml.safe_dump(tiny_experiment()))
    out = tmp_path / "runs"
    for vut in ("pi1", "pi2"):
        train(load_experiment(exp).with_vut(vut), seed=0, out=out)
        evaluate_run(
            out / "car_following" / vut / "seed_0",
            n_outcome=N,
            ayss=AyssConfig(n_samples=200),
            progress=False,
        )
    runs = case_runs(out, "car_following", ["pi1", "pi2"], [0])
    folder = CaseFolder(out / "car_following")

    def cross(progress: _StopAfter) -> Path:
        return run_case(runs, folder.path, n=N, seed=DEFAULT_OUTCOME_SEED, progress=progress)

    whole = _StopAfter()
    cross(whole)  # undisturbed: 4 cells, then the reference driver against 2 opponents
    assert whole.driven() == 6 and whole.kept() == 0
    undisturbed = {
        p.name: p.read_bytes() for p in (folder.crossplay_csv, folder.crossplay_reference_csv)
    }
    for p in (folder.crossplay_csv, folder.crossplay_json, folder.crossplay_reference_csv):
        p.unlink()

    first = _StopAfter(stop=2)  # killed after the second of the four cells
    with pytest.raises(KeyboardInterrupt):
        cross(first)
    assert not folder.crossplay_csv.exists()
    assert len(list(folder.crossplay_partial.glob("cell_*.csv"))) == 2

    second = _StopAfter(stop=1, prefix=DEFAULT_REFERENCE)  # then in the reference cells
    with pytest.raises(KeyboardInterrupt):
        cross(second)
    assert (second.kept("pi"), second.driven("pi")) == (2, 2)  # only the unfinished cells
    assert not folder.crossplay_csv.exists()  # written after the reference drivers' table
    assert len(list(folder.crossplay_partial.glob("cell_*.csv"))) == 4
    assert len(list(folder.crossplay_reference_partial.glob("cell_*.csv"))) == 1

    third = _StopAfter()
    cross(third)
    assert (third.kept("pi"), third.driven("pi")) == (4, 0)
    assert (third.kept(DEFAULT_REFERENCE), third.driven(DEFAULT_REFERENCE)) == (1, 1)
    assert folder.crossplay_csv.read_bytes() == undisturbed["crossplay.csv"]
    assert folder.crossplay_reference_csv.read_bytes() == undisturbed["crossplay_reference.csv"]
    assert not folder.crossplay_partial.exists()  # removed once the tables are written
    assert not folder.crossplay_reference_partial.exists()
    assert folder.inevitable_json.is_file()
