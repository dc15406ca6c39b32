"""Env throughput: CarFollowing-v0 (random policy, resets included) vs a raw libsumo loop.

Both run in this one process, one after the other, on the same scene (one VUT-POV pair,
5 s episodes of 25 steps, fresh vehicles each episode). The raw loop does the minimum of
libsumo calls the scene needs, with no Python env around it: it is the ceiling.

    python benchmarks/env_throughput.py [--steps 60000] [--repeats 3]
    python benchmarks/env_throughput.py --follower    # the cost of issue 33's follower
    python benchmarks/env_throughput.py --cases cut_in lead_and_cut_in  # per case (issue 39)

With ``--follower`` each case runs twice on the outcome stage's path (every reset from a
given initial condition of a scenario set): without and with the follower behind the VUT.

Targets (issue 2): >= 30,000 env steps/s and >= 35 % of the raw loop.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from sumo_ayss.config import SimConfig
from sumo_ayss.envs.car_following import CarFollowingEnv
from sumo_ayss.sim.network import network_path
from sumo_ayss.sim.session import SumoSession
from sumo_ayss.vuts.catalog import BUILTIN_VUTS, POV_TYPE


def bench_env(env_cls: type, steps: int) -> float:
    env = env_cls()
    rng = np.random.default_rng(0)
    actions = rng.integers(0, env.action_space.n, size=steps)
    env.reset(seed=0)
    t0 = time.perf_counter()
    for a in actions:
        _, _, term, trunc, _ = env.step(int(a))
        if term or trunc:
            env.reset()
    dt = time.perf_counter() - t0
    env.close()
    return steps / dt


def bench_follower(case: str, steps: int, follower: bool) -> float:
    """Env steps/s on given initial conditions (the outcome stage's resets), with or
    without the follower (issue 33), random actions."""
    from sumo_ayss.config import EnvConfig, FollowerConfig
    from sumo_ayss.envs import make_env
    from sumo_ayss.envs.odd import sample_initial_conditions, with_followers

    cfg = EnvConfig(case=case, follower=FollowerConfig(enabled=follower))
    ics = with_followers(sample_initial_conditions(cfg.odd, steps // 10 + 1, 0), cfg.follower, 0)
    env = make_env(cfg, sumo_seed=0)
    rng = np.random.default_rng(0)
    actions = rng.integers(0, env.action_space.n, size=steps)
    k = 0
    env.reset(options={"initial_condition": ics[k]})
    t0 = time.perf_counter()
    for a in actions:
        _, _, term, trunc, _ = env.step(int(a))
        if term or trunc:
            k += 1
            env.reset(options={"initial_condition": ics[k]})
    dt = time.perf_counter() - t0
    env.close()
    return steps / dt


def bench_case(case: str, steps: int) -> dict[str, float]:
    """Env steps/s of ``case`` on the outcome stage's path (given initial conditions of a
    scenario set, random actions), with the episodes, crashes and, for a case that labels
    its crashes online (lead_and_cut_in), the replays and their share of the wall time."""
    from sumo_ayss.config import EnvConfig
    from sumo_ayss.envs import make_env
    from sumo_ayss.envs.odd import sample_initial_conditions

    cfg = EnvConfig(case=case)
    ics = sample_initial_conditions(cfg.odd, steps + 1, 0)
    env = make_env(cfg, sumo_seed=0)
    rng = np.random.default_rng(0)
    actions = rng.integers(0, env.action_space.n, size=steps)
    k = episodes = crashes = 0
    env.reset(options={"initial_condition": ics[k]})
    t0 = time.perf_counter()
    for a in actions:
        _, _, term, trunc, info = env.step(int(a))
        if term or trunc:
            episodes += 1
            crashes += bool(info["collision"])
            k += 1
            env.reset(options={"initial_condition": ics[k]})
    dt = time.perf_counter() - t0
    replays, replay_s = getattr(env, "replays", 0), getattr(env, "replay_wall_s", 0.0)
    env.close()
    return {
        "steps_per_s": steps / dt,
        "episodes": episodes,
        "crashes": crashes,
        "replays": replays,
        "replay_share": replay_s / dt,
    }


def bench_raw(steps: int) -> float:
    import libsumo

    types = {"vut_pi1": BUILTIN_VUTS["pi1"], "pov": POV_TYPE}
    session = SumoSession(network_path("car_following"), types, SimConfig(), 0, "raw bench")
    session.start()
    libsumo.route.add("r", ["road"])
    rng = np.random.default_rng(0)
    v = rng.uniform(10, 30, size=steps)
    ep = 0
    vut = pov = ""
    t0 = time.perf_counter()
    for i in range(steps):
        if i % 25 == 0:  # new episode: fresh vehicles, one insertion step, exact placement
            if vut:
                libsumo.vehicle.remove(vut)
                libsumo.vehicle.remove(pov)
            ep += 1
            vut, pov = f"v{ep}", f"p{ep}"
            libsumo.vehicle.add(pov, "r", "pov", "now", "0", "60", "0")
            libsumo.vehicle.add(vut, "r", "vut_pi1", "now", "0", "10", "0")
            libsumo.simulationStep()
            libsumo.vehicle.setSpeedMode(pov, 0)
            libsumo.vehicle.moveTo(pov, "road_0", 170.0)
            libsumo.vehicle.moveTo(vut, "road_0", 150.0)
            libsumo.vehicle.setPreviousSpeed(pov, 20.0)
            libsumo.vehicle.setPreviousSpeed(vut, 20.0)
        libsumo.vehicle.setSpeed(pov, v[i])
        libsumo.simulationStep()
        libsumo.vehicle.getLanePosition(pov)
        libsumo.vehicle.getSpeed(pov)
        libsumo.vehicle.getLanePosition(vut)
        libsumo.vehicle.getSpeed(vut)
        libsumo.simulation.getCollidingVehiclesNumber()
    dt = time.perf_counter() - t0
    session.close()
    return steps / dt


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=60_000)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--follower", action="store_true", help="the follower's cost")
    parser.add_argument("--cases", nargs="+", default=None, help="steps/s per case")
    args = parser.parse_args()
    if args.cases:
        print(
            f"{'case':<18}{'steps/s (median)':>18}{'min':>10}{'max':>10}{'episodes':>10}"
            f"{'crashes':>9}{'replays':>9}{'replay share':>14}"
        )
        for case in args.cases:
            runs = [bench_case(case, args.steps) for _ in range(args.repeats)]
            rates = [r["steps_per_s"] for r in runs]
            last = runs[-1]
            print(
                f"{case:<18}{statistics.median(rates):>18,.0f}{min(rates):>10,.0f}"
                f"{max(rates):>10,.0f}{last['episodes']:>10}{last['crashes']:>9}"
                f"{last['replays']:>9}{statistics.median(r['replay_share'] for r in runs):>14.1%}"
            )
        return
    if args.follower:
        print(f"{'case':<16}{'follower':>9}{'steps/s (median)':>18}{'min':>10}{'max':>10}")
        for case in ("car_following", "cut_in"):
            for on in (False, True):
                runs = [bench_follower(case, args.steps, on) for _ in range(args.repeats)]
                med = statistics.median(runs)
                print(
                    f"{case:<16}{'on' if on else 'off':>9}{med:>18,.0f}{min(runs):>10,.0f}"
                    f"{max(runs):>10,.0f}"
                )
        return
    cases: dict[str, object] = {"CarFollowing-v0": CarFollowingEnv}
    try:
        from sumo_ayss.envs.cut_in import CutInEnv

        cases["CutIn-v0"] = CutInEnv
    except ImportError:
        pass
    raw = [bench_raw(args.steps) for _ in range(args.repeats)]
    raw_med = statistics.median(raw)
    print(f"{'loop':<22}{'steps/s (median)':>18}{'min':>10}{'max':>10}{'vs raw':>9}")
    print(f"{'raw libsumo':<22}{raw_med:>18,.0f}{min(raw):>10,.0f}{max(raw):>10,.0f}{1:>9.0%}")
    for name, cls in cases.items():
        runs = [bench_env(cls, args.steps) for _ in range(args.repeats)]  # type: ignore[arg-type]
        med = statistics.median(runs)
        print(f"{name:<22}{med:>18,.0f}{min(runs):>10,.0f}{max(runs):>10,.0f}{med / raw_med:>9.0%}")
    print("targets: >= 30,000 env steps/s; >= 35 % of the raw loop")


if __name__ == "__main__":
    main()
