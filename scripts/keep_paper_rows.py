"""Carry a study's paper-mode rows over into its re-ranked ``ranking.csv`` / ``ranking.md``.

    python scripts/keep_paper_rows.py <study> <previous ranking.csv>

Paper mode reads the AYSS samples (``ayss.csv``), which results/ does not commit (size), so
``rank --no-run`` on a committed study cannot recompute them; the harm score does not touch
paper mode, so its previous rows stand. Appends them (with empty crash and mobility cells)
after the rows ``rank`` wrote, unless paper rows are there already.
"""

from __future__ import annotations

import sys
from pathlib import Path

from sumo_ayss.rank import write_ranking
from sumo_ayss.run_folder import StudyFolder
from sumo_ayss.run_folder.study import read_order_check, read_ranking_csv


def main(study: Path, previous: Path) -> None:
    folder = StudyFolder(study)
    rows = read_ranking_csv(folder.ranking_csv)
    if any(r["mode"] == "paper" for r in rows):
        return
    paper = [r for r in read_ranking_csv(previous) if r["mode"] == "paper"]
    if not paper:
        return
    merged = []
    for r in rows + paper:  # every column: the reader fills a missing one with ""
        row: dict[str, object] = dict(r)
        for key in ("score", "lo", "hi", "crash_rate", "crash_lo", "crash_hi", "mobility_mps"):
            if r[key] != "":
                row[key] = float(r[key])
        for key in ("rank", "n_seeds", "crashes", "episodes"):
            if r[key] != "":
                row[key] = int(r[key])
        row["timid"] = r["timid"] == "True" if r["timid"] != "" else ""
        merged.append(row)
    found = read_order_check(folder.order_check_json) if folder.order_check_json.is_file() else None
    checks = found.cases if found is not None else ()
    expected = found.expected if found is not None else ()
    write_ranking(merged, study, checks, expected)
    print(f"{study}: {len(paper)} paper-mode rows carried over from {previous}")


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]))
