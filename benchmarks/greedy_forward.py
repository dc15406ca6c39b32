"""The greedy policy's forward pass: NumPy on the host against torch, by batch size.

    python benchmarks/greedy_forward.py [--calls 2000] [--threads 1]

Builds the learner's default network (:class:`~sumo_ayss.agents.policies.DuelingQNetwork`,
256-wide layers, untrained) for the cut-in case's spaces and times
:meth:`~sumo_ayss.agents.greedy.GreedyPolicy.q_values` through both paths, side by side in
one run, for 1 to 64 observations per call: an episode (the outcome stage, cross-play) asks
for one at a time, a vec env's evaluation for 8, Monte Carlo for thousands. Prints the
microseconds per call, the ratio, the largest difference between the two paths' Q-values and
whether their argmax agree. :data:`~sumo_ayss.agents.greedy.HOST_MAX_BATCH` is the batch
size up to which the policy takes the NumPy path.
"""

from __future__ import annotations

import argparse
import os
import time


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--calls", type=int, default=2000, help="calls per measurement")
    parser.add_argument("--threads", type=int, default=1, help="BLAS and torch threads")
    args = parser.parse_args()
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ[var] = str(args.threads)  # before numpy and torch are imported
    import numpy as np
    import torch as th

    from sumo_ayss.agents.dqn import AyssDQN
    from sumo_ayss.agents.greedy import HOST_MAX_BATCH, GreedyPolicy, _host_q
    from sumo_ayss.agents.hparams import DQNHyperParams
    from sumo_ayss.envs.cut_in import CutInEnv

    th.set_num_threads(args.threads)
    env = CutInEnv()  # spaces only: SUMO never starts
    policy = GreedyPolicy(AyssDQN(env, DQNHyperParams(), seed=0))
    host = policy._host
    assert host is not None, "the default network must take the NumPy path"
    rng = np.random.default_rng(0)
    d = int(np.prod(env.observation_space.shape or (1,)))
    print(f"threads {args.threads}, {args.calls} calls each; NumPy path up to {HOST_MAX_BATCH}")
    head = ("batch", "torch us", "numpy us", "torch/numpy", "max |dq|")
    print(f"{head[0]:>5} {head[1]:>9} {head[2]:>9} {head[3]:>11} {head[4]:>9} argmax")
    for n in (1, 2, 4, 8, 64):
        obs = rng.uniform(0.0, 30.0, size=(n, d)).astype(np.float32)
        timings = {}
        for name, path in (("torch", None), ("numpy", host)):
            policy._host = path
            policy.q_values(obs)
            t0 = time.perf_counter()
            for _ in range(args.calls):
                policy.q_values(obs)
            timings[name] = (time.perf_counter() - t0) / args.calls * 1e6
        policy._host = None
        q_torch = policy.q_values(obs)
        policy._host = host
        q_numpy = _host_q(host, obs)
        same = bool((q_torch.argmax(1) == q_numpy.argmax(1)).all())
        print(
            f"{n:>5} {timings['torch']:>9.0f} {timings['numpy']:>9.0f} "
            f"{timings['torch'] / timings['numpy']:>11.2f} {np.abs(q_torch - q_numpy).max():>9.1e} "
            f"{'same' if same else 'DIFFER'}"
        )
    env.close()


if __name__ == "__main__":
    main()
