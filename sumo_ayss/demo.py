"""``make demo``: a few CarFollowing-v0 episodes per paper VUT with scripted POV policies.

A first look at the env until the full pipeline lands: for each VUT and each scripted POV
policy it runs episodes on the same initial conditions and prints mean episode reward,
crash rate and mean final headway.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable

import numpy as np

from sumo_ayss.envs.car_following import CarFollowingEnv
from sumo_ayss.envs.odd import sample_initial_conditions

Policy = Callable[[np.ndarray], int]


def hold_speed(obs: np.ndarray) -> int:
    return 2  # target = 1.0 · v_pov


def brake_hard(obs: np.ndarray) -> int:
    return 0  # target = 0


def close_in(obs: np.ndarray) -> int:
    """Slow down while the gap is large, hold speed once within 2 m."""
    return 1 if obs[2] > 2.0 else 2


POLICIES: dict[str, Policy] = {"hold": hold_speed, "brake": brake_hard, "close-in": close_in}


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=20)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    print(f"{'VUT':<5}{'POV policy':<12}{'mean reward':>12}{'crash %':>9}{'final h [m]':>13}")
    for vut in ("pi1", "pi2"):
        env = CarFollowingEnv(vut=vut, sumo_seed=args.seed)
        scenarios = sample_initial_conditions(env.config.odd, args.episodes, args.seed)
        try:
            for name, policy in POLICIES.items():
                returns, crashes, final_h = [], 0, []
                for ic in scenarios:
                    obs, _ = env.reset(options={"initial_condition": ic})
                    total, done = 0.0, False
                    while not done:
                        obs, r, term, trunc, info = env.step(policy(obs))
                        total += float(r)
                        done = term or trunc
                    returns.append(total)
                    crashes += bool(info["collision"])
                    final_h.append(info["headway_m"])
                print(
                    f"{vut:<5}{name:<12}{np.mean(returns):>12.2f}"
                    f"{100 * crashes / len(scenarios):>9.1f}{np.mean(final_h):>13.2f}"
                )
        finally:
            env.close()


if __name__ == "__main__":
    main()
