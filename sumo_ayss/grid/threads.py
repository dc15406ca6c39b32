"""Thread settings for processes that each run one job beside others on shared cores.

A DQN gradient step here is a few small matrix products (batch 64, 256 wide) and a greedy
policy call is one row: far too little work to split over threads. With torch's default
(one intra-op thread per core) every process of a pool of N workers on N cores spins N
threads, and on a loaded machine each op waits for a thread whose core is busy elsewhere:
measured on the 2-core machine with another grid running, the outcome + AYSS evaluation of
one run took 46 s with torch's default 2 threads and 6.6 s with 1 (docs/performance.md).

:func:`single_thread_env` is for a fresh worker process, before it imports torch or numpy's
BLAS; :func:`set_torch_threads` sets torch's intra-op threads in a running process.
"""

from __future__ import annotations

import os

#: Thread-count variables read once, at import, by OpenMP (torch's intra-op pool), MKL,
#: OpenBLAS and numexpr.
THREAD_ENV_VARS: tuple[str, ...] = (
    "OMP_NUM_THREADS",
    "MKL_NUM_THREADS",
    "OPENBLAS_NUM_THREADS",
    "NUMEXPR_NUM_THREADS",
)


def single_thread_env() -> dict[str, str]:
    """Set each of :data:`THREAD_ENV_VARS` to ``"1"`` unless the user has set it.

    Takes effect for libraries imported after the call (torch reads ``OMP_NUM_THREADS`` when
    it is imported), and for child processes started after it.

    Returns:
        The variables this call set (name -> value); those already set are left alone.
    """
    changed = {}
    for name in THREAD_ENV_VARS:
        if name not in os.environ:
            os.environ[name] = changed[name] = "1"
    return changed


def set_torch_threads(n: int) -> None:
    """Use ``n`` intra-op threads in torch (``train.torch_threads``), >= 1.

    Torch's inter-op pool is left alone: nothing here runs inter-op parallel work, so torch
    never starts it (checked: a training process holds 2 threads with torch's defaults).

    Args:
        n: Intra-op threads.
    """
    import torch

    if torch.get_num_threads() != n:
        torch.set_num_threads(n)
