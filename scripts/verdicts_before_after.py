"""Each verdict of a study's ranking.csv before and after a re-run, as a markdown table.

    python scripts/verdicts_before_after.py results/paper <git revision before the re-run>

One row per (case, mode) with a "vs next" sentence: the sentence committed at the revision,
the one in the working tree, and whether the verdict moved (a different significance call,
or a different VUT called safer).
"""

from __future__ import annotations

import csv
import io
import subprocess
import sys
from pathlib import Path


def _verdicts(text: str) -> dict[tuple[str, str], dict[str, str]]:
    return {(r["case"], r["mode"]): r for r in csv.DictReader(io.StringIO(text)) if r["vs_next"]}


def _sentence(row: dict[str, str] | None) -> str:
    return "—" if row is None else row["vs_next"].split("] ", 1)[-1].replace("|", "/")


def _call(row: dict[str, str] | None) -> tuple[str | None, str | None]:
    if row is None:
        return None, None
    significant = row["significant_vs_next"] == "True"
    return row["significant_vs_next"], row["vut"] if significant else None


def main(study: str, revision: str) -> None:
    before = subprocess.run(
        ["git", "show", f"{revision}:{study}/ranking.csv"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    old, new = _verdicts(before), _verdicts(Path(study, "ranking.csv").read_text())
    order = {"crossplay": 0, "exposure": 1, "paper": 2}
    print("| case | mode | before | after | verdict |")
    print("|---|---|---|---|---|")
    for key in sorted(set(old) | set(new), key=lambda k: (order.get(k[1], 3), k[0])):
        a, b = old.get(key), new.get(key)
        moved = "held" if _call(a) == _call(b) else "**moved**"
        print(f"| {key[0]} | {key[1]} | {_sentence(a)} | {_sentence(b)} | {moved} |")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
