"""How much slower is one gradient step when several training jobs share the machine?

The pipeline runs one training job per worker process, one torch thread each. This prints,
from one run, the time of one gradient step (``AyssDQN.train``, the paper's network, batch
64, PER, fused Adam: the same case as ``benchmarks/learner.py``'s ``ours``) in one process
alone, then in ``k`` processes at once, for every ``k`` up to ``--processes`` (default: the
number of cores), interleaved over ``--rounds`` rounds. The ratio ``k at once / alone`` is
the slow-down that the grid's wall clock pays over the single-job learner figure
(``1 / ratio`` of the ideal ``k``-fold speed-up is lost to shared caches, memory bandwidth,
frequency and, in a VM, to whatever the host maps the virtual cores to).

Run: ``python benchmarks/parallel_steps.py [--help]``.
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import os
import statistics
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # benchmarks/learner.py


def _worker(steps: int, warmup: int, start: mp.synchronize.Barrier, out: mp.Queue) -> None:
    """Build a learner, wait for the others, time ``steps`` gradient steps, report µs/step."""
    import torch as th
    from learner import BATCH, DummyEnv, fill
    from stable_baselines3.common.logger import Logger

    from sumo_ayss.agents import AyssDQN, DQNHyperParams

    th.set_num_threads(1)
    model = AyssDQN(DummyEnv(), DQNHyperParams(), seed=0)
    fill(model.replay_buffer, 20_000, np.random.default_rng(os.getpid()))  # type: ignore[arg-type]
    model.set_logger(Logger(folder=None, output_formats=[]))
    model.train(warmup, BATCH)
    start.wait()
    t0 = time.perf_counter()
    for _ in range(steps // 2):
        model.train(2, BATCH)  # the default job: 2 gradient steps per train() call
    out.put((time.perf_counter() - t0) / steps * 1e6)


def _time(k: int, steps: int, warmup: int) -> float:
    """Mean µs per gradient step over ``k`` processes stepping at the same time."""
    ctx = mp.get_context("spawn")
    start, out = ctx.Barrier(k), ctx.Queue()
    procs = [ctx.Process(target=_worker, args=(steps, warmup, start, out)) for _ in range(k)]
    for p in procs:
        p.start()
    times = [out.get() for _ in procs]
    for p in procs:
        p.join()
    return statistics.mean(times)


def main() -> None:
    """Parse options, time 1..k processes interleaved, print the table."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--processes", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--steps", type=int, default=600, help="timed gradient steps per process")
    parser.add_argument("--warmup", type=int, default=50)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    ks = list(range(1, args.processes + 1))
    results: dict[int, list[float]] = {k: [] for k in ks}
    for r in range(args.rounds):
        for k in ks[r % len(ks) :] + ks[: r % len(ks)]:
            results[k].append(_time(k, args.steps, args.warmup))
    alone = statistics.median(results[1])
    print(f"{os.cpu_count()} cores, load before: {os.getloadavg()[0]:.2f} (1 min)")
    print("processes  median us/step  min us/step  vs alone  throughput vs alone")
    for k in ks:
        med = statistics.median(results[k])
        print(
            f"{k:9d}  {med:13.0f}  {min(results[k]):11.0f}  {med / alone:8.2f}  "
            f"{k * alone / med:19.2f}"
        )


if __name__ == "__main__":
    main()
