"""Re-read committed studies' cross-play crashes against the inevitable-collision states.

    python scripts/ics_reread.py results/ladders [results/preventability/committed_ladders.md]

The committed studies keep no SPCP weights, so their crashes cannot be replayed with the
careful human (the POV's actions were not stored either). What can be re-read is the scenario
set: for each study and case, the scenarios of its ``crossplay.csv`` (``n`` draws of the
outcome seed, from ``crossplay.json``) are checked for inevitable-collision states
(:mod:`sumo_ayss.scenarios.inevitable`: a VUT braking at 0.85 g from the first instant
still touches a POV that brakes or cuts in at once), with the case's env as the study's
runs configured it. Then, per study and case:

* shared crash episodes: (opponent, scenario) cells in which *every* VUT of the study
  crashed, their share of all episodes, and how many of them start in an ICS;
* all crashes: how many start in an ICS.

An ICS crash is unpreventable for every driver (the careful human brakes later and no
harder), so "in an ICS" is a lower bound of "unpreventable". Writes a Markdown table.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from sumo_ayss.envs.odd import scenario_set
from sumo_ayss.records.table import read_table
from sumo_ayss.run_folder import CROSSPLAY_SCHEMA, CaseFolder, read_crossplay_json, read_run
from sumo_ayss.scenarios.inevitable import ics_flags
from sumo_ayss.util.atomic import atomic_write_text


def _case_rows(study: Path, case_dir: Path) -> dict[str, object] | None:
    folder = CaseFolder(case_dir)
    if not (folder.crossplay_csv.is_file() and folder.crossplay_json.is_file()):
        return None
    record = read_crossplay_json(folder.crossplay_json)
    run_dir = next(case_dir.glob("*/seed_*"))
    env = read_run(run_dir).experiment.env
    flags = np.array(ics_flags(env, scenario_set(env, record.n, record.seed)))
    t = read_table(folder.crossplay_csv, CROSSPLAY_SCHEMA)
    vuts = sorted(set(t["vut"].tolist()))
    cells: dict[tuple[str, int, int], list[bool]] = {}
    for v, o, s, sc, c in zip(
        t["vut"], t["opponent_vut"], t["opponent_seed"], t["scenario"], t["collided"], strict=True
    ):
        cells.setdefault((str(o), int(s), int(sc)), []).append(bool(c))
        del v
    shared = [k for k, cs in cells.items() if len(cs) == len(vuts) and all(cs)]
    shared_ics = sum(flags[sc] for _o, _s, sc in shared)
    crashed = t["collided"]
    crash_ics = int(flags[t["scenario"][crashed]].sum())
    return {
        "study": study.name,
        "case": case_dir.name,
        "vuts": len(vuts),
        "scenarios": record.n,
        "ics_scenarios": int(flags.sum()),
        "episodes": len(t),
        "crashes": int(crashed.sum()),
        "crashes_in_ics": crash_ics,
        "shared_cells": len(shared),
        "cells": len(cells),
        "shared_in_ics": int(shared_ics),
    }


def main(root: Path, out: Path) -> None:
    rows = []
    for study in sorted(p for p in root.iterdir() if p.is_dir()):
        for case_dir in sorted(p for p in study.iterdir() if p.is_dir() and p.name != "report"):
            row = _case_rows(study, case_dir)
            if row is not None:
                rows.append(row)
                print(row, flush=True)
    lines = [
        "# Committed studies: crashes in inevitable-collision states",
        "",
        f"Written by `python scripts/ics_reread.py {root}`. ICS: a vehicle braking at 0.85 g "
        "from the first instant still touches a POV that brakes (car-following) or cuts in "
        "(cut-in) at once. Shared crash cells: (opponent, scenario) in which every VUT of "
        "the study crashed.",
        "",
        "| study | case | VUTs | ICS scenarios | crashes | of them in an ICS | shared crash "
        "cells (share of cells) | of them in an ICS |",
        "|---|---|---:|---|---:|---|---|---|",
    ]
    for r in rows:
        pct = 100 * r["ics_scenarios"] / r["scenarios"]
        crashes = r["crashes"]
        in_ics = r["crashes_in_ics"]
        shared = r["shared_cells"]
        lines.append(
            f"| {r['study']} | {r['case']} | {r['vuts']} | {r['ics_scenarios']}/{r['scenarios']}"
            f" ({pct:.1f} %) | {crashes} | {in_ics} ({100 * in_ics / max(crashes, 1):.0f} %) | "
            f"{shared} ({100 * shared / r['cells']:.1f} %) | {r['shared_in_ics']} "
            f"({100 * r['shared_in_ics'] / max(shared, 1):.0f} %) |"
        )
    out.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out, "\n".join(lines) + "\n")
    print(f"wrote {out}")


if __name__ == "__main__":
    args = sys.argv[1:]
    if not args or args[0] in ("-h", "--help"):
        print(__doc__)
        sys.exit(0 if args else 2)
    main(
        Path(args[0]),
        Path(args[1]) if len(args) > 1 else Path("results/preventability/committed_ladders.md"),
    )
