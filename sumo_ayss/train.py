"""Train SPCP candidates for one (case, VUT, seed) and select the SPCP: the stage's entry point.

    python -m sumo_ayss.train --config configs/car_following.yaml --vut pi1 --seed 0
    python -m sumo_ayss.train --config configs/car_following.yaml --vut pi1 --seed 0 --resume

The work is :func:`sumo_ayss.training.trainer.train` (the run folder it writes, candidates,
evaluation and resume are described there).
"""

from __future__ import annotations

import argparse
import dataclasses
import logging
import shlex
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from sumo_ayss.cli import prog
from sumo_ayss.config import load_experiment
from sumo_ayss.run_folder import StudyFolder
from sumo_ayss.training.trainer import train
from sumo_ayss.util.errors import AyssError

__all__ = ["main", "parse_args", "train"]


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(
        prog=prog("python -m sumo_ayss.train"), description=__doc__.splitlines()[0]
    )
    parser.add_argument(
        "--config",
        type=Path,
        default=None,
        help="experiment YAML (required): configs/car_following.yaml or configs/cut_in.yaml "
        "are the paper's experiments",
    )
    parser.add_argument("--vut", default=None, help="VUT name (overrides env.vut)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=Path, default=Path("runs"), help="runs root folder")
    parser.add_argument("--resume", action="store_true", help="continue a killed run")
    parser.add_argument(
        "--total-timesteps", type=int, default=None, help="override train.total_timesteps"
    )
    parser.add_argument("--eval-every", type=int, default=None, help="override train.eval_every")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.add_argument(
        "--device", default=None, help="override train.device (cpu, cuda, cuda:<index>)"
    )
    return parser.parse_args(argv)


def main(argv: Sequence[str] | None = None) -> None:
    argv = list(sys.argv[1:] if argv is None else argv)
    args = parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(name)s: %(message)s")
    if args.config is None:
        # The built-in defaults (one env, 200,000 transitions) are not the paper's
        # configuration: starting a long run on them by omission helps nobody.
        sys.exit(
            "error: --config: an experiment YAML is required, e.g. --config "
            "configs/car_following.yaml (the paper's car-following experiment) or "
            "configs/cut_in.yaml; the built-in defaults are not the paper's configuration"
        )
    run_dir: Path | None = None
    try:
        cfg = load_experiment(args.config).with_vut(args.vut)
        overrides: dict[str, Any] = {}
        if args.total_timesteps is not None:
            overrides["total_timesteps"] = args.total_timesteps
        if args.eval_every is not None:
            overrides["eval_every"] = args.eval_every
        if args.no_progress:
            overrides["progress_bar"] = False
        if args.device is not None:
            overrides["device"] = args.device
        cfg = dataclasses.replace(cfg, train=dataclasses.replace(cfg.train, **overrides))
        run_dir = StudyFolder(args.out).run(cfg.env.case, cfg.env.vut, args.seed).path
        run_dir = train(cfg, args.seed, args.out, resume=args.resume, argv=argv)
    except AyssError as e:
        sys.exit(f"error: {e}")
    except KeyboardInterrupt:
        resume = [a for a in argv if a != "--resume"] + ["--resume"]
        where = f" ({run_dir})" if run_dir is not None else ""
        print(
            f"\ninterrupted: training stopped{where}; continue it from its last checkpoint "
            f"with:\n  python -m sumo_ayss.train {shlex.join(resume)}",
            file=sys.stderr,
            flush=True,
        )
        sys.exit(130)
    print(run_dir)


if __name__ == "__main__":
    main()
