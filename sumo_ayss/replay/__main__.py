"""``python -m sumo_ayss.replay``."""

import sys

from sumo_ayss.replay.cli import main

sys.exit(main())
