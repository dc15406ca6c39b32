"""Evaluate a trained run's SPCP: overall safety outcome, then Monte Carlo AYSS.

    python -m sumo_ayss.evaluate runs/car_following/pi1/seed_0
    python -m sumo_ayss.evaluate <run_dir> --n-outcome 200 --n-ayss 100000 --seed 4242 --force

Reads ``<run>/config.yaml`` (the resolved configuration and the ``seed``) and the
selected policy ``<run>/spcp.zip``, and writes into the run folder:

    outcome.csv   one row per outcome episode   (sumo_ayss.run_folder.OUTCOME_SCHEMA)
    outcome.json  crash / lane-change rates, mean reward and final headway with 95 % CIs
    ayss.csv      one row per kept AYSS sample  (sumo_ayss.run_folder.AYSS_SCHEMA)
    ayss_bins.csv the same samples as moments per 1/32 m headway cell (committed where
                  ayss.csv is not: sumo_ayss.run_folder.ayss_bins)
    ayss.json     filter counts, throughput, the Monte Carlo settings, mean indicator

(file names, writers and readers: :mod:`sumo_ayss.run_folder`).

Both stages run in one env, so in one SUMO simulation (libsumo allows one per process). A
stage whose CSV and JSON both exist is skipped unless ``--force``; a skipped stage whose
stored settings differ from the requested ones is reported in the log (the stage contract,
:class:`~sumo_ayss.run_folder.OutcomeStage` and :class:`~sumo_ayss.run_folder.AyssStage`).
``--seed`` fixes the outcome scenario set and the AYSS draws; keep it the same for every run
that is compared.
"""

from __future__ import annotations

import argparse
import dataclasses
import logging
import sys
import time
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sumo_ayss.analysis.ayss_cells import cells_of
from sumo_ayss.cli import prog
from sumo_ayss.config import DEFAULT_AYSS_SEED, AyssConfig, to_dict
from sumo_ayss.envs import make_env
from sumo_ayss.envs.pair_env import PairEnv
from sumo_ayss.grid.threads import set_torch_threads
from sumo_ayss.records.table import Table, read_table, write_table
from sumo_ayss.run_folder import (
    AYSS_SCHEMA,
    RunRecord,
    StageHeader,
    read_run,
    write_ayss_json,
    write_outcome_json,
)
from sumo_ayss.run_folder.ayss_bins import AyssCells, write_ayss_bins
from sumo_ayss.scenarios.ayss import run_ayss
from sumo_ayss.scenarios.outcome import (
    DEFAULT_OUTCOME_N,
    DEFAULT_OUTCOME_SEED,
    OutcomeResult,
    run_outcome,
    supporting_pov_summary,
)
from sumo_ayss.scenarios.preventability import DEFAULT_REFERENCE, label_crashes
from sumo_ayss.scenarios.rollout import Policy
from sumo_ayss.stages import AyssStage, OutcomeStage, is_done
from sumo_ayss.util.errors import AyssError
from sumo_ayss.util.paths import portable_path
from sumo_ayss.vuts.catalog import controller_imports
from sumo_ayss.vuts.reference_types import REFERENCE_VUTS

__all__ = ["EvaluationResult", "evaluate_run", "main"]

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class EvaluationResult:
    """Files of an evaluated run and which stages ran now (False: skipped, outputs existed)."""

    run_dir: Path
    outcome_csv: Path
    outcome_json: Path
    ayss_csv: Path
    ayss_json: Path
    ran_outcome: bool
    ran_ayss: bool


def _header(run: RunRecord) -> StageHeader:
    env = run.experiment.env
    step = run.spcp.step if run.spcp is not None else None
    return StageHeader(portable_path(run.path), env.case, env.vut, run.config_seed, step)


def _should_run(stage: OutcomeStage | AyssStage, force: bool) -> bool:
    """Whether a stage of the CLI runs: when forced or its outputs are missing. A stage
    whose outputs exist is skipped, with a warning when they were made with other settings
    (:func:`~sumo_ayss.run_folder.is_done`)."""
    if force or not all(p.is_file() for p in stage.outputs):
        return True
    logger.info("skipping %s: outputs exist (pass --force to recompute)", stage.outputs[0].name)
    if not is_done(stage):
        logger.warning(
            "%s was computed with %s, not the requested %s; pass --force to recompute",
            stage.outputs[1].name,
            stage.stored(),
            stage.settings(),
        )
    return False


def _outcome_stage(
    env: PairEnv, policy: Policy, run: RunRecord, n: int, seed: int, progress: bool
) -> OutcomeResult:
    """The outcome rollouts (written by :func:`_write_outcome` once labelled)."""
    if seed == run.experiment.train.eval_seed:
        logger.warning(
            "outcome seed %d equals train.eval_seed: the SPCP is scored on the scenarios it "
            "was selected on",
            seed,
        )
    return run_outcome(env, policy, n=n, seed=seed, progress=progress)


def _per_pov(result: OutcomeResult) -> dict[str, Any] | None:
    """``outcome.json``'s sections of a case with a second POV (issue 39), else None."""
    support = supporting_pov_summary(result.episodes)
    return None if support is None else {"supporting_pov": support}


def _write_outcome(
    run: RunRecord, result: OutcomeResult, n: int, seed: int, reference: str | None
) -> None:
    """Label the crashes (a replay each, with ``reference`` in the VUT's place; None: no
    labels) and write ``outcome.csv`` and ``outcome.json``."""
    if reference is not None:
        t0 = time.perf_counter()
        labels = label_crashes(
            run.experiment.env,
            result.scenarios,
            [e.collided for e in result.episodes],
            [e.actions for e in result.episodes],
            sumo_seed=run.config_seed,
            reference=reference,
        )
        result = result.labelled(labels)
        crashed = labels[~np.isnan(labels)]
        logger.info(
            "outcome: %d crashes replayed with %s: %d preventable, %d unpreventable (%.1f s)",
            crashed.size,
            reference,
            int((crashed == 1.0).sum()),
            int((crashed == 0.0).sum()),
            time.perf_counter() - t0,
        )
    folder = run.folder
    write_table(folder.outcome_csv, result.table)
    write_outcome_json(
        folder.outcome_json,
        _header(run),
        {"n": n, "seed": seed},
        to_dict(run.experiment.env.odd),
        result.summary.as_dict(),
        result.wall_s,
        _per_pov(result),
    )
    s = result.summary
    logger.info(
        "outcome: crash rate %.3f [%.3f, %.3f], mean return %.3f",
        s.crash_rate.value,
        s.crash_rate.lo,
        s.crash_rate.hi,
        s.mean_return.mean,
    )


def _ayss_stage(
    env: PairEnv, policy: Policy, run: RunRecord, cfg: AyssConfig, progress: bool
) -> None:
    result = run_ayss(env, policy, cfg, progress=progress)
    folder = run.folder
    write_table(folder.ayss_csv, result.table)
    table = result.table
    _write_cells(folder.ayss_bins, table, result.indicator_name)
    summary = result.summary()
    settings = summary.pop("config")  # the AyssConfig used, compared on a later skip
    write_ayss_json(folder.ayss_json, _header(run), settings, summary)
    logger.info(
        "ayss: kept %d of %d samples in %.1f s", len(result.table), cfg.n_samples, result.wall_s
    )


def _write_cells(path: Path, samples: Table, indicator_name: str | None) -> None:
    """``ayss_bins.csv`` of an ``ayss.csv`` table: its samples as per-cell moments."""
    c = cells_of(samples["h_m"], samples["indicator"])
    write_ayss_bins(path, AyssCells(c.h_low_m, c.h_high_m, c.n, c.mean, c.m2, indicator_name))


def backfill_ayss_bins(ayss_csv: Path, ayss_bins: Path) -> bool:
    """Write ``ayss_bins`` from an existing ``ayss_csv`` that has none beside it (a run
    evaluated before the evaluate stage wrote it): the stage's own reduction, no simulation
    (``ayss.csv`` stores every float exactly, so the file is the one the stage writes).

    Returns:
        Whether it wrote the file.
    """
    if ayss_bins.is_file() or not ayss_csv.is_file():
        return False
    table = read_table(ayss_csv, AYSS_SCHEMA)
    names = Counter(str(v) for v in table["indicator_name"])
    _write_cells(ayss_bins, table, names.most_common(1)[0][0] if names else None)
    return True


def evaluate_run(
    run: str | Path | RunRecord,
    *,
    n_outcome: int = DEFAULT_OUTCOME_N,
    outcome_seed: int = DEFAULT_OUTCOME_SEED,
    ayss: AyssConfig | None = None,
    force: bool = False,
    progress: bool = True,
    policy: Policy | None = None,
    trust_controller: bool = False,
    reference: str | None = DEFAULT_REFERENCE,
) -> EvaluationResult:
    """Run the outcome and AYSS stages on a run folder (see the module docstring).

    Args:
        run: The run, as read by :func:`~sumo_ayss.run_folder.read_run` (or its folder,
            written by :func:`sumo_ayss.training.trainer.train`, read here).
        n_outcome: Outcome episodes (paper: 200).
        outcome_seed: Seed of the outcome scenario set (same for every compared run).
        ayss: Monte Carlo settings; default :class:`AyssConfig()` (its seed included).
        force: Recompute stages whose outputs exist.
        progress: tqdm progress bars.
        policy: Use this policy instead of ``<run>/spcp.zip`` (e.g. a scripted one).
        trust_controller: Allow importing the run's user-controller VUT (runs its code); a
            run whose VUT is a controller cannot be evaluated without it.
        reference: The reference driver that replays every outcome crash to label it
            preventable or not (:mod:`sumo_ayss.scenarios.preventability`); None: no labels.

    Returns:
        The output paths and which stages ran.

    Raises:
        CheckpointError: If the run folder, its config or its SPCP cannot be read.
    """
    record = run if isinstance(run, RunRecord) else read_run(run)
    with controller_imports(trust_controller):
        return _evaluate_run(
            record, n_outcome, outcome_seed, ayss, force, progress, policy, reference
        )


def _evaluate_run(
    run: RunRecord,
    n_outcome: int,
    outcome_seed: int,
    ayss: AyssConfig | None,
    force: bool,
    progress: bool,
    policy: Policy | None,
    reference: str | None,
) -> EvaluationResult:
    cfg = run.experiment  # raises if config.yaml is missing or invalid
    ayss_cfg = ayss if ayss is not None else AyssConfig()
    f = run.folder
    backfill_ayss_bins(f.ayss_csv, f.ayss_bins)  # evaluated before ayss_bins.csv existed
    do_outcome = _should_run(OutcomeStage(f, n_outcome, outcome_seed), force)
    do_ayss = _should_run(AyssStage(f, ayss_cfg), force)
    outcome: OutcomeResult | None = None
    if do_outcome or do_ayss:
        env = make_env(cfg.env, sumo_seed=run.config_seed)
        try:
            if policy is None:
                from sumo_ayss.agents.weights import load_spcp  # torch: only when needed

                policy = load_spcp(run, env)
            pol = policy
            if do_outcome:
                outcome = _outcome_stage(env, pol, run, n_outcome, outcome_seed, progress)
            if do_ayss:
                _ayss_stage(env, pol, run, ayss_cfg, progress)
        finally:
            env.close()
    if outcome is not None:  # the replays need the process's SUMO: after the env closed
        _write_outcome(run, outcome, n_outcome, outcome_seed, reference)
    return EvaluationResult(
        f.path, f.outcome_csv, f.outcome_json, f.ayss_csv, f.ayss_json, do_outcome, do_ayss
    )


# --------------------------------------------------------------------------- CLI


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(
        prog=prog("python -m sumo_ayss.evaluate"), description=(__doc__ or "").splitlines()[0]
    )
    parser.add_argument("run_dir", type=Path, help="run folder (holds config.yaml, spcp.zip)")
    parser.add_argument(
        "--n-outcome", type=int, default=DEFAULT_OUTCOME_N, help="outcome episodes (default 200)"
    )
    parser.add_argument(
        "--n-ayss",
        type=int,
        default=AyssConfig.n_samples,
        help=f"AYSS Monte Carlo draws before filtering (default {AyssConfig.n_samples})",
    )
    parser.add_argument(
        "--seed",
        type=int,
        default=None,
        help=f"seed of the outcome scenarios and the AYSS draws (default: outcome "
        f"{DEFAULT_OUTCOME_SEED}, AYSS {DEFAULT_AYSS_SEED}); the same for compared runs",
    )
    parser.add_argument(
        "--ayss-speeds-from-odd",
        action="store_true",
        help="sample AYSS speeds in the run's ODD instead of [0, 30] m/s",
    )
    parser.add_argument("--force", action="store_true", help="recompute existing outputs")
    parser.add_argument(
        "--trust-controller",
        action="store_true",
        help="import the run's user-controller VUT (runs code the run folder names)",
    )
    parser.add_argument(
        "--reference",
        choices=[*sorted(REFERENCE_VUTS), "none"],
        default=DEFAULT_REFERENCE,
        help="reference driver that replays every outcome crash to label it preventable or "
        f"not (default {DEFAULT_REFERENCE}; none: no labels)",
    )
    parser.add_argument("--no-progress", action="store_true", help="no progress bars")
    return parser.parse_args(argv)


def main(argv: Sequence[str] | None = None) -> None:
    args = parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(name)s: %(message)s")
    t0 = time.perf_counter()
    try:
        run = read_run(args.run_dir)  # read once, then handed on
        cfg = run.experiment
        set_torch_threads(cfg.train.torch_threads)
        overrides: dict[str, Any] = {"n_samples": args.n_ayss}
        if args.seed is not None:
            overrides["seed"] = args.seed
        if args.ayss_speeds_from_odd:
            ayss = AyssConfig.from_odd(cfg.env.odd, **overrides)
        else:
            ayss = dataclasses.replace(AyssConfig(), **overrides)
        result = evaluate_run(
            run,
            n_outcome=args.n_outcome,
            outcome_seed=args.seed if args.seed is not None else DEFAULT_OUTCOME_SEED,
            ayss=ayss,
            force=args.force,
            reference=None if args.reference == "none" else args.reference,
            progress=not args.no_progress,
            trust_controller=args.trust_controller,
        )
    except AyssError as e:
        sys.exit(f"error: {e}")
    logger.info("done in %.1f s", time.perf_counter() - t0)
    for path in (result.outcome_csv, result.outcome_json, result.ayss_csv, result.ayss_json):
        print(path)


if __name__ == "__main__":
    main()
