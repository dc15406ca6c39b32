"""Draw ``docs/reward_shapes.png``: the default adversarial reward shapes (the report's
figure of the configured shapes, :func:`~sumo_ayss.report.figures.reward_shapes_figure`,
for the default :class:`~sumo_ayss.config.RewardConfig`).

    python -m sumo_ayss.report.reward_shapes [--out PATH]
"""

from __future__ import annotations

import argparse
from pathlib import Path

from sumo_ayss.config import PROJECT_ROOT, RewardConfig
from sumo_ayss.report.figures import reward_shapes_figure

__all__ = ["main"]


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--out", type=Path, default=PROJECT_ROOT / "docs" / "reward_shapes.png")
    args = parser.parse_args(argv)
    print(reward_shapes_figure(RewardConfig(), args.out, styled=False))


if __name__ == "__main__":
    main()
