"""Copy a finished study from runs/ into results/ without what git should not hold.

    python scripts/commit_study.py runs/ladders/braking_a results/ladders/braking_a

Leaves out the candidate checkpoints, ``spcp.zip``, TensorBoard logs, job logs and progress
files (they stay in runs/, which the time-to-verdict work reads) and the AYSS sample tables
(``ayss.csv``, ignored by git for size). Everything a reader or ``rank --no-run`` needs is
copied: configs, seeds, versions, evaluation and outcome tables, cross-play tables and
records, discriminability, rankings and the report.
"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

SKIP_DIRS = {"checkpoints", "tb"}
SKIP_FILES = {"spcp.zip", "job.log", "progress.json", "ayss.csv", "pipeline.lock"}


def main(src: Path, dst: Path) -> None:
    n = 0
    for path in sorted(src.rglob("*")):
        rel = path.relative_to(src)
        if any(part in SKIP_DIRS for part in rel.parts) or not path.is_file():
            continue
        if path.name in SKIP_FILES:
            continue
        target = dst / rel
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(path, target)
        n += 1
    print(f"copied {n} files from {src} to {dst}")


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]))
