"""``sumo-ayss <command> ...``: one entry point for every stage (imports are lazy).

sumo-ayss train    --config configs/car_following.yaml --vut pi1 --seed 0
sumo-ayss evaluate runs/paper/car_following/pi1/seed_0
sumo-ayss report   runs/paper
sumo-ayss pipeline configs/paper.yaml
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Sequence

COMMANDS = {
    "train": ("sumo_ayss.train", "train one (case, VUT, seed) and select its SPCP"),
    "evaluate": ("sumo_ayss.evaluate", "outcome table and Monte Carlo AYSS of a run's SPCP"),
    "report": ("sumo_ayss.report.__main__", "HTML + Markdown report from run folders"),
    "pipeline": ("sumo_ayss.pipeline", "the grid cases x VUTs x seeds, resumable"),
    "rank": ("sumo_ayss.rank", "leaderboard of K VUTs by safety index"),
    "discriminability": (
        "sumo_ayss.discriminability",
        "where VUTs' one-step responses differ over the AYSS box (no training)",
    ),
    "networks": ("sumo_ayss.sim.network", "rebuild the built-in networks and vType file"),
}


def usage() -> str:
    lines = ["usage: sumo-ayss <command> [args...]", "", "commands:"]
    lines += [f"  {name:<17} {help_}" for name, (_, help_) in COMMANDS.items()]
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> None:
    args = list(sys.argv[1:] if argv is None else argv)
    if not args or args[0] in ("-h", "--help"):
        print(usage())
        return
    if args[0] not in COMMANDS:
        sys.exit(f"error: unknown command {args[0]!r}\n{usage()}")
    module = importlib.import_module(COMMANDS[args[0]][0])
    sys.argv = [f"sumo-ayss {args[0]}", *args[1:]]
    module.main(args[1:])


if __name__ == "__main__":
    main()
