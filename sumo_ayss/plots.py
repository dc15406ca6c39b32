"""Figures that document the configuration (reward shapes). ``python -m sumo_ayss.plots``."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from sumo_ayss.config import PROJECT_ROOT, RewardConfig
from sumo_ayss.envs.rewards import adversarial_reward_array


def plot_reward_shapes(cfg: RewardConfig, path: Path) -> Path:
    """Draw R_A(h) for the same-lane and the lane-change shapes of ``cfg`` into ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 3.6), constrained_layout=True)
    panels = [
        ("same lane (car-following; cut-in after the change)", cfg.same_lane, 25.0),
        ("while changing lanes (cut-in)", cfg.lane_change, 8.0),
    ]
    for ax, (title, shape, h_max) in zip(axes, panels, strict=True):
        h = np.linspace(0.0, h_max, 801)
        r = cfg.alpha_adversarial * adversarial_reward_array(h, shape)
        ax.plot(h, r, color="tab:blue", lw=2, label=f"R = α_A·R_A ({shape.kind})")
        ax.axvline(
            shape.peak_m, color="tab:green", ls="--", lw=1, label=f"peak h = {shape.peak_m} m"
        )
        ax.axvline(
            shape.zero_m, color="tab:gray", ls=":", lw=1, label=f"zero for h ≥ {shape.zero_m} m"
        )
        contact = cfg.alpha_adversarial * shape.value_at_contact
        ax.scatter([0.0], [contact], color="tab:blue", zorder=3, s=12)
        ax.set_title(title)
        ax.set_xlabel("headway h [m]")
        ax.set_ylabel("reward per step")
        ax.set_ylim(-0.05, cfg.alpha_adversarial * 1.05)
        ax.grid(alpha=0.3)
        ax.legend(loc="upper right", fontsize=8)
    fig.suptitle(
        f"Adversarial reward shapes; a collision step gets the minimum {cfg.min_reward:g} "
        "and ends the episode",
        fontsize=10,
    )
    from sumo_ayss.atomic import atomic_write_with

    atomic_write_with(path, lambda tmp: fig.savefig(tmp, dpi=120))
    plt.close(fig)
    return path


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=PROJECT_ROOT / "docs" / "reward_shapes.png")
    args = parser.parse_args(argv)
    print(plot_reward_shapes(RewardConfig(), args.out))


if __name__ == "__main__":
    main()
