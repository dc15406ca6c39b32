"""Discriminability before training: can the paper's indicator separate these VUTs at all?

    python -m sumo_ayss.discriminability configs/car_following.yaml --vuts pi1 pi2
    python -m sumo_ayss.discriminability configs/ladders/min_gap.yaml      # grid.vuts
    python -m sumo_ayss.discriminability configs/cut_in.yaml --vuts pi1 pi2 --decisions 2

Maps, over the AYSS box (both speeds in [0, 30] m/s, h in (0, 5] m, TTC >= 0.2 s; a regular
grid, :class:`~sumo_ayss.analysis.discriminability.BoxGrid`), each VUT's one-step response
(its acceleration over one decision, measured in SUMO with the experiment's own env:
:mod:`sumo_ayss.scenarios.responses`) and reports where two VUTs differ by more than a
threshold (0.1 m/s²): the share of the box, by headway bin and by speed bin, for every pair,
and the mean response per VUT. An SPCP can only adapt to a VUT where the VUT reacts
differently; where the responses of two VUTs coincide, their AYSS indicators have nothing
to tell apart. No training is needed: 4 VUTs took 43 s on the default grid here (2 busy
cores; 20 s of CPU).

CONFIG is an experiment YAML (``env: ...``; VUTs from ``env.vuts`` and the built-ins) or a
pipeline YAML (``grid: ...``; its ``vuts`` section adds VUTs to every case, and
``grid.vuts`` is the default VUT list). Writes ``discriminability.json``, ``.csv`` and
``.png`` into ``--out`` (atomic writes) and prints one line per pair.
"""

from __future__ import annotations

import argparse
import dataclasses
import logging
import sys
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sumo_ayss.analysis.discriminability import (
    DEFAULT_THRESHOLD_MPS2,
    BoxGrid,
    Discriminability,
    compare_responses,
)
from sumo_ayss.cases import case_names
from sumo_ayss.cli import prog
from sumo_ayss.config import (
    Case,
    EnvConfig,
    PipelineConfig,
    experiment_from_dict,
    load_experiment,
    load_pipeline,
    read_yaml,
)
from sumo_ayss.run_folder import (
    CaseFolder,
    StudyFolder,
    read_discriminability_json,
    write_discriminability,
)
from sumo_ayss.stages import DiscriminabilityStage, is_done
from sumo_ayss.util.errors import AyssError, ConfigError, DiskFullError

logger = logging.getLogger(__name__)

#: Keys that mark a pipeline YAML (any other top-level mapping is read as an experiment).
#: Keys a run folder's config.yaml adds to an experiment.
_RUN_KEYS = ("vut", "seed")
_PIPELINE_KEYS = {"grid", "experiments", "out", "evaluate", "workers", "retries", "vuts"}


@dataclass(frozen=True)
class Target:
    """What to compare: the env of one case (with its VUT catalog) and the VUT names."""

    env: EnvConfig
    vuts: tuple[str, ...]
    source: str


def load_target(path: str | Path, vuts: Sequence[str] | None, case: Case | None) -> Target:
    """Read an experiment or pipeline YAML and resolve the env and the VUTs to compare.

    Args:
        path: Experiment YAML (``env``/``agent``/``train``; a run folder's ``config.yaml``
            too) or pipeline YAML (``grid``...).
        vuts: VUT names; default: a pipeline's ``grid.vuts`` (an experiment needs them).
        case: Case to use; default: the experiment's ``env.case`` or the pipeline's first
            ``grid.cases`` (a pipeline then uses that case's experiment file; an experiment
            YAML's env is used with the given case).

    Raises:
        ConfigError: On unreadable files, unknown VUTs or cases, fewer than 2 VUTs.
    """
    path = Path(path)
    data = read_yaml(path)
    is_pipeline = "env" not in data and bool(set(data) & _PIPELINE_KEYS)
    if is_pipeline:
        pipe = load_pipeline(path)
        if case is None and len(pipe.grid.cases) > 1:
            logger.warning(
                "%s has %d cases (%s): measuring only the first, %s; choose one with --case",
                path,
                len(pipe.grid.cases),
                ", ".join(pipe.grid.cases),
                pipe.grid.cases[0],
            )
        case = case or pipe.grid.cases[0]
        env = pipeline_env(pipe, case)
        names = tuple(vuts) if vuts else tuple(pipe.grid.vuts)
    else:
        # A run folder's config.yaml is an experiment plus the run's ``vut`` and ``seed``.
        exp_data = {k: v for k, v in data.items() if k not in _RUN_KEYS}
        env = experiment_from_dict(exp_data, path.resolve().parent).env
        if not vuts:
            raise ConfigError(
                f"--vuts: an experiment YAML needs the VUTs to compare; allowed: {sorted(env.vuts)}"
            )
        names = tuple(vuts)
    if case is not None and case != env.case:
        env = dataclasses.replace(env, case=case)  # validated by EnvConfig
    if len(names) < 2:
        raise ConfigError(f"--vuts needs at least 2 VUTs, got {list(names)}")
    if len(set(names)) != len(names):
        raise ConfigError(f"--vuts has duplicates: {list(names)}")
    unknown = [v for v in names if v not in env.vuts]
    if unknown:
        raise ConfigError(f"--vuts: unknown VUT(s) {unknown}; allowed: {sorted(env.vuts)}")
    return Target(env, names, str(path))


def pipeline_env(pipe: PipelineConfig, case: Case) -> EnvConfig:
    """The env of ``case``'s experiment in a pipeline, with the pipeline's extra VUTs."""
    if case not in pipe.experiments:
        raise ConfigError(
            f"--case {case!r}: the pipeline has no experiment for it; "
            f"allowed: {sorted(pipe.experiments)}"
        )
    exp = load_experiment(pipe.experiments[case])
    if exp.env.case != case:
        raise ConfigError(
            f"experiments.{case}: {pipe.experiments[case]} is a {exp.env.case!r} experiment"
        )
    return dataclasses.replace(exp.env, vuts={**exp.env.vuts, **pipe.vuts})


def compute(
    env: EnvConfig,
    vuts: Sequence[str],
    *,
    grid: BoxGrid | None = None,
    threshold_mps2: float = DEFAULT_THRESHOLD_MPS2,
    decisions: int = 1,
    n_pairs: int | None = None,
    progress: bool = False,
) -> tuple[Discriminability, dict[str, Any]]:
    """Measure every VUT on the grid and compare them.

    Returns:
        ``(result, meta)``: the comparison and the JSON-ready record (settings, timings,
        collisions per VUT, fingerprint, the comparison itself).
    """
    from sumo_ayss.scenarios.responses import DEFAULT_N_PAIRS, measure_responses

    grid = grid or BoxGrid()
    states = grid.states()
    responses = {}
    collisions = {}
    seconds = {}
    for vut in vuts:
        t0 = time.perf_counter()
        r = measure_responses(
            env,
            vut,
            states.v_pov_mps,
            states.v_vut_mps,
            states.h_m,
            decisions=decisions,
            n_pairs=n_pairs or DEFAULT_N_PAIRS,
        )
        seconds[vut] = round(time.perf_counter() - t0, 2)
        responses[vut] = r.accel_mps2
        collisions[vut] = int(r.collided.sum())
        if progress:
            print(f"  {vut}: {len(states):,} states in {seconds[vut]:.1f} s", file=sys.stderr)
    result = compare_responses(responses, states, threshold_mps2=threshold_mps2)
    settings = _settings(grid, threshold_mps2, decisions)
    meta = {
        "case": env.case,
        "vuts": list(vuts),
        "vut_descriptions": {v: env.vuts[v].description for v in vuts},
        "settings": settings,
        "response": (
            f"VUT acceleration [m/s²] averaged over {decisions} decision(s) of "
            f"{env.decision_period_s:g} s, measured in SUMO"
        ),
        "step_length_s": env.sim.step_length_s,
        "collisions": collisions,
        "seconds": seconds,
        "fingerprint": _stage(env, vuts, settings, Path()).key(),
        "summary": summary_lines(result, grid),
        **result.to_dict(),
    }
    return result, meta


def summary_lines(result: Discriminability, grid: BoxGrid | None = None) -> list[str]:
    """One line per pair, e.g. ``pi1 vs pi2 differ in 11.9 % of the AYSS box; none below h ≈
    2.95 m``."""
    from sumo_ayss.report.sections.discriminability import pair_summary

    step = grid.headway_step_m + grid.h_m[0] if grid is not None else None
    return [pair_summary(p, result.threshold_mps2, step) for p in result.pairs]


def write_outputs(meta: dict[str, Any], out_dir: str | Path, *, figure: bool = True) -> list[Path]:
    """Write ``discriminability.json`` and ``.csv`` (:func:`~sumo_ayss.run_folder.
    write_discriminability`) and the figure ``.png`` into ``out_dir``."""
    folder = CaseFolder(Path(out_dir))
    paths = write_discriminability(folder, meta)
    if figure:
        from sumo_ayss.report.sections.discriminability import discriminability_figure

        png = discriminability_figure(meta, folder.discriminability_png)
        if png is not None:
            paths.append(png)
    return paths


def _settings(grid: BoxGrid, threshold_mps2: float, decisions: int) -> dict[str, Any]:
    return {"grid": grid.to_dict(), "threshold_mps2": threshold_mps2, "decisions": decisions}


def _stage(
    env: EnvConfig, vuts: Sequence[str], settings: dict[str, Any], out_dir: Path
) -> DiscriminabilityStage:
    return DiscriminabilityStage(CaseFolder(out_dir), env, tuple(vuts), settings)


def ensure(
    env: EnvConfig, vuts: Sequence[str], out_dir: str | Path, **kwargs: Any
) -> dict[str, Any]:
    """:func:`compute` + :func:`write_outputs`, unless ``out_dir`` holds a record made from
    the same inputs (:class:`~sumo_ayss.run_folder.DiscriminabilityStage` is done): then
    that record is returned as is."""
    settings = _settings(
        kwargs.get("grid") or BoxGrid(),
        kwargs.get("threshold_mps2", DEFAULT_THRESHOLD_MPS2),
        kwargs.get("decisions", 1),
    )
    stage = _stage(env, vuts, settings, Path(out_dir))
    if is_done(stage):
        return read_discriminability_json(stage.folder.discriminability_json)
    _, meta = compute(env, vuts, **kwargs)
    write_outputs(meta, out_dir)
    return meta


# ------------------------------------------------------------------ in the pipeline


@contextmanager
def discriminability_beside(cfg: PipelineConfig) -> Iterator[None]:
    """:func:`write_for_pipeline` in a worker process while the body runs (the report's
    analysis: about 25 s of one core on a 3-VUT ladder, beside discriminability's 27 s of
    SUMO; docs/performance.md, "session 13"); done when the body is. With one worker,
    in this process before the body. Its failures are logged here, never fatal."""
    if len(cfg.grid.vuts) < 2:
        yield
        return
    logger.info(
        "discriminability of %s: one-step responses of %d VUTs over the AYSS box "
        "(seconds per VUT; skipped when up to date)",
        ", ".join(cfg.grid.cases),
        len(cfg.grid.vuts),
    )
    if cfg.n_workers <= 1:
        for line in write_for_pipeline(cfg):
            logger.warning("%s", line)
        yield
        return
    from concurrent.futures.process import BrokenProcessPool

    from sumo_ayss.grid.workers import spawn_pool, stop_workers

    pool = spawn_pool(1)
    try:
        future = pool.submit(write_for_pipeline, cfg)
        yield
        try:
            failures = future.result()
        except BrokenProcessPool as e:  # the worker died: as any failure, not fatal
            failures = [f"discriminability not computed: its worker process died ({e})"]
    except BaseException:
        stop_workers(pool)  # an error or Ctrl-C in the body: do not wait for it
        raise
    pool.shutdown(wait=True)
    for line in failures:
        logger.warning("%s", line)


def write_for_pipeline(cfg: PipelineConfig) -> list[str]:
    """``<out>/<case>/discriminability.json`` (+ .csv, .png) for every case with >= 2 VUTs.

    Where the grid's VUTs' one-step responses differ over the AYSS box
    (:mod:`sumo_ayss.discriminability`, default grid, some seconds per VUT); the report shows
    it. Skipped when an up-to-date record exists. Returns the failures, one line per case
    (never fatal: the report says so); a full disk raises.
    """
    if len(cfg.grid.vuts) < 2:
        return []
    failures = []
    for case in cfg.grid.cases:
        try:
            env = pipeline_env(cfg, case)
            ensure(env, cfg.grid.vuts, StudyFolder(cfg.out).case(case).path)
        except DiskFullError:
            raise
        except (AyssError, ImportError, OSError) as e:  # never fatal: the report says so
            failures.append(f"discriminability of {case} not computed: {e}")
    return failures


# --------------------------------------------------------------------------- CLI


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(
        prog=prog("python -m sumo_ayss.discriminability"),
        description=(__doc__ or "").splitlines()[0],
    )
    p.add_argument("config", type=Path, help="experiment YAML or pipeline YAML")
    p.add_argument("--vuts", nargs="+", default=None, help="VUTs to compare (>= 2)")
    p.add_argument(
        "--case",
        choices=case_names(),
        default=None,
        help="case to measure (default: the experiment's, or a pipeline's FIRST grid.cases "
        "only; a warning says so)",
    )
    p.add_argument(
        "--out", type=Path, default=None, help="default: runs/discriminability/<stem>_<case>"
    )
    p.add_argument(
        "--threshold",
        type=float,
        default=DEFAULT_THRESHOLD_MPS2,
        help=f"responses differ above this [m/s²] (default {DEFAULT_THRESHOLD_MPS2})",
    )
    p.add_argument(
        "--speed-step",
        type=float,
        default=BoxGrid.speed_step_mps,
        help="grid step of both speeds [m/s] (default 1)",
    )
    p.add_argument(
        "--headway-step",
        type=float,
        default=BoxGrid.headway_step_m,
        help="grid step of h [m] (default 0.1)",
    )
    p.add_argument(
        "--speed-range",
        type=float,
        nargs=2,
        default=None,
        metavar=("MIN", "MAX"),
        help="both speeds [m/s] (default 0 30, the AYSS box)",
    )
    p.add_argument(
        "--decisions",
        type=int,
        default=1,
        help="decisions measured per state (default 1; cut-in: try 2)",
    )
    p.add_argument(
        "--pairs", type=int, default=None, help="pairs per SUMO simulation (default 256)"
    )
    return p.parse_args(argv)


def main(argv: Sequence[str] | None = None) -> None:
    args = parse_args(argv)
    logging.basicConfig(level=logging.WARNING, format="%(asctime)s %(name)s: %(message)s")
    try:
        target = load_target(args.config, args.vuts, args.case)
        speeds = tuple(args.speed_range) if args.speed_range else BoxGrid.v_pov_mps
        grid = BoxGrid(
            v_pov_mps=speeds,
            v_vut_mps=speeds,
            speed_step_mps=args.speed_step,
            headway_step_m=args.headway_step,
        )
        out = (
            args.out or Path("runs") / "discriminability" / f"{args.config.stem}_{target.env.case}"
        )
        t0 = time.perf_counter()
        n = len(grid.states())
        print(
            f"{target.env.case}: {len(target.vuts)} VUTs on {n:,} AYSS states "
            f"(speeds step {grid.speed_step_mps:g} m/s, h step {grid.headway_step_m:g} m)",
            file=sys.stderr,
        )
        result, meta = compute(
            target.env,
            target.vuts,
            grid=grid,
            threshold_mps2=args.threshold,
            decisions=args.decisions,
            n_pairs=args.pairs,
            progress=True,
        )
        paths = write_outputs(meta, out)
    except AyssError as e:
        sys.exit(f"error: {e}")
    print(
        f"Where the VUTs' responses over {args.decisions} decision(s) differ by > "
        f"{args.threshold:g} m/s² "
        f"({target.env.case}, {time.perf_counter() - t0:.0f} s):"
    )
    for line in meta["summary"]:
        print(f"  {line}")
    means = ", ".join(f"{v} {a:+.2f}" for v, a in result.mean_response_mps2.items())
    print(f"  mean response [m/s²]: {means}")
    print(f"written: {', '.join(str(p) for p in paths)}")


if __name__ == "__main__":
    main()
