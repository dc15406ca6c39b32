"""Issue 40: a budget checked on real runs of every ladder, beside the earlier default's runs,
as one Markdown table (cross-play mode, the product's verdict).

    python scripts/budget_validation_table.py results/budget_validation \
        --before results/follower_ladders results/verdict_budget results/ladders

For every ``<root>/<ladder>/`` holding ``order_check.json`` (written by ``rank``), one row
per case of its cross-play verdict: the seeds per VUT adaptive seeding settled at (and its
looks), the ranking, Kendall's τ against the known order, the ends' paired-t p (the
product's "ends significant") and the adjacent pairs significant under Holm (the frontier's
family-wise rule: the ends are significant under it only when every adjacent pair is), and
the CPU-seconds and wall time of the whole ``rank`` when ``<root>/<ladder>.time`` holds
``/usr/bin/time``'s line (``wall W s  user U  sys S ...``). Then the same ladder and case
from the first ``--before`` root that has it (τ, ends p, adjacent pairs), for comparison; a
``--before`` entry ``LADDER=STUDY`` names one ladder's study folder directly.
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path

from sumo_ayss.run_folder import read_adaptive
from sumo_ayss.run_folder.study import StudyFolder, read_order_check

MODE = "crossplay"


def _check(study: Path, case: str):
    path = StudyFolder(study).order_check_json
    if not path.is_file():
        return None
    for c in read_order_check(path).cases:
        if c.case == case and c.mode == MODE:
            return c
    return None


def _cases(study: Path) -> list[str]:
    path = StudyFolder(study).order_check_json
    return list(dict.fromkeys(c.case for c in read_order_check(path).cases if c.mode == MODE))


def _seeds(study: Path, case: str) -> str:
    path = study / case / "adaptive.json"
    if not path.is_file():
        return "fixed"
    rec = read_adaptive(path)
    looks = ", ".join(
        f"{look.n_seeds}: p {look.ends_p:.3g}{' settled' if look.settled else ''}"
        for look in rec.looks
    )
    return f"{len(rec.seeds)} ({looks})"


def _cost(root: Path, ladder: str) -> str:
    path = root / f"{ladder}.time"
    if not path.is_file():
        return "—"
    m = re.search(r"wall ([\d.]+) s\s+user ([\d.]+)\s+sys ([\d.]+)", path.read_text())
    if m is None:
        return "—"
    wall, user, sys_ = (float(x) for x in m.groups())
    return f"{user + sys_:,.0f} / {wall / 60:.1f} min"


def _short(c) -> str:
    sig = "yes" if c.ends_significant else "no"
    return f"{c.tau:.2f}, {c.ends_p:.3g} ({sig}), {c.significant_adjacent} of {c.adjacent}"


def _earlier(before: list[str], ladder: str, case: str) -> str:
    for entry in before:
        name, _, path = entry.partition("=")
        study = Path(path) if path else Path(name) / ladder
        if path and name != ladder:
            continue
        c = _check(study, case)
        if c is not None:
            return _short(c)
    return "—"


def rows(root: Path, before: list[str], ladders: list[str] | None) -> list[str]:
    out = [
        "| ladder | case | seeds per VUT (looks: ends p) | ranking, safest first | τ | "
        "ends p (paired t) | adjacent significant (Holm) | CPU-s / wall, both cases | "
        "earlier default: τ, ends p, adjacent |",
        "|---|---|---|---|---:|---|---|---|---|",
    ]
    names = ladders or sorted(p.name for p in root.iterdir() if (p / "order_check.json").is_file())
    for ladder in names:
        study = root / ladder
        for case in _cases(study):
            c = _check(study, case)
            if c is None:
                continue
            earlier = _earlier(before, ladder, case)
            sig = "yes" if c.ends_significant else "no"
            out.append(
                f"| {ladder} | {case} | {_seeds(study, case)} | {' > '.join(c.order)} | "
                f"{c.tau:.2f} | {c.ends_p:.3g} ({sig}) | {c.significant_adjacent} of "
                f"{c.adjacent} | {_cost(root, ladder)} | {earlier} |"
            )
    return out


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("root", type=Path)
    p.add_argument("--before", nargs="*", default=[], help="ROOT or LADDER=STUDY")
    p.add_argument("--ladders", nargs="*", default=None)
    a = p.parse_args()
    print("\n".join(rows(a.root, a.before, a.ladders)))


if __name__ == "__main__":
    main()
