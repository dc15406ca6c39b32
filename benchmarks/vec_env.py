"""PairVecEnv throughput: env steps/s and DQN training transitions/s, N pairs vs one env.

Env steps/s (random actions, resets included; one "step" = one transition of one pair):

* ``single env``: ``CarFollowingEnv.step`` in a plain loop (the env alone);
* ``single env in SB3``: the same env as training with ``n_envs = 1`` runs it,
  ``DummyVecEnv([Monitor(env)])``;
* ``PairVecEnv N``: N pairs in one SUMO simulation, N = 1, 8, 32, 128;
* ``SubprocVecEnv N``: N single envs in N worker processes (one libsumo each), N = 2, 8.

Training transitions/s: :class:`~sumo_ayss.agents.AyssDQN` with the paper's
hyper-parameters (2x256 nets, double, dueling, PER) at the default update-to-data ratio
(0.25 gradient steps per transition; with N pairs ``train_freq``/``gradient_steps`` are
rescaled by :func:`sumo_ayss.train.hparams_for_n_envs`), one torch thread, timed over the
transitions collected after ``learning_starts``, for ``n_envs`` = 1 and 8.

    python benchmarks/vec_env.py [--case car_following] [--seconds 3] [--train-steps 5000]

Targets (issue 7): PairVecEnv N = 32 >= 3x the single env's steps/s; training with
``n_envs = 8`` >= 2x single-env training throughput. Wall-clock numbers: other work on the
machine slows them (the load average is printed before and after).
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
import time
from collections.abc import Callable

import numpy as np
import torch as th
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.monitor import Monitor
from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv, VecEnv, VecMonitor

from sumo_ayss.agents import AyssDQN
from sumo_ayss.agents.hparams import DQNHyperParams
from sumo_ayss.config import EnvConfig
from sumo_ayss.envs import make_env
from sumo_ayss.envs.pair_env import PairEnv
from sumo_ayss.envs.vec_env import PairVecEnv
from sumo_ayss.training.trainer import hparams_for_n_envs

#: Random actions are drawn ahead of the timed loop, in blocks of about this many transitions.
_BLOCK = 4096


def _timed(
    run_block: Callable[[np.ndarray], None], n_actions: int, width: int, seconds: float
) -> float:
    """Steps/s of ``run_block`` (one call per block of random actions) for >= ``seconds``."""
    rng = np.random.default_rng(0)
    rows = max(8, _BLOCK // width)
    blocks = 0
    t0 = time.perf_counter()
    while True:
        run_block(rng.integers(0, n_actions, size=(rows, width)))
        blocks += 1
        elapsed = time.perf_counter() - t0
        if elapsed >= seconds:
            return blocks * rows * width / elapsed


def bench_single(config: EnvConfig, seconds: float) -> float:
    env = make_env(config, sumo_seed=0)
    env.reset(seed=0)

    def run(actions: np.ndarray) -> None:
        for a in actions[:, 0].tolist():
            _, _, terminated, truncated, _ = env.step(a)
            if terminated or truncated:
                env.reset()

    try:
        return _timed(run, int(env.action_space.n), 1, seconds)  # type: ignore[attr-defined]
    finally:
        env.close()


def _bench_vec(vec: VecEnv, seconds: float) -> float:
    vec.seed(0)
    vec.reset()

    def run(actions: np.ndarray) -> None:
        for row in actions:
            vec.step(row)

    try:
        return _timed(run, int(vec.action_space.n), vec.num_envs, seconds)  # type: ignore[attr-defined]
    finally:
        vec.close()


def bench_single_sb3(config: EnvConfig, seconds: float) -> float:
    env = make_env(config, sumo_seed=0)
    return _bench_vec(DummyVecEnv([lambda: Monitor(env)]), seconds)


def bench_pairs(config: EnvConfig, n: int, seconds: float) -> float:
    return _bench_vec(PairVecEnv(config, n, sumo_seed=0), seconds)


def _worker_env(config: EnvConfig, index: int) -> Callable[[], Monitor]:
    def make() -> Monitor:
        return Monitor(make_env(config, sumo_seed=index))

    return make


def bench_subproc(config: EnvConfig, n: int, seconds: float) -> float:
    # forkserver: the workers start from a clean process, each owning one libsumo.
    fns = [_worker_env(config, i) for i in range(n)]
    return _bench_vec(SubprocVecEnv(fns, start_method="forkserver"), seconds)


class _StartClock(BaseCallback):
    """Notes the time and step count when learning starts (the first gradient step)."""

    def __init__(self, learning_starts: int) -> None:
        super().__init__()
        self.learning_starts = learning_starts
        self.t0: float | None = None
        self.step0 = 0

    def _on_step(self) -> bool:
        if self.t0 is None and self.num_timesteps >= self.learning_starts:
            self.t0, self.step0 = time.perf_counter(), self.num_timesteps
        return True


def bench_training(config: EnvConfig, n_envs: int, transitions: int) -> tuple[float, float]:
    """``(transitions/s, gradient steps per transition)`` after ``learning_starts``."""
    th.set_num_threads(1)
    hp = hparams_for_n_envs(DQNHyperParams(), n_envs)
    if n_envs == 1:
        env: PairEnv = make_env(config, sumo_seed=0)
        vec: VecEnv = DummyVecEnv([lambda: Monitor(env)])
    else:
        vec = VecMonitor(PairVecEnv(config, n_envs, sumo_seed=0))
    try:
        model = AyssDQN(vec, hp, seed=0)
        clock = _StartClock(hp.learning_starts)
        model.learn(total_timesteps=hp.learning_starts + transitions, callback=clock)
        assert clock.t0 is not None
        elapsed = time.perf_counter() - clock.t0
        done = model.num_timesteps - clock.step0
        return done / elapsed, model._n_updates / max(model.num_timesteps - hp.learning_starts, 1)
    finally:
        vec.close()


def _load() -> str:
    return "load average (1, 5, 15 min): " + ", ".join(f"{x:.2f}" for x in os.getloadavg())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", default="car_following", choices=["car_following", "cut_in"])
    parser.add_argument("--seconds", type=float, default=3.0, help="per env measurement")
    parser.add_argument("--train-steps", type=int, default=5000, help="after learning_starts")
    parser.add_argument("--pairs", type=int, nargs="+", default=[1, 8, 32, 128])
    parser.add_argument("--procs", type=int, nargs="+", default=[2, 8])
    parser.add_argument("--no-train", action="store_true")
    args = parser.parse_args()
    config = EnvConfig(case=args.case)
    print(f"case {args.case}, {os.cpu_count()} CPUs; {_load()}")

    single = bench_single(config, args.seconds)
    rows = [("single env (env.step loop)", single)]
    rows.append(("single env in SB3 (DummyVecEnv)", bench_single_sb3(config, args.seconds)))
    rows += [(f"PairVecEnv N={n}", bench_pairs(config, n, args.seconds)) for n in args.pairs]
    rows += [(f"SubprocVecEnv N={n}", bench_subproc(config, n, args.seconds)) for n in args.procs]
    print(f"\n{'env steps (random actions, resets included)':<44}{'steps/s':>10}{'vs single':>11}")
    for name, rate in rows:
        print(f"{name:<44}{rate:>10,.0f}{rate / single:>10.2f}x")

    if not args.no_train:
        print(
            f"\n{'AyssDQN training (paper hparams, 1 thread)':<44}{'trans/s':>10}{'vs n=1':>11}"
            f"{'grad/trans':>12}"
        )
        base = 0.0
        for n in (1, 8):
            rate, ratio = bench_training(config, n, args.train_steps)
            base = base or rate
            print(f"{'n_envs=' + str(n):<44}{rate:>10,.0f}{rate / base:>10.2f}x{ratio:>12.3f}")
    print(f"\n{_load()}")
    print("targets: PairVecEnv N=32 >= 3x single env; training n_envs=8 >= 2x n_envs=1")


if __name__ == "__main__":
    multiprocessing.set_start_method("forkserver", force=True)
    main()
