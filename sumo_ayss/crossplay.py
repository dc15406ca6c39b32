"""Cross-play stage: the pooled SPCPs of a grid against every VUT, and their ranking.

    python -m sumo_ayss.crossplay configs/ladders/time_headway.yaml [--out DIR] [--seeds ...]

After a pipeline grid (or ``python -m sumo_ayss.rank``) has trained and evaluated every
(case, VUT, seed) job, this runs every SPCP of a case against every VUT of that case on the
outcome scenarios (``evaluate.n_outcome`` of the outcome seed) and writes, per case,

* ``<out>/<case>/crossplay.csv``: one row per (VUT, opponent, scenario)
  (:data:`~sumo_ayss.run_folder.CROSSPLAY_SCHEMA`);
* ``<out>/<case>/crossplay.json``: the settings, the opponents with the SHA-256 of their
  ``spcp.zip``, and the wall time (:class:`~sumo_ayss.run_folder.CrossplayRecord`). A rerun
  with the same settings and SPCPs skips the case (the stage contract,
  :class:`~sumo_ayss.run_folder.CrossplayStage`).

Until the table is written whole, each finished (VUT, opponent) cell is kept as its own
file in ``<out>/<case>/crossplay.partial/`` (``crossplay_reference.partial/`` for the
reference drivers; :class:`~sumo_ayss.run_folder.CellStore`): a stage interrupted mid-case
(Ctrl-C, SIGKILL) resumes from the cells it finished, and the finished table is
byte-identical to an undisturbed run's. ``--force`` drops them.

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
from typing import Any

from sumo_ayss.analysis.crossplay import BLOCKS
from sumo_ayss.cli import prog
from sumo_ayss.run_folder import (
    CROSSPLAY_SCHEMA,
    OUTCOME_SCHEMA,
    CaseFolder,
    CellStore,
    CrossplayOpponent,
    CrossplayRecord,
    CrossplayStage,
    RunFolder,
    RunRecord,
    Table,
    case_dir_for,
    is_done,
    load_crossplay,
    read_crossplay_json,
    read_inevitable,
    read_outcome_json,
    read_run,
    read_table,
    run_dir_for,
    write_crossplay_json,
    write_inevitable,
    write_table,
)
from sumo_ayss.util.errors import AyssError, CheckpointError, TableError
from sumo_ayss.vuts.catalog import controller_imports
from sumo_ayss.vuts.reference_types import DEFAULT_REFERENCE

logger = logging.getLogger(__name__)


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def case_runs(out: Path, case: str, vuts: Sequence[str], seeds: Sequence[int]) -> list[RunRecord]:
    """The runs of one case of a grid, read (:func:`~sumo_ayss.run_folder.read_run`), VUTs
    then seeds in grid order.

    Raises:
        CheckpointError: If a run folder has no ``spcp.zip`` (its job did not finish).
    """
    folders = [RunFolder(run_dir_for(out, case, v, s)) for v in vuts for s in seeds]
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
) -> Path:
    """Cross-play of one case's runs; writes and returns the case folder's ``crossplay.csv``.

    Skipped when the stage is done with these settings and SPCPs
    (:class:`~sumo_ayss.run_folder.CrossplayStage`), unless ``force``. After the rollouts,
    every SPCP's episodes against its own VUT are compared with its run's ``outcome.csv``
    (:func:`~sumo_ayss.scenarios.crossplay.diagonal_check`); the result goes into
    ``crossplay.json``.

    ``references`` (reference drivers, :data:`~sumo_ayss.vuts.reference_types.REFERENCE_VUTS`) then
    drive against the whole pool into ``crossplay_reference.csv`` (none: no file).
    ``reference`` labels every crash preventable or not
    (:mod:`sumo_ayss.scenarios.preventability`; None: no labels). It is not part of the
    stage's settings: a table made without labels is kept (``--force`` relabels).

    Raises:
        DiagonalMismatchError: If an SPCP did not reproduce its outcome table (the table
            and the record are written first, for inspection; loaders refuse to rank it).
        TableError: If a run's outcome table is missing or was run on other scenarios.
        CheckpointError: If a run's configuration or SPCP cannot be read.
    """
    from sumo_ayss.evaluate import load_spcp
    from sumo_ayss.scenarios.crossplay import (
        Opponent,
        check_diagonal,
        diagonal_check,
        run_crossplay,
    )

    pool = tuple(
        CrossplayOpponent(r.experiment.env.vut, r.config_seed, _sha256(r.folder.spcp_zip))
        for r in runs
    )
    folder = CaseFolder(case_dir)
    case = runs[0].experiment.env.case
    requested = CrossplayRecord(case, n, seed, pool, (), 0.0)
    envs: dict[str, Any] = {}
    for r in runs:
        envs.setdefault(r.experiment.env.vut, r.experiment.env)
    if not force and _done(CrossplayStage(folder, requested)):
        logger.info("%s: cross-play done with these settings and SPCPs; skipped", case_dir)
        check_diagonal(read_crossplay_json(folder.crossplay_json).diagonal, case)
        _reference_rows(runs, folder, references, n, seed, trust_controller, progress, reference)
        return folder.crossplay_csv
    earlier = None if force else _extended(folder, requested, tuple(envs))
    if earlier is not None:
        old = set(earlier.opponents)
        to_play = [r for r, o in zip(runs, pool, strict=True) if o not in old]
        logger.info(
            "%s: cross-play of %d new SPCPs (the table of the other %d is kept)",
            case_dir,
            len(to_play),
            len(old),
        )
    else:
        to_play = list(runs)
    outcomes = {(r.experiment.env.vut, r.config_seed): _outcome_table(r, n, seed) for r in to_play}
    sha = {(o.vut, o.seed): o.spcp_sha256 for o in pool}
    opponents = [
        Opponent(
            r.experiment.env.vut,
            r.config_seed,
            functools.partial(load_spcp, r),
            sha[(r.experiment.env.vut, r.config_seed)],
        )
        for r in to_play
    ]
    cells = _cells(folder.crossplay_partial, force)
    t0 = time.perf_counter()
    with controller_imports(trust_controller):
        table = run_crossplay(
            envs, opponents, n=n, seed=seed, progress=progress, reference=reference, cells=cells
        )
    wall_s = time.perf_counter() - t0
    checks = tuple(diagonal_check(table, v, s, out) for (v, s), out in outcomes.items())
    if earlier is not None:
        table = _merged(
            read_table(folder.crossplay_csv, CROSSPLAY_SCHEMA), table, tuple(envs), pool
        )
        checks = _merged_checks(earlier.diagonal, checks, pool)
        wall_s += earlier.wall_s
    folder.path.mkdir(parents=True, exist_ok=True)
    write_table(folder.crossplay_csv, table)
    record = dataclasses.replace(requested, vuts=tuple(envs), wall_s=wall_s, diagonal=checks)
    write_crossplay_json(folder.crossplay_json, record)
    cells.clear()  # the whole table is written: its cells are no longer needed
    check_diagonal(checks, case)
    _reference_rows(runs, folder, references, n, seed, trust_controller, progress, reference)
    return folder.crossplay_csv


def _inevitable(env: Any, folder: CaseFolder, n: int, seed: int) -> None:
    """``inevitable.json``: which of the ``n`` scenarios are inevitable-collision states
    (a second per thousand scenarios; kept when it holds this scenario set)."""
    from sumo_ayss.envs.odd import sample_initial_conditions
    from sumo_ayss.scenarios.inevitable import ics_flags, pov_strategies

    path = folder.inevitable_json
    if path.is_file():
        try:
            if read_inevitable(path)[:2] == (n, seed):
                return
        except TableError:
            pass
    flags = ics_flags(env, sample_initial_conditions(env.odd, n, seed))
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
) -> None:
    """Drive the reference drivers against the whole pool (``crossplay_reference.csv``):
    seconds, since they need no opponents of their own. Kept when the file already holds
    exactly these references against exactly this pool on these scenarios."""
    from sumo_ayss.evaluate import load_spcp
    from sumo_ayss.scenarios.crossplay import Opponent, run_crossplay
    from sumo_ayss.scenarios.preventability import reference_config

    _inevitable(runs[0].experiment.env, folder, n, seed)
    path = folder.crossplay_reference_csv
    if not references:
        return
    pool = sorted({(r.experiment.env.vut, r.config_seed) for r in runs})
    if path.is_file():
        try:
            old = read_table(path, CROSSPLAY_SCHEMA)
            opp = zip(old["opponent_vut"].tolist(), old["opponent_seed"].tolist(), strict=True)
            held = sorted(set(opp))
            same = (
                held == pool
                and sorted(set(old["vut"].tolist())) == sorted(references)
                and len(old) == n * len(pool) * len(references)
            )
        except TableError:
            same = False
        if same:
            return
    base = runs[0].experiment.env
    for name in references:  # one catalog holding every reference: one world for all
        base = reference_config(base, name, own_body=True)
    envs = {name: dataclasses.replace(base, vut=name) for name in references}
    opponents = [
        Opponent(
            r.experiment.env.vut,
            r.config_seed,
            functools.partial(load_spcp, r),
            _sha256(r.folder.spcp_zip),
        )
        for r in runs
    ]
    cells = _cells(folder.crossplay_reference_partial, False)
    t0 = time.perf_counter()
    with controller_imports(trust_controller):
        table = run_crossplay(
            envs, opponents, n=n, seed=seed, progress=progress, reference=label_with, cells=cells
        )
    write_table(path, table)
    cells.clear()
    logger.info(
        "%s: reference drivers %s against %d opponents in %.1f s",
        folder.path,
        ", ".join(references),
        len(opponents),
        time.perf_counter() - t0,
    )


def _cells(path: Path, force: bool) -> CellStore:
    """The finished cells of an interrupted run of this table (:class:`~sumo_ayss.run_folder.
    CellStore`); ``force`` drops them first (every cell is driven again)."""
    cells = CellStore(path)
    if force:
        cells.clear()
    elif held := cells.count():
        logger.info("%s: %d finished cells of an interrupted run are kept", path, held)
    return cells


def _done(stage: CrossplayStage) -> bool:
    """Whether the stage is done; an unreadable record is logged and the case runs again."""
    try:
        return is_done(stage)
    except TableError as exc:
        logger.warning("%s; cross-play of %s runs again", exc, stage.folder.path)
        return False


def _extended(
    folder: CaseFolder, requested: CrossplayRecord, vuts: tuple[str, ...]
) -> CrossplayRecord | None:
    """The case's recorded cross-play when ``requested`` only adds opponents to it (the same
    scenarios, rollout and VUTs; adaptive seeding's new seeds), else None."""
    if not (folder.crossplay_csv.is_file() and folder.crossplay_json.is_file()):
        return None
    try:
        done = read_crossplay_json(folder.crossplay_json)
    except TableError:
        return None
    if done.extended_by(requested) and done.diagonal and done.vuts == vuts:
        return done
    return None


def _merged(old: Any, new: Any, vuts: tuple[str, ...], pool: tuple[Any, ...]) -> Any:
    """The rows of ``old`` and ``new`` in the order one run over the whole pool writes them:
    VUT, then opponent (pool order), then scenario. Each (VUT, opponent) cell is its own
    fresh simulation, so the merged table equals that run's."""
    from sumo_ayss.run_folder import table_from_rows

    order = {(o.vut, o.seed): j for j, o in enumerate(pool)}
    rows = [*old.rows(), *new.rows()]
    rows.sort(
        key=lambda r: (
            vuts.index(r["vut"]),
            order[(r["opponent_vut"], r["opponent_seed"])],
            r["scenario"],
        )
    )
    return table_from_rows(CROSSPLAY_SCHEMA, rows)


def _merged_checks(old: Sequence[Any], new: Sequence[Any], pool: tuple[Any, ...]) -> tuple:
    """The diagonal checks of both tables, in pool order."""
    by_run = {(c.vut, c.seed): c for c in (*old, *new)}
    return tuple(by_run[(o.vut, o.seed)] for o in pool if (o.vut, o.seed) in by_run)


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


def read_matrix(runs: Sequence[RunRecord]) -> Any:
    """The :class:`~sumo_ayss.analysis.crossplay.CrossplayMatrix` of one case's runs, scored
    on their harm scale, with its diagonal check (:func:`sumo_ayss.run_folder.
    load_crossplay`).

    Raises:
        TableError: If there is no usable table (the message says why).
    """
    from sumo_ayss.report.load import group_runs

    groups = group_runs(runs)
    found = load_crossplay(next(iter(groups.values())))
    if found.matrix is None:
        raise TableError(found.missing or f"no cross-play table for {runs[0].path}")
    return found.matrix


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

    from sumo_ayss.analysis.crossplay import rank_crossplay
    from sumo_ayss.analysis.seeds import kendall_tau
    from sumo_ayss.config import load_pipeline
    from sumo_ayss.modes.crossplay import crossplay_sentence
    from sumo_ayss.modes.formatting import seed_interval_text
    from sumo_ayss.scenarios.outcome import DEFAULT_OUTCOME_SEED

    args = parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    try:
        out = Path(args.out) if args.out is not None else None
        cfg = load_pipeline(args.config, out=out, seeds=args.seeds)
        seeds = cfg.seeds
        for case in cfg.grid.cases:
            runs = case_runs(Path(cfg.out), case, cfg.grid.vuts, seeds)
            run_case(
                runs,
                case_dir_for(cfg.out, case),
                n=cfg.evaluate.n_outcome,
                seed=DEFAULT_OUTCOME_SEED,
                force=args.force,
                trust_controller=args.trust_controller,
                progress=functools.partial(print, f"{case}:", flush=True),
                reference=cfg.evaluate.reference,
                references=cfg.evaluate.reference_rows,
            )
            matrix = read_matrix(runs)
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
                print(
                    f"  Kendall tau vs expected order: {kendall_tau(order, cfg.expected_order):.2f}"
                )
    except AyssError as exc:
        sys.exit(f"error: {exc}")


if __name__ == "__main__":
    main()
