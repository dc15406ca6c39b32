"""Write ``ayss_bins.csv`` beside every ``ayss.csv`` of a study that has none (runs evaluated
before the evaluate stage wrote it; the pipeline and evaluate do this too, for their runs).

    python scripts/ayss_bins_from_csv.py <study> [<study> ...]

:func:`sumo_ayss.evaluate.backfill_ayss_bins`: the evaluate stage's reduction of the table.
Prints each file written.
"""

from __future__ import annotations

import sys
from pathlib import Path

from sumo_ayss.evaluate import backfill_ayss_bins
from sumo_ayss.run_folder import RunFolder, find_run_dirs


def main(studies: list[str]) -> None:
    for run in find_run_dirs([Path(s) for s in studies]):
        folder = RunFolder(run)
        if backfill_ayss_bins(folder.ayss_csv, folder.ayss_bins):
            print(folder.ayss_bins)


if __name__ == "__main__":
    main(sys.argv[1:])
