"""Write ``ayss_bins.csv`` beside every ``ayss.csv`` of a study (runs evaluated before the
evaluate stage wrote it).

    python scripts/ayss_bins_from_csv.py <study> [<study> ...]

The same reduction the evaluate stage applies to the table it has just written
(:func:`sumo_ayss.run_folder.ayss_cells` of ``h_m`` and ``indicator``); ``ayss.csv`` stores
every float exactly (``repr``), so the file equals the one the stage would have written.
Prints each file written.
"""

from __future__ import annotations

import sys
from pathlib import Path

from sumo_ayss.run_folder import (
    AYSS_SCHEMA,
    RunFolder,
    ayss_cells,
    find_run_dirs,
    read_table,
    write_ayss_bins,
)


def main(studies: list[str]) -> None:
    for run in find_run_dirs([Path(s) for s in studies]):
        folder = RunFolder(run)
        if not folder.ayss_csv.is_file():
            continue
        table = read_table(folder.ayss_csv, AYSS_SCHEMA)
        names = sorted({str(v) for v in table["indicator_name"]})
        cells = ayss_cells(table["h_m"], table["indicator"], names[0] if names else None)
        write_ayss_bins(folder.ayss_bins, cells)
        print(folder.ayss_bins)


if __name__ == "__main__":
    main(sys.argv[1:])
