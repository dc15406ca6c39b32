"""Training throughput of one default job against the learner's own limit, from one run.

For each ``--device`` (default: cpu), in this process:

1. **job**: one training job of ``--config`` (default ``configs/car_following.yaml``: 8 pairs
   in one SUMO simulation, the paper's learner) for ``--transitions`` transitions with the
   config's candidate schedule, through :class:`sumo_ayss.train.Trainer` exactly as
   ``python -m sumo_ayss.train`` runs it (run folder, candidates, checkpoints, selection) in a
   temporary folder. Reported: transitions/s over the whole job (SUMO start to SPCP selected)
   and over its ``learn`` phase alone, and the time in candidates (evaluation + checkpoint).
2. **learner step**: afterwards, on that job's own model and replay buffer, the time of one
   gradient step of ``AyssDQN.train`` (called as in training: ``gradient_steps`` steps per
   call) against a minimal raw-torch step of the same dueling network (same widths), batch and
   optimizer (fused Adam, same learning rate) on the same transitions: uniform minibatch from
   preallocated tensors, double-DQN target, Huber loss, backward, Adam step; no PER, no
   gradient clipping, no SB3. Interleaved rounds; medians.
3. **ratios**: learner step / raw-torch step (target <= 1.2), and the job's transitions/s
   as a fraction of the learner-bound limit ``1 / (learner step x gradient steps per
   transition)`` (target >= 0.8). The job makes no gradient steps before
   ``agent.learning_starts`` (1,000 transitions), so a short job can pass 1. Also printed:
   the share of the job's time spent inside ``AyssDQN.train`` (timed in the job itself), a
   direct reading of how learner-bound it is that does not mix two moments of a noisy
   machine.

    python benchmarks/throughput.py [--transitions 20000] [--device cpu cuda]

Every figure is given twice: by the wall clock, and by this process's CPU time (all its
threads; SUMO runs in-process through libsumo, so it counts). On an idle machine the two
agree; when other work shares the cores the wall clock measures the sharing, and the CPU-time
figures are the ones that say what the code costs. The load average is printed before and
after. ``--device cuda`` fails at once, naming the problem, where torch sees no
CUDA device.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import torch as th
from torch import nn
from torch.nn import functional as F

from sumo_ayss.agents import AyssDQN, PrioritizedReplayBuffer
from sumo_ayss.config import ExperimentConfig, TrainConfig, load_experiment
from sumo_ayss.training.trainer import Trainer, check_device, hparams_for_n_envs
from sumo_ayss.util.errors import ConfigError

ROOT = Path(__file__).resolve().parent.parent


def _load() -> str:
    return "load average (1, 5, 15 min): " + ", ".join(f"{x:.2f}" for x in os.getloadavg())


def _sync(device: str) -> None:
    if device.startswith("cuda"):
        th.cuda.synchronize()


@dataclasses.dataclass
class JobTimes:
    """Times of one job, s (wall clock, or this process's CPU time); transitions collected."""

    transitions: int
    total_s: float
    setup_s: float
    learn_s: float
    candidates_s: float
    n_candidates: int
    n_updates: int
    gradient_steps_s: float


def _clocks() -> tuple[float, float]:
    """(wall clock, this process's CPU time over all its threads), s."""
    return time.perf_counter(), time.process_time()


def run_job(
    cfg: ExperimentConfig, seed: int, out: Path
) -> tuple[tuple[JobTimes, JobTimes], Trainer]:
    """Run one job like :func:`sumo_ayss.train.train`; its (wall, CPU) times, open trainer.

    The caller closes the trainer (the learner benchmark reuses its model and buffer).
    """
    t0 = _clocks()
    trainer = Trainer(cfg, seed, out / cfg.env.case / cfg.env.vut / f"seed_{seed}")
    trainer.write_metadata(["benchmarks/throughput.py"])
    trainer.new_model()
    spent = [0.0, 0.0]
    calls = [0]
    candidate = trainer.candidate

    def timed_candidate(*args: object, **kwargs: object) -> None:
        start = _clocks()
        candidate(*args, **kwargs)  # type: ignore[arg-type]
        end = _clocks()
        spent[0] += end[0] - start[0]
        spent[1] += end[1] - start[1]
        calls[0] += 1

    trainer.candidate = timed_candidate  # type: ignore[method-assign]
    model = trainer.model
    assert model is not None
    learner = [0.0, 0.0]
    cls = type(model)
    original_train = cls.train

    def timed_train(self: AyssDQN, gradient_steps: int, batch_size: int = 100) -> None:
        start = _clocks()
        original_train(self, gradient_steps, batch_size)
        end = _clocks()
        learner[0] += end[0] - start[0]
        learner[1] += end[1] - start[1]

    # On the class, for the job only: SB3's save pickles instance attributes.
    cls.train = timed_train  # type: ignore[method-assign]
    try:
        t1 = _clocks()
        trainer.learn(progress_bar=False)
        t2 = _clocks()
    finally:
        cls.train = original_train  # type: ignore[method-assign]
    trainer.select()
    t3 = _clocks()

    def job_times(k: int) -> JobTimes:
        return JobTimes(
            transitions=model.num_timesteps,
            n_updates=model._n_updates,
            gradient_steps_s=learner[k],
            total_s=t3[k] - t0[k],
            setup_s=t1[k] - t0[k],
            learn_s=t2[k] - t1[k],
            candidates_s=spent[k],
            n_candidates=calls[0],
        )

    times = (job_times(0), job_times(1))
    return times, trainer


def _mlp(in_dim: int, hidden: tuple[int, ...], out_dim: int | None) -> nn.Sequential:
    layers: list[nn.Module] = []
    for width in hidden:
        layers += [nn.Linear(in_dim, width), nn.ReLU()]
        in_dim = width
    if out_dim is not None:
        layers.append(nn.Linear(in_dim, out_dim))
    return nn.Sequential(*layers)


class RawDueling(nn.Module):
    """The learner's dueling network in plain torch: Q = V + A - mean(A)."""

    def __init__(self, obs_dim: int, n_actions: int, model: AyssDQN) -> None:
        super().__init__()
        hp = model.hparams
        self.feature = _mlp(obs_dim, hp.feature_net_arch, None)
        hidden = hp.feature_net_arch[-1]
        self.value = _mlp(hidden, hp.value_net_arch, 1)
        self.advantage = _mlp(hidden, hp.advantage_net_arch, n_actions)

    def forward(self, obs: th.Tensor) -> th.Tensor:
        hidden = self.feature(obs)
        adv = self.advantage(hidden)
        return self.value(hidden) + adv - adv.mean(dim=1, keepdim=True)


def raw_step_fn(model: AyssDQN) -> Callable[[int], None]:
    """``run(k)``: ``k`` minimal raw-torch double-DQN steps on ``model``'s stored transitions."""
    buffer = model.replay_buffer
    device = model.device
    n = buffer.size()
    obs_dim = int(np.prod(buffer.obs_shape))
    n_actions = int(model.action_space.n)  # type: ignore[attr-defined]

    def flat(a: np.ndarray, dtype: th.dtype) -> th.Tensor:
        return th.as_tensor(a[:n].reshape(n * buffer.n_envs, -1), dtype=dtype, device=device)

    obs = flat(buffer.observations, th.float32)
    next_obs = flat(buffer.next_observations, th.float32)
    actions = flat(buffer.actions, th.int64)
    rewards = flat(buffer.rewards, th.float32)
    dones = flat(buffer.dones * (1 - buffer.timeouts), th.float32)
    rows = obs.shape[0]
    online = RawDueling(obs_dim, n_actions, model).to(device)
    target = RawDueling(obs_dim, n_actions, model).to(device)
    target.load_state_dict(online.state_dict())
    opt = th.optim.Adam(online.parameters(), lr=model.hparams.learning_rate, fused=True)
    gamma, batch = model.gamma, model.batch_size

    def run(k: int) -> None:
        for _ in range(k):
            idx = th.randint(rows, (batch,), device=device)
            with th.no_grad():
                next_a = online(next_obs[idx]).argmax(dim=1, keepdim=True)
                next_q = target(next_obs[idx]).gather(1, next_a)
                y = rewards[idx] + (1 - dones[idx]) * gamma * next_q
            q = online(obs[idx]).gather(1, actions[idx])
            loss = F.smooth_l1_loss(q, y)
            opt.zero_grad(set_to_none=True)
            loss.backward()
            opt.step()

    return run


def learner_fn(model: AyssDQN) -> Callable[[int], None]:
    """``run(k)``: ``k`` gradient steps of ``model.train``, called as in training."""
    per_call = model.gradient_steps
    assert isinstance(per_call, int)

    def run(k: int) -> None:
        for _ in range(max(1, k // per_call)):
            model.train(gradient_steps=per_call, batch_size=model.batch_size)

    return run


def time_steps(
    cases: dict[str, Callable[[int], None]], device: str, steps: int, rounds: int
) -> dict[str, list[tuple[float, float]]]:
    """(wall, CPU) seconds per step of each case, per round (interleaved, order rotated)."""
    names = list(cases)
    for run in cases.values():
        run(max(steps // 4, 8))  # warm-up
    out: dict[str, list[tuple[float, float]]] = {name: [] for name in names}
    for r in range(rounds):
        for name in names[r % len(names) :] + names[: r % len(names)]:
            _sync(device)
            start = _clocks()
            cases[name](steps)
            _sync(device)
            end = _clocks()
            out[name].append(((end[0] - start[0]) / steps, (end[1] - start[1]) / steps))
    return out


def bench_device(args: argparse.Namespace, device: str) -> dict[str, float]:
    """Run the job and the learner comparison on ``device``; print and return the figures."""
    base = load_experiment(args.config)
    cfg = dataclasses.replace(
        base,
        train=dataclasses.replace(
            base.train,
            total_timesteps=args.transitions,
            eval_every=min(base.train.eval_every, args.transitions),
            progress_bar=False,
            device=device,
        ),
    )
    hp = hparams_for_n_envs(cfg.agent, cfg.train.n_envs)
    grad_per_transition = cfg.agent.update_to_data_ratio
    with tempfile.TemporaryDirectory(prefix="sumo_ayss_throughput_") as tmp:
        jobs, trainer = run_job(cfg, args.seed, Path(tmp))
        try:
            model = trainer.model
            assert model is not None
            if next(model.q_net.parameters()).device.type != th.device(device).type:
                raise RuntimeError(f"the job's network is not on {device}")
            per_step = time_steps(
                {"learner": learner_fn(model), "raw": raw_step_fn(model)},
                device,
                args.steps,
                args.rounds,
            )
            buffer_kind = (
                "PER" if isinstance(model.replay_buffer, PrioritizedReplayBuffer) else "uniform"
            )
        finally:
            trainer.close()

    print(f"\n== device {device} (torch {th.__version__}, {th.get_num_threads()} thread(s))")
    print(
        f"job: {args.config.name}, n_envs {cfg.train.n_envs}, {jobs[0].transitions:,} transitions, "
        f"{grad_per_transition:g} gradient steps per transition (train_freq {hp.train_freq}, "
        f"gradient_steps {hp.gradient_steps}; {jobs[0].n_updates:,} done: none before "
        f"learning_starts {hp.learning_starts:,}), batch {hp.batch_size}, {buffer_kind} replay"
    )
    figures: dict[str, float] = {}
    for k, clock in enumerate(("wall", "cpu")):
        job = jobs[k]
        learner_s = statistics.median(r[k] for r in per_step["learner"])
        raw_s = statistics.median(r[k] for r in per_step["raw"])
        pairs = zip(per_step["learner"], per_step["raw"], strict=True)
        ratio = statistics.median(a[k] / b[k] for a, b in pairs)
        limit = 1.0 / (learner_s * grad_per_transition)
        job_rate = job.transitions / job.total_s
        learn_rate = job.transitions / job.learn_s
        steady_rate = job.transitions / (job.learn_s - job.candidates_s)
        grad_share = job.gradient_steps_s / job.total_s
        print(
            f"[{clock}] job {job.total_s:.1f} s = setup {job.setup_s:.1f} + learn "
            f"{job.learn_s:.1f} (of which {job.n_candidates} candidates {job.candidates_s:.1f}) "
            f"+ select {job.total_s - job.setup_s - job.learn_s:.2f}; in AyssDQN.train "
            f"{job.gradient_steps_s:.1f} = {grad_share:.0%} of the job "
            f"({job.gradient_steps_s / job.n_updates * 1e3:.3f} ms per gradient step)"
        )
        print(
            f"[{clock}]   transitions/s: whole job {job_rate:.0f}, learn phase {learn_rate:.0f}, "
            f"learn phase without candidates {steady_rate:.0f}"
        )
        print(
            f"[{clock}]   gradient step: learner {learner_s * 1e3:.3f} ms, raw torch "
            f"{raw_s * 1e3:.3f} ms, ratio {ratio:.2f} (target <= 1.2); "
            f"learner-bound limit {limit:.0f} transitions/s"
        )
        print(
            f"[{clock}]   job / limit {job_rate / limit:.2f} (target >= 0.8); learn phase / limit "
            f"{learn_rate / limit:.2f}; without candidates {steady_rate / limit:.2f}"
        )
        figures.update(
            {
                f"{clock}_job_rate": job_rate,
                f"{clock}_learner_ms": learner_s * 1e3,
                f"{clock}_raw_ms": raw_s * 1e3,
                f"{clock}_ratio": ratio,
                f"{clock}_fraction": job_rate / limit,
                f"{clock}_grad_share": grad_share,
            }
        )
    return figures


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--config", type=Path, default=ROOT / "configs" / "car_following.yaml", help="job YAML"
    )
    parser.add_argument("--transitions", type=int, default=20_000, help="job budget")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--device", nargs="+", default=["cpu"], help="cpu and/or cuda (cuda:<index>)"
    )
    parser.add_argument("--steps", type=int, default=200, help="gradient steps per round")
    parser.add_argument("--rounds", type=int, default=7, help="interleaved timing rounds")
    args = parser.parse_args(argv)
    try:
        for device in args.device:  # fail before any work
            TrainConfig(device=device)
            check_device(device)
    except ConfigError as e:
        sys.exit(f"error: {e}")
    print(f"{os.cpu_count()} CPUs; {_load()}")
    results = {device: bench_device(args, device) for device in args.device}
    print(
        f"\n{'device':<9}{'clock':<6}{'job tr/s':>9}{'step ms':>9}{'raw ms':>8}"
        f"{'ratio':>7}{'job/limit':>10}{'in train()':>11}"
    )
    for device, r in results.items():
        for clock in ("wall", "cpu"):
            print(
                f"{device:<9}{clock:<6}{r[clock + '_job_rate']:>9.0f}"
                f"{r[clock + '_learner_ms']:>9.3f}{r[clock + '_raw_ms']:>8.3f}"
                f"{r[clock + '_ratio']:>7.2f}{r[clock + '_fraction']:>10.2f}"
                f"{r[clock + '_grad_share']:>11.0%}"
            )
    print(f"\n{_load()}")


if __name__ == "__main__":
    main()
