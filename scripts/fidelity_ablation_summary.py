"""Put the paper pair's verdicts from several worlds side by side (issue 12 ablation).

    python scripts/fidelity_ablation_summary.py OUT.md NAME=STUDY [NAME=STUDY ...]

Each ``STUDY`` is a folder ranked with ``python -m sumo_ayss.rank <config> --no-run --mode
paper`` (so its ``ranking.csv`` has rows of every mode available: cross-play, exposure,
paper). VUTs are matched across worlds by the last part of their name (``pi1`` /
``hwenv_pi1`` → ``pi1``). One row per case and mode: per world, the difference of the
mode's scores oriented so that positive = pi2 safer (the paper's direction), its p-value,
and whether the study called it significant. Writes the Markdown table to
``OUT.md`` and prints it.
"""

from __future__ import annotations

import sys
from pathlib import Path

from sumo_ayss.run_folder import StudyFolder
from sumo_ayss.run_folder.study import read_ranking_csv
from sumo_ayss.util.atomic import atomic_write_text

MODES = ("crossplay", "exposure", "paper")
UNITS = {
    "crossplay": "harm per episode the pooled SPCPs bring about (1 = a collision; "
    "sumo_ayss.analysis.harm)",
    "exposure": "harm per episode each VUT's own SPCPs bring about",
    "paper": "safety index in the AYSS (car-following: how much harder the SPCPs brake "
    "[m/s²]; cut-in: how much lower their Δv̄ is [m/s]; the more aggressive SPCP marks the "
    "safer VUT)",
}


def _rows(study: Path) -> dict[tuple[str, str], dict[str, dict[str, str]]]:
    """``{(case, mode): {"pi1": row, "pi2": row}}`` from ``study/ranking.csv``."""
    out: dict[tuple[str, str], dict[str, dict[str, str]]] = {}
    for row in read_ranking_csv(StudyFolder(study).ranking_csv):
        out.setdefault((row["case"], row["mode"]), {})[row["vut"].split("_")[-1]] = row
    return out


def _cell(rows: dict[str, dict[str, str]] | None) -> str:
    """``+1.10 (p 0.001, sig.)`` for one world, case and mode; ``—`` where missing."""
    if not rows or set(rows) != {"pi1", "pi2"}:
        return "—"
    pi1, pi2 = float(rows["pi1"]["score"]), float(rows["pi2"]["score"])
    # Orient by the score's stated direction (paper mode: "higher = safer"; cross-play and
    # exposure: harm, "lower = safer"), so that positive = pi2 safer.
    higher_safer = "higher = safer" in rows["pi1"]["unit"]
    diff = pi2 - pi1 if higher_safer else pi1 - pi2
    top = rows["pi1"] if rows["pi1"]["rank"] == "1" else rows["pi2"]
    p = top["p_vs_next"]
    sig = "**sig.**" if top["significant_vs_next"] == "True" else "n.s."
    p_text = f"p {float(p):.2g}" if p else "no test"
    digits = 2 if higher_safer else 3  # harm lies in [0, 1]
    return f"{diff:+.{digits}f} ({p_text}, {sig})"


def main(out: Path, studies: list[tuple[str, Path]]) -> None:
    """Read every study's ranking.csv and write the side-by-side table."""
    data = {name: _rows(path) for name, path in studies}
    cases = sorted({case for rows in data.values() for case, _ in rows})
    head = "| case | mode | " + " | ".join(name for name, _ in studies) + " |"
    lines = [
        "Difference between the pair in each mode's score, oriented so that positive = pi2 "
        "safer (the paper's direction), p of the mode's test, and the mode's significance call.",
        "",
        head,
        "|---|---|" + "---|" * len(studies),
    ]
    for case in cases:
        for mode in MODES:
            cells = [_cell(data[name].get((case, mode))) for name, _ in studies]
            if all(c == "—" for c in cells):
                continue
            lines.append(f"| {case} | {mode} | " + " | ".join(cells) + " |")
    lines += ["", *(f"* {mode}: {unit}" for mode, unit in UNITS.items())]
    text = "\n".join(lines) + "\n"
    atomic_write_text(out, text)
    print(text)


if __name__ == "__main__":
    if len(sys.argv) < 3 or any("=" not in a for a in sys.argv[2:]):
        sys.exit(__doc__)
    main(Path(sys.argv[1]), [(a.split("=", 1)[0], Path(a.split("=", 1)[1])) for a in sys.argv[2:]])
