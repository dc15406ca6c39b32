"""``python -m sumo_ayss.replay``: see :mod:`sumo_ayss.replay.cli`."""

import sys

from sumo_ayss.replay.cli import main

__all__ = ["main"]

if __name__ == "__main__":
    sys.exit(main())
