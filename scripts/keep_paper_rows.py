"""Carry a study's paper-mode rows over into its re-ranked ``ranking.csv`` / ``ranking.md``.

    python scripts/keep_paper_rows.py <study> <previous ranking.csv>

Paper mode reads the AYSS samples (``ayss.csv``), which results/ does not commit (size), so
``rank --no-run`` on a committed study cannot recompute them; the harm score does not touch
paper mode, so its previous rows stand. Appends them (with empty crash and mobility cells)
after the rows ``rank`` wrote, unless paper rows are there already.
"""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

from sumo_ayss.rank import RANKING_COLUMNS, write_ranking


def main(study: Path, previous: Path) -> None:
    with (study / "ranking.csv").open() as f:
        rows = list(csv.DictReader(f))
    if any(r["mode"] == "paper" for r in rows):
        return
    with previous.open() as f:
        paper = [r for r in csv.DictReader(f) if r["mode"] == "paper"]
    if not paper:
        return
    merged = []
    for r in rows + paper:
        row = {k: r.get(k, "") for k in RANKING_COLUMNS}
        for key in ("score", "lo", "hi", "crash_rate", "crash_lo", "crash_hi", "mobility_mps"):
            if row[key] not in ("", None):
                row[key] = float(row[key])
        for key in ("rank", "n_seeds", "crashes", "episodes"):
            if row[key] not in ("", None):
                row[key] = int(row[key])
        row["timid"] = row["timid"] == "True" if row["timid"] != "" else ""
        merged.append(row)
    check = study / "order_check.json"
    checks = json.loads(check.read_text())["cases"] if check.is_file() else []
    expected = json.loads(check.read_text())["expected"] if check.is_file() else []
    write_ranking(merged, study, checks, expected)
    print(f"{study}: {len(paper)} paper-mode rows carried over from {previous}")


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]))
