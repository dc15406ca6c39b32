"""Check the diagonal of every committed cross-play table against its runs' outcome tables.

    python scripts/check_diagonals.py [results]

For each ``<case folder>/crossplay.csv`` under the root, every run ``<vut>/seed_<k>`` of the
case folder: its SPCP's episodes against its own VUT in the cross-play table must equal its
``outcome.csv`` (:func:`sumo_ayss.scenarios.crossplay.diagonal_check`; the cross-play stage
does this itself since issue 21, tables made before it were not checked). Prints, per table,
the equal episodes and, where some differ, by how much (largest return difference, and
whether any collision or episode length differs).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from sumo_ayss.records.table import read_table
from sumo_ayss.run_folder import CROSSPLAY_SCHEMA, OUTCOME_SCHEMA
from sumo_ayss.run_folder.layout import seed_of_dir
from sumo_ayss.scenarios.crossplay import diagonal_check


def main(root: Path) -> None:
    for csv_path in sorted(root.glob("**/crossplay.csv")):
        table = read_table(csv_path, CROSSPLAY_SCHEMA)
        equal = total = 0
        worst, structural = 0.0, False
        for run in sorted(csv_path.parent.glob("*/seed_*")):
            seed = seed_of_dir(run)
            if seed is None:
                continue
            vut = run.parent.name
            outcome = read_table(run / "outcome.csv", OUTCOME_SCHEMA)
            check = diagonal_check(table, vut, seed, outcome)
            equal, total = equal + check.n_equal, total + check.n
            rows = (
                (table["vut"] == vut)
                & (table["opponent_vut"] == vut)
                & (table["opponent_seed"] == seed)
            )
            diff = np.abs(table["episode_return"][rows] - outcome["episode_return"])
            worst = max(worst, float(diff.max()))
            structural |= bool(
                np.any(table["collided"][rows] != outcome["collided"])
                or np.any(table["n_steps"][rows] != outcome["n_steps"])
            )
        note = (
            ""
            if equal == total
            else (
                f"; largest return difference {worst:.2g}, "
                + (
                    "collisions or lengths differ"
                    if structural
                    else "no collision or length differs"
                )
            )
        )
        print(f"{csv_path.parent}: {equal}/{total} diagonal episodes equal{note}")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("results"))
