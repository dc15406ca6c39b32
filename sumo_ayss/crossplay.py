"""Cross-play stage: the pooled SPCPs of a grid against every VUT, and their ranking.

    python -m sumo_ayss.crossplay configs/ladders/time_headway.yaml [--out DIR] [--seeds ...]

After a pipeline grid (or ``python -m sumo_ayss.rank``) has trained and evaluated every
(case, VUT, seed) job, this runs every SPCP of a case against every VUT of that case on the
outcome scenarios (``evaluate.n_outcome`` of the outcome seed) and writes, per case,

* ``<out>/<case>/crossplay.csv``: one row per (VUT, opponent, scenario)
  (:data:`~sumo_ayss.run_folder.CROSSPLAY_SCHEMA`);
* ``<out>/<case>/crossplay.json``: the settings, the opponents with the SHA-256 of their
  ``spcp.zip``, the definition key of every VUT, and the wall time
  (:class:`~sumo_ayss.run_folder.CrossplayRecord`). A rerun with the same settings, VUTs and
  SPCPs skips the case (the stage contract, :class:`~sumo_ayss.run_folder.CrossplayStage`);
  a study that added, dropped, redefined or renamed a VUT, or added seeds, drives only the
  cells it does not hold yet (:mod:`sumo_ayss.stages.crossplay_cells`).

A stage interrupted mid-case resumes from the cells it finished (each kept in
``<case>/crossplay.partial/`` until the table is written: :class:`~sumo_ayss.run_folder.CellStore`).

(file names, writers and readers: :mod:`sumo_ayss.run_folder`).

It then prints the cross-play ranking (:mod:`sumo_ayss.analysis.crossplay`) and, with the
config's ``expected_order``, Kendall's τ against it. ``rank --mode crossplay`` runs this
stage itself and writes the ranking files.
"""

from __future__ import annotations

import argparse
import dataclasses
import functools
import hashlib
import logging
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from sumo_ayss.analysis.crossplay import BLOCKS
from sumo_ayss.analysis.crossplay_scoring import case_matrix
from sumo_ayss.cli import prog
from sumo_ayss.config.identity import vut_key
from sumo_ayss.records.table import Table, read_table, table_from_rows, write_table
from sumo_ayss.run_folder import (
    CROSSPLAY_SCHEMA,
    OUTCOME_SCHEMA,
    CaseFolder,
    CellStore,
    CrossplayOpponent,
    CrossplayRecord,
    RunRecord,
    StudyFolder,
    case_of,
    read_crossplay_json,
    read_inevitable,
    read_outcome_json,
    read_run,
    write_crossplay_json,
    write_inevitable,
)
from sumo_ayss.stages import CellPlan, CrossplayStage, is_done, merged_rows, plan_cells
from sumo_ayss.stages.crossplay_cells import cell_groups, kept_reference_rows, same_scenarios
from sumo_ayss.util.errors import AyssError, CheckpointError, TableError
from sumo_ayss.vuts.catalog import controller_imports
from sumo_ayss.vuts.reference_types import DEFAULT_REFERENCE

if TYPE_CHECKING:
    from sumo_ayss.scenarios.crossplay import CellRunner, Opponent

logger = logging.getLogger(__name__)


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def case_runs(out: Path, case: str, vuts: Sequence[str], seeds: Sequence[int]) -> list[RunRecord]:
    """The runs of one case of a grid, read (:func:`~sumo_ayss.run_folder.read_run`), VUTs
    then seeds in grid order.

    Raises:
        CheckpointError: If a run folder has no ``spcp.zip`` (its job did not finish).
    """
    folders = [StudyFolder(out).run(case, v, s) for v in vuts for s in seeds]
    missing = [str(f.path) for f in folders if not f.spcp_zip.is_file()]
    if missing:
        raise CheckpointError(
            f"cross-play needs every SPCP of the grid; no spcp.zip in {', '.join(missing)} "
            "(run the grid first: python -m sumo_ayss.rank <config>)"
        )
    return [read_run(f.path) for f in folders]


def run_case(
    runs: Sequence[RunRecord],
    case_dir: Path,
    *,
    n: int,
    seed: int,
    force: bool = False,
    trust_controller: bool = False,
    progress: Callable[[str], None] | None = None,
    reference: str | None = DEFAULT_REFERENCE,
    references: Sequence[str] = (DEFAULT_REFERENCE,),
    pool: CellRunner | None = None,
) -> Path:
    """Cross-play of one case's runs; writes and returns the case folder's ``crossplay.csv``.

    Skipped when the stage is done with these settings and SPCPs
    (:class:`~sumo_ayss.run_folder.CrossplayStage`), unless ``force``. Otherwise only the
    cells (VUT × opponent) that the case's recorded table does not hold are driven (a VUT
    added, redefined or renamed; new opponents: :func:`~sumo_ayss.stages.crossplay_cells.
    plan_cells`), the rest kept; the written table equals a full run's. After the rollouts,
    every SPCP's episodes against its own VUT are compared with its run's ``outcome.csv``
    (:func:`~sumo_ayss.scenarios.crossplay.diagonal_check`); the result goes into
    ``crossplay.json``.

    ``references`` (reference drivers, :data:`~sumo_ayss.vuts.reference_types.REFERENCE_VUTS`) then
    drive against the whole pool into ``crossplay_reference.csv`` (none: no file).
    ``reference`` labels every crash preventable or not
    (:mod:`sumo_ayss.scenarios.preventability`; None: no labels). It is not part of the
    stage's settings: a table made without labels is kept (``--force`` relabels).

    ``pool``: drives the cells on worker processes (:func:`sumo_ayss.grid.cells.cell_pool`,
    the pipeline's ``workers``); None: in this process. The tables are the same either way.

    Raises:
        DiagonalMismatchError: If an SPCP did not reproduce its outcome table (the table
            and the record are written first, for inspection; loaders refuse to rank it).
        TableError: If a run's outcome table is missing or was run on other scenarios.
        CheckpointError: If a run's configuration or SPCP cannot be read.
    """
    from sumo_ayss.scenarios.crossplay import (
        check_diagonal,
        check_one_world,
        diagonal_check,
        run_crossplay,
    )

    opps = tuple(
        CrossplayOpponent(r.experiment.env.vut, r.config_seed, _sha256(r.folder.spcp_zip))
        for r in runs
    )
    folder = CaseFolder(case_dir)
    case = runs[0].experiment.env.case
    envs: dict[str, Any] = {}
    for r in runs:
        envs.setdefault(r.experiment.env.vut, r.experiment.env)
    check_one_world(envs)  # also across kept and new VUTs, driven apart
    keys = tuple(vut_key(env.vut_type) for env in envs.values())
    requested = CrossplayRecord(case, n, seed, opps, tuple(envs), 0.0, vut_keys=keys)
    if not force and _done(CrossplayStage(folder, requested)):
        logger.info("%s: cross-play done with these settings and SPCPs; skipped", case_dir)
        done = read_crossplay_json(folder.crossplay_json)
        check_diagonal(done.diagonal, case)
        _reference_rows(
            runs,
            folder,
            references,
            n,
            seed,
            trust_controller,
            progress,
            reference,
            done,
            opps,
            pool,
        )
        return folder.crossplay_csv
    plan = None if force else _reusable(folder, requested)
    if plan is not None:
        to_drive = dict(plan.to_drive)
        logger.info(
            "%s: cross-play drives %d new cells (VUT x SPCP) and keeps %d%s",
            case_dir,
            plan.n_to_drive,
            plan.n_kept,
            "".join(f"; {new} is {old} renamed: its cells kept" for old, new in plan.renamed),
        )
    else:
        to_drive = {v: opps for v in envs}
    by_run = {(o.vut, o.seed): r for o, r in zip(opps, runs, strict=True)}
    own = [o for o in opps if o in to_drive.get(o.vut, ())]  # diagonal cells driven now
    outcomes = {o: _outcome_table(by_run[(o.vut, o.seed)], n, seed) for o in own}
    rows: list[Any] = [] if plan is None else list(plan.kept_rows)
    cells = CellStore.resume(folder.crossplay_partial, force=force)
    t0 = time.perf_counter()
    for group, vuts in cell_groups(to_drive).items():
        with controller_imports(trust_controller):
            part = run_crossplay(
                {v: envs[v] for v in vuts},
                _opponents(group, by_run),
                n=n,
                seed=seed,
                progress=progress,
                reference=reference,
                cells=cells,
                runner=pool,
            )
        rows += part.rows()
    wall_s = time.perf_counter() - t0 + (plan.wall_s if plan is not None else 0.0)
    table = table_from_rows(CROSSPLAY_SCHEMA, merged_rows(rows, tuple(envs), opps))
    found = {(c.vut, c.seed): c for c in (plan.kept_checks if plan is not None else ())}
    for o, out in outcomes.items():
        found[(o.vut, o.seed)] = diagonal_check(table, o.vut, o.seed, out)
    checks = tuple(found[(o.vut, o.seed)] for o in opps if (o.vut, o.seed) in found)
    # The reference table first: its cells are matched through the record written after it.
    earlier = None if force else _record(folder)
    _reference_rows(
        runs,
        folder,
        references,
        n,
        seed,
        trust_controller,
        progress,
        reference,
        earlier,
        opps,
        pool,
    )
    folder.path.mkdir(parents=True, exist_ok=True)
    write_table(folder.crossplay_csv, table)
    record = dataclasses.replace(requested, wall_s=wall_s, diagonal=checks)
    write_crossplay_json(folder.crossplay_json, record)
    cells.clear()  # the whole table is written: its cells are no longer needed
    check_diagonal(checks, case)
    return folder.crossplay_csv


def _inevitable(env: Any, folder: CaseFolder, n: int, seed: int) -> None:
    """``inevitable.json``: which of the ``n`` scenarios are inevitable-collision states
    (a second per thousand scenarios; kept when it holds this scenario set)."""
    from sumo_ayss.envs.odd import scenario_set
    from sumo_ayss.scenarios.inevitable import ics_flags, pov_strategies

    path = folder.inevitable_json
    if path.is_file():
        try:
            if read_inevitable(path)[:2] == (n, seed):
                return
        except TableError:
            pass
    flags = ics_flags(env, scenario_set(env, n, seed))
    write_inevitable(path, n, seed, flags, tuple(pov_strategies(env.case)))


def _reference_rows(
    runs: Sequence[RunRecord],
    folder: CaseFolder,
    references: Sequence[str],
    n: int,
    seed: int,
    trust_controller: bool,
    progress: Callable[[str], None] | None,
    label_with: str | None,
    earlier: CrossplayRecord | None,
    pool: tuple[CrossplayOpponent, ...],
    runner: CellRunner | None,
) -> None:
    """Drive the reference drivers against the whole pool (``crossplay_reference.csv``):
    seconds, since they need no opponents of their own. Each (reference, opponent) cell the
    file already holds is kept where its opponent is still the same SPCP (its SHA-256 in
    ``earlier``, the case's record, which is written after this file: a kill between the
    two drives a cell again, never keeps a stale one); only the others are driven, and the
    file is written in the order a run over the whole pool writes it."""
    from sumo_ayss.scenarios.crossplay import run_crossplay
    from sumo_ayss.scenarios.preventability import reference_config

    _inevitable(runs[0].experiment.env, folder, n, seed)
    path = folder.crossplay_reference_csv
    if not references:
        return
    kept = kept_reference_rows(path, references, n, seed, earlier, pool)
    cells = {(r["vut"], r["opponent_vut"], r["opponent_seed"]) for r in kept}
    to_drive = {
        name: tuple(o for o in pool if (name, o.vut, o.seed) not in cells) for name in references
    }
    to_drive = {name: opps for name, opps in to_drive.items() if opps}
    if not to_drive and len(kept) == n * len(pool) * len(references) and path.is_file():
        same = table_from_rows(CROSSPLAY_SCHEMA, merged_rows(kept, references, pool))
        if read_table(path, CROSSPLAY_SCHEMA).equals(same):
            return  # exactly these references against exactly this pool
    base = runs[0].experiment.env
    for name in references:  # one catalog holding every reference: one world for all
        base = reference_config(base, name, own_body=True)
    by_run = {(o.vut, o.seed): r for o, r in zip(pool, runs, strict=True)}
    rows = list(kept)
    store = CellStore.resume(folder.crossplay_reference_partial)
    t0 = time.perf_counter()
    for opps, names in cell_groups(to_drive).items():
        envs = {name: dataclasses.replace(base, vut=name) for name in names}
        with controller_imports(trust_controller):
            part = run_crossplay(
                envs,
                _opponents(opps, by_run),
                n=n,
                seed=seed,
                progress=progress,
                reference=label_with,
                cells=store,
                runner=runner,
            )
        rows += part.rows()
    write_table(path, table_from_rows(CROSSPLAY_SCHEMA, merged_rows(rows, references, pool)))
    store.clear()
    logger.info(
        "%s: reference drivers %s against %d opponents in %.1f s (%d cells kept)",
        folder.path,
        ", ".join(references),
        len({o for opps in to_drive.values() for o in opps}),
        time.perf_counter() - t0,
        len(cells),
    )


def _done(stage: CrossplayStage) -> bool:
    """Whether the stage is done; an unreadable record is logged and the case runs again."""
    try:
        return is_done(stage)
    except TableError as exc:
        logger.warning("%s; cross-play of %s runs again", exc, stage.folder.path)
        return False


def _record(folder: CaseFolder) -> CrossplayRecord | None:
    """The case's ``crossplay.json``, None when missing or unreadable."""
    try:
        return read_crossplay_json(folder.crossplay_json)
    except TableError:
        return None


def _reusable(folder: CaseFolder, requested: CrossplayRecord) -> CellPlan | None:
    """The cells of the case's recorded cross-play that ``requested`` keeps
    (:func:`~sumo_ayss.stages.crossplay_cells.plan_cells`), or None when there is no
    usable record (none, unreadable, other scenarios or rollout, no diagonal check)."""
    if not (folder.crossplay_csv.is_file() and folder.crossplay_json.is_file()):
        return None
    try:
        done = read_crossplay_json(folder.crossplay_json)
        if not (same_scenarios(done, requested) and done.diagonal):
            return None
        rows = read_table(folder.crossplay_csv, CROSSPLAY_SCHEMA).rows()
        return plan_cells(done, rows, requested)
    except TableError as exc:
        logger.warning("%s; cross-play of %s is driven whole", exc, folder.path)
        return None


def _opponents(
    opps: Sequence[CrossplayOpponent], by_run: dict[tuple[str, int], RunRecord]
) -> list[Opponent]:
    """The opponents to drive, each loaded from its run's ``spcp.zip`` (a small loader that
    travels to a worker process, :class:`~sumo_ayss.agents.weights.SpcpFile`)."""
    from sumo_ayss.agents.weights import SpcpFile
    from sumo_ayss.scenarios.crossplay import Opponent

    return [
        Opponent(o.vut, o.seed, SpcpFile.of(by_run[(o.vut, o.seed)]), o.spcp_sha256) for o in opps
    ]


def _outcome_table(run: RunRecord, n: int, seed: int) -> Table:
    """A run's outcome table, checked to hold the scenarios cross-play drives.

    Raises:
        TableError: If ``outcome.json`` or ``outcome.csv`` is missing or unreadable (the
            reader's own message, naming the file), or the outcome stage ran other
            scenarios.
    """
    folder = run.folder
    # What the record could not read is read again here, for the reader's own error.
    outcome = run.outcome_record or read_outcome_json(folder.outcome_json)
    settings = outcome.settings
    if (settings.get("n"), settings.get("seed")) != (n, seed):
        raise TableError(
            f"{folder.outcome_json}: the outcome stage ran n={settings.get('n')}, "
            f"seed={settings.get('seed')}; cross-play drives n={n}, seed={seed}, so its diagonal "
            "cannot be checked against it (re-run: python -m sumo_ayss.evaluate <run> --force)"
        )
    if run.outcome_table is not None:
        return run.outcome_table
    return read_table(folder.outcome_csv, OUTCOME_SCHEMA)


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(
        prog=prog("python -m sumo_ayss.crossplay"),
        description="Cross-play: every SPCP of a grid against every VUT, and the ranking.",
    )
    p.add_argument("config", help="pipeline YAML (the grid to cross-play)")
    p.add_argument("--out", default=None, help="replace the config's out")
    p.add_argument("--seeds", type=int, nargs="+", default=None, help="replace grid.seeds")
    p.add_argument("--force", action="store_true", help="rerun even when done")
    p.add_argument(
        "--workers", type=int, default=None, help="processes for the cells (default: the config's)"
    )
    p.add_argument(
        "--blocks",
        choices=BLOCKS,
        default="seed",
        help="block unit of the paired test: training seeds (default) or single opponents",
    )
    p.add_argument(
        "--trust-controller",
        action="store_true",
        help="allow importing user-controller VUTs named by the run folders (runs their code)",
    )
    return p.parse_args(argv)


def main(argv: Sequence[str] | None = None) -> None:
    """Entry point of ``python -m sumo_ayss.crossplay``."""
    import sys

    from sumo_ayss.config import load_pipeline
    from sumo_ayss.grid.cells import cell_pool

    args = parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    try:
        out = Path(args.out) if args.out is not None else None
        cfg = load_pipeline(args.config, out=out, seeds=args.seeds, workers=args.workers)
        with cell_pool(cfg.n_workers) as pool:  # one pool for every case
            for case in cfg.grid.cases:
                _main_case(cfg, case, args, pool)
    except AyssError as exc:
        sys.exit(f"error: {exc}")


def _main_case(cfg: Any, case: str, args: argparse.Namespace, pool: CellRunner | None) -> None:
    """Cross-play one case of :func:`main`'s config and print its ranking."""
    from sumo_ayss.analysis.crossplay import rank_crossplay
    from sumo_ayss.analysis.seeds import kendall_tau
    from sumo_ayss.modes.crossplay import crossplay_sentence
    from sumo_ayss.modes.formatting import seed_interval_text
    from sumo_ayss.scenarios.outcome import DEFAULT_OUTCOME_SEED

    runs = case_runs(Path(cfg.out), case, cfg.grid.vuts, cfg.seeds)
    run_case(
        runs,
        StudyFolder(cfg.out).case(case).path,
        n=cfg.evaluate.n_outcome,
        seed=DEFAULT_OUTCOME_SEED,
        force=args.force,
        trust_controller=args.trust_controller,
        progress=functools.partial(print, f"{case}:", flush=True),
        reference=cfg.evaluate.reference,
        references=cfg.evaluate.reference_rows,
        pool=pool,
    )
    found = case_of(runs)
    matrix = case_matrix(found.crossplay, found.runs)
    rows, _pairs = rank_crossplay(matrix, blocks=args.blocks)
    print(f"\n{case}: cross-play ranking, safest first (lower harm = safer)")
    for r in rows:
        crashes, episodes = matrix.crashes(r.name)
        print(
            f"  {r.rank}. {r.name}: H = {r.mean:.3f} "
            f"({seed_interval_text(r.lo, r.hi, r.n_seeds, 3)}); "
            f"crashes {crashes}/{episodes}; mean speed "
            f"{matrix.vut_mobility(r.name):.1f} m/s"
        )
        if r.vs_next is not None:
            print(f"     {crossplay_sentence(r.vs_next, args.blocks)}")
    if cfg.expected_order:
        order = [r.name for r in rows]
        print(f"  Kendall tau vs expected order: {kendall_tau(order, cfg.expected_order):.2f}")


if __name__ == "__main__":
    main()
