"""``sumo-ayss <command> ...``: one entry point for every stage (imports are lazy).

    sumo-ayss train    --config configs/car_following.yaml --vut pi1 --seed 0
    sumo-ayss evaluate runs/car_following/pi1/seed_0
    sumo-ayss report   runs
    sumo-ayss pipeline configs/paper.yaml
    sumo-ayss rank     configs/ladders/min_gap.yaml
    sumo-ayss discriminability configs/ladders/min_gap.yaml
    sumo-ayss replay   export runs/car_following/pi1/seed_0 --outcome-row 0 --out scen/ep0
    sumo-ayss networks

``sumo-ayss <command> ...`` is the same as ``python -m <module> ...`` of the command's
module (:data:`COMMANDS`; ``pipeline`` and ``rank`` are the commands above their stages,
:mod:`sumo_ayss.commands`, which ``python -m sumo_ayss.pipeline`` and ``python -m
sumo_ayss.rank`` run too); ``sumo-ayss <command> --help`` names itself ``sumo-ayss
<command>``.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Sequence

COMMANDS = {
    "train": ("sumo_ayss.train", "train one (case, VUT, seed) and select its SPCP"),
    "evaluate": ("sumo_ayss.evaluate", "outcome table and Monte Carlo AYSS of a run's SPCP"),
    "report": ("sumo_ayss.report.__main__", "HTML + Markdown report from run folders"),
    "pipeline": ("sumo_ayss.commands.pipeline", "the grid cases x VUTs x seeds, resumable"),
    "rank": (
        "sumo_ayss.commands.rank",
        "leaderboard of K VUTs by safety (a pipeline + ranking; default mode cross-play)",
    ),
    "discriminability": (
        "sumo_ayss.discriminability",
        "where VUTs' one-step responses differ over the AYSS box (no training)",
    ),
    "replay": ("sumo_ayss.replay", "export a run's scenario as SUMO files; replay it"),
    "networks": ("sumo_ayss.sim.network", "rebuild the built-in networks and vType file"),
}
"""Command name -> (module with a ``main(argv)``, one line of help)."""

_invoked_as: str | None = None


#: ``--strict``'s help, the same in every stage that prints input problems (``report``,
#: ``rank``, ``pipeline``).
STRICT_HELP = (
    "exit non-zero when an input file is missing, unreadable, empty or damaged, or every "
    "SPCP candidate of a run scored the same (each is printed as a WARNING line naming the "
    "file, and listed in the report); for CI"
)


def prog(module_prog: str) -> str:
    """The program name for ``--help``: ``sumo-ayss <command>`` when run through this CLI,
    else ``module_prog`` (e.g. ``python -m sumo_ayss.train``)."""
    return _invoked_as or module_prog


def usage() -> str:
    lines = ["usage: sumo-ayss <command> [args...]", "", "commands:"]
    lines += [f"  {name:<17} {help_}" for name, (_, help_) in COMMANDS.items()]
    lines += ["", "sumo-ayss <command> --help: that command's options"]
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> None:
    # The commands import ``sumo_ayss.cli``; under ``python -m sumo_ayss.cli`` this module is
    # ``__main__``, a different object: set the name where the commands read it.
    canonical = importlib.import_module("sumo_ayss.cli")
    args = list(sys.argv[1:] if argv is None else argv)
    if not args or args[0] in ("-h", "--help"):
        print(usage())
        return
    if args[0] not in COMMANDS:
        sys.exit(f"error: unknown command {args[0]!r}\n{usage()}")
    module = importlib.import_module(COMMANDS[args[0]][0])
    name = f"sumo-ayss {args[0]}"
    setattr(canonical, "_invoked_as", name)  # noqa: B010 (mypy: a module object)
    sys.argv = [name, *args[1:]]
    try:
        rc = module.main(args[1:])
    finally:
        setattr(canonical, "_invoked_as", None)  # noqa: B010
    if isinstance(rc, int) and rc:
        sys.exit(rc)


if __name__ == "__main__":
    main()
