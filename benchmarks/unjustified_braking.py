"""Issue 33: how often the unjustified-braking rule fires, before and after its session-10
revision, on the same episodes (real SUMO, follower on).

Each VUT (pi1, pi2, the over-braker) drives both cases from the same ODD scenarios against
the same scripted, seeded POV: per decision it brakes hard (8 %), brakes mildly (12 %),
holds its speed (65 %) or speeds up (15 %); in cut-in it also changes lanes once, at a
random decision. The episodes' trajectories are scored by both rules
(:func:`sumo_ayss.analysis.hazards.unjustified_braking` with and without the revision's
clauses), and the samples the first rule called unjustified are described (time headway,
closing speed, the POV's braking just before), so the change can be read against them.

    python benchmarks/unjustified_braking.py [--episodes 300]
"""

from __future__ import annotations

import argparse
from collections.abc import Callable

import numpy as np

from sumo_ayss.analysis.hazards import (
    REACTION_WINDOW_S,
    overbraking_flags,
    r157_min_following_distance_m,
    unjustified_braking,
)
from sumo_ayss.analysis.safety_measures import PairTrajectory
from sumo_ayss.scenarios.scripted import scripted_episodes
from sumo_ayss.vuts.catalog import BUILTIN_VUTS
from sumo_ayss.vuts.reference_types import OVERBRAKER_VUT

VUTS = ("pi1", "pi2", "overbraker")
CASES = ("car_following", "cut_in")


def episodes(case: str, vut: str, n: int, seed: int = 11) -> list[PairTrajectory]:
    """``n`` episodes of ``vut`` in ``case`` (the same scenarios and POV for every VUT)."""
    return scripted_episodes(
        case, vut, {**BUILTIN_VUTS, "overbraker": OVERBRAKER_VUT}, n, seed=seed
    )


Rule = Callable[[PairTrajectory], np.ndarray]
RULES: dict[str, Rule] = {
    "first (session 9)": lambda tr: unjustified_braking(
        tr, reaction_window_s=0.0, following_distance=False
    ),
    "+ reaction window": lambda tr: unjustified_braking(tr, following_distance=False),
    "+ R157 following distance": lambda tr: unjustified_braking(tr, reaction_window_s=0.0),
    "revised (both)": unjustified_braking,
}


def describe(trs: list[PairTrajectory]) -> str:
    """Where the first rule fired: medians of time headway, closing speed, and shares."""
    thw, closing, below, led = [], [], [], []
    for tr in trs:
        ub = RULES["first (session 9)"](tr)
        gap = tr.pov_ahead_gap_m()
        pov_braking = -np.diff(tr.pov_speed_mps) / np.diff(tr.time_s)
        w = round(REACTION_WINDOW_S / float(tr.time_s[1] - tr.time_s[0]))
        for k in np.flatnonzero(ub > 0.0):
            v = tr.vut_speed_mps[k]
            thw.append(gap[k] / v if v > 0 else np.inf)
            closing.append(v - tr.pov_speed_mps[k])
            below.append(gap[k] < r157_min_following_distance_m(np.array(v)))
            led.append(pov_braking[max(0, k - w) : k].max(initial=0.0) >= ub[k] - 1e-6)
    if not thw:
        return "no firing"
    return (
        f"{len(thw)} decisions: THW median {np.median(thw):.2f} s, closing median "
        f"{np.median(closing):+.1f} m/s (opening in {np.mean(np.array(closing) < 0):.0%}), "
        f"below R157 distance {np.mean(below):.0%}, POV braked as hard within "
        f"{REACTION_WINDOW_S} s {np.mean(led):.0%}"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--episodes", type=int, default=300)
    args = ap.parse_args()
    for case in CASES:
        trs = {vut: episodes(case, vut, args.episodes) for vut in VUTS}
        print(f"== {case}: {args.episodes} episodes per VUT")
        for vut in VUTS:
            print(f"   first rule fired at {vut}: {describe(trs[vut])}")
        for name, rule in RULES.items():
            scores = {vut: [rule(tr) for tr in trs[vut]] for vut in VUTS}
            share = {v: np.mean([u.max(initial=0.0) > 0 for u in s]) for v, s in scores.items()}
            dv = {
                v: float(
                    np.mean(
                        [np.sum(u) * float(tr.time_s[1]) for u, tr in zip(s, trs[v], strict=True)]
                    )
                )
                for v, s in scores.items()
            }
            flags = overbraking_flags(dv)
            cells = "  ".join(
                f"{v} {share[v]:4.0%} {dv[v]:.2f} m/s{' FLAG' if flags[v] else ''}" for v in VUTS
            )
            print(f"   {name:27s} episodes, speed shed/ep: {cells}")


if __name__ == "__main__":
    main()
