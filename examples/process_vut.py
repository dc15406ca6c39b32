"""Reference client of the process-VUT line protocol (version 1): a time-gap ACC.

The testbed starts this program, writes one line per message to its standard input and
reads one line per answer from its standard output (:mod:`sumo_ayss.vuts.process`)::

    sumo_ayss-vut 1 <signal> ...   ->  ok 1              (once: the signals of each step)
    reset <k>                      ->  ok                (every episode of VUT instance k)
    step <k> <value> ...           ->  accel <m/s²>      (every SUMO step of instance k)
    quit                           ->  (exit)

One process serves every VUT instance ``k`` of a vectorised env; this law keeps no state,
so it ignores ``k`` (a controller with state would keep one per ``k``).

It needs nothing but Python's standard library, so it reads as a template for a client in
any language: read a line, split on spaces, answer one line, flush. The law is
``examples/acc_controller.py``'s TimeGapACC (same operations in the same order, so that the
process and the Python controller command the same numbers).

YAML::

    acc_proc:
      process:
        command: [python, examples/process_vut.py, --time-gap, "2.0"]
        signals: [speed_mps, gap_m, rel_speed_mps, has_leader]
        max_accel_mps2: 3.0
        max_decel_mps2: 6.0
"""

from __future__ import annotations

import argparse
import sys

NEEDED = ("speed_mps", "gap_m", "rel_speed_mps", "has_leader")


def acceleration(args: argparse.Namespace, v: float, gap: float, rel: float, lead: bool) -> float:
    """TimeGapACC's command [m/s²] from own speed, gap, relative speed and leader flag."""
    accel = args.cruise_gain * (args.set_speed - v)
    if lead:
        spacing_error = gap - (args.standstill_gap + args.time_gap * v)
        accel = min(accel, args.gap_gain * spacing_error + args.rel_speed_gain * rel)
    return min(max(accel, -args.max_decel), args.max_accel)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    for name, default in (
        ("time-gap", 1.5),
        ("standstill-gap", 5.0),
        ("gap-gain", 0.3),
        ("rel-speed-gain", 0.8),
        ("set-speed", 30.0),
        ("cruise-gain", 0.4),
        ("max-accel", 3.0),
        ("max-decel", 6.0),
    ):
        parser.add_argument(f"--{name}", type=float, default=default)
    args = parser.parse_args()

    def answer(line: str) -> None:
        sys.stdout.write(line + "\n")
        sys.stdout.flush()

    index: dict[str, int] = {}
    for line in sys.stdin:
        words = line.split()
        if not words:
            continue
        if words[0] == "sumo_ayss-vut":
            if words[1] != "1":
                answer(f"error protocol version {words[1]} not supported (1 is)")
                return 1
            index = {name: i for i, name in enumerate(words[2:])}
            missing = [n for n in NEEDED if n not in index]
            if missing:
                answer(f"error this ACC needs the signals {missing}")
                return 1
            answer("ok 1")
        elif words[0] == "reset":
            answer("ok")  # the law keeps no state
        elif words[0] == "step":
            values = words[2:]  # words[1] is the instance k
            v, gap, rel = (float(values[index[n]]) for n in NEEDED[:3])
            lead = values[index["has_leader"]] == "1"
            answer(f"accel {acceleration(args, v, gap, rel, lead)!r}")
        elif words[0] == "quit":
            return 0
        else:
            answer(f"error unknown message {words[0]!r}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
