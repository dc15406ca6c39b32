"""Recompute the outcome tables of a study's runs with the safety-measure columns (issue 27).

    python scripts/add_measures.py STUDY_DIR [--overhead]

For every run folder under ``STUDY_DIR`` (a ``config.yaml`` beside an ``outcome.json`` and
a ``spcp.zip``), reruns the outcome stage exactly as ``python -m sumo_ayss.evaluate`` did
(same SUMO seed, scenario seed and count, from ``outcome.json``), refuses to write unless
every column of the old ``outcome.csv`` is reproduced exactly, and rewrites ``outcome.csv``
with the measure columns (``outcome.json`` is left as it is: same settings, same summary).

``--overhead`` also times each run's outcome stage with the trajectory recording switched
off (the rollout without :func:`~sumo_ayss.scenarios.trajectory.measures_of`), alternating
the two, and prints both wall times: the recording's cost.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from sumo_ayss.agents.weights import load_spcp
from sumo_ayss.envs import make_env
from sumo_ayss.records.table import write_table
from sumo_ayss.run_folder import OUTCOME_SCHEMA, RunRecord, read_run
from sumo_ayss.scenarios import rollout
from sumo_ayss.scenarios.outcome import run_outcome

#: The columns an outcome table held before the measures.
OLD_COLUMNS = [c.name for c in OUTCOME_SCHEMA.columns if c.name not in rollout.MEASURE_NAMES]


def _timed(run: RunRecord, measures: bool) -> tuple[object, float]:
    if run.outcome_record is None:
        raise SystemExit(f"{run.folder.outcome_json}: missing or unreadable")
    settings = run.outcome_record.settings
    env = make_env(run.experiment.env, sumo_seed=run.config_seed)
    original = rollout.measures_of
    if not measures:
        rollout.measures_of = lambda *a: None  # type: ignore[assignment,return-value]
    try:
        policy = load_spcp(run, env)
        t0 = time.perf_counter()
        result = run_outcome(env, policy, n=settings["n"], seed=settings["seed"])
        return result, time.perf_counter() - t0
    finally:
        rollout.measures_of = original
        env.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("study", type=Path)
    parser.add_argument("--overhead", action="store_true", help="time with/without recording")
    args = parser.parse_args()
    runs = sorted(p.parent for p in args.study.rglob("outcome.json"))
    with_s, without_s = [], []
    for run_dir in runs:
        run = read_run(run_dir)
        old = run.outcome_table
        if old is None:
            raise SystemExit(f"{run.folder.outcome_csv}: missing or unreadable")
        if args.overhead:
            _, t_off = _timed(run, measures=False)
            without_s.append(t_off)
        result, t_on = _timed(run, measures=True)
        with_s.append(t_on)
        new = result.table  # type: ignore[attr-defined]
        for col in OLD_COLUMNS:
            if not np.array_equal(old[col], new[col], equal_nan=old[col].dtype.kind == "f"):
                raise SystemExit(f"{run_dir}: column {col} not reproduced; nothing written")
        write_table(run.folder.outcome_csv, new)
        line = f"{run_dir}: {len(new)} episodes, {t_on:.2f} s with recording"
        print(line + (f", {without_s[-1]:.2f} s without" if args.overhead else ""))
    if args.overhead and with_s:
        on, off = float(np.sum(with_s)), float(np.sum(without_s))
        print(f"outcome stage, {len(runs)} runs: {off:.2f} s without recording, {on:.2f} s with")
        print(f"overhead {on - off:+.2f} s ({100 * (on - off) / off:+.1f} %)")


if __name__ == "__main__":
    main()
