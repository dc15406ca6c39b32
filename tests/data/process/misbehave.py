"""A process VUT that breaks the line protocol on request (``--mode``), after ``--after``
good steps: ``silent`` never answers the hello, ``die`` exits with code 3, ``hang`` stops
answering, ``garbage`` answers nonsense, ``error`` reports an error, ``version`` refuses
the protocol version."""

from __future__ import annotations

import argparse
import sys
import time

parser = argparse.ArgumentParser()
parser.add_argument("--mode", required=True)
parser.add_argument("--after", type=int, default=2)
args = parser.parse_args()


def answer(line: str) -> None:
    sys.stdout.write(line + "\n")
    sys.stdout.flush()


steps = 0
for line in sys.stdin:
    word = line.split()[0]
    if word == "sumo_ayss-vut":
        if args.mode == "silent":
            time.sleep(60)
        answer("error version 1 unknown" if args.mode == "version" else "ok 1")
    elif word == "reset":
        answer("ok")
    elif word == "step":
        steps += 1
        if steps <= args.after:
            answer("accel 0.5")
        elif args.mode == "die":
            print("lost the sensor bus", file=sys.stderr)
            sys.exit(3)
        elif args.mode == "hang":
            time.sleep(60)
        elif args.mode == "garbage":
            answer("accelerate please")
        elif args.mode == "error":
            answer("error radar blinded")
        else:
            answer("accel 0.5")
    elif word == "quit":
        break
