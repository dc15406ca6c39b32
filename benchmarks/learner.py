"""Learner micro-benchmark: cost of one DQN gradient step, side by side in one process.

Cases (batch 64, Box(3,) observations, Discrete(21) actions, buffers pre-filled):

* ``ours``: ``AyssDQN.train`` with double + dueling + PER (the paper's network:
  feature 256-256, value 256-256-1, advantage 256-256-21) and fused Adam;
* ``floor``: minimal raw-torch double dueling step on the same network (random minibatch
  from preallocated tensors, 3 forwards, Huber loss, backward, Adam step; no clipping),
  once with torch's default Adam and once with fused Adam;
* ``sb3``: stock SB3 ``DQN.train`` with ``net_arch=[256, 256]`` and default Adam, and the
  raw-torch double-DQN floor of that smaller network;
* ``sb3-same-net``: stock SB3 ``DQN.train`` on our dueling network with default Adam.

Rounds interleave the cases (rotating their order), so background load hits them alike; the
table reports µs per gradient step (median and min over rounds) and, per case, the median over
rounds of its time divided by its floor's time in the same round.

Run: ``python benchmarks/learner.py [--help]``.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable
from typing import Any

import gymnasium as gym
import numpy as np
import torch as th
from gymnasium import spaces
from stable_baselines3 import DQN
from stable_baselines3.common.buffers import ReplayBuffer
from stable_baselines3.common.logger import Logger
from torch import nn
from torch.nn import functional as F

from sumo_ayss.agents import AyssDQN, AyssDQNPolicy, DQNHyperParams, PrioritizedReplayBuffer

OBS_DIM, N_ACTIONS, BATCH, GAMMA, LR = 3, 21, 64, 0.8, 1e-5


class DummyEnv(gym.Env[np.ndarray, np.int64]):
    """Random Box(3,) observations, Discrete(21) actions, 50-step episodes."""

    observation_space = spaces.Box(-1.0, 1.0, (OBS_DIM,), np.float32)
    action_space = spaces.Discrete(N_ACTIONS)

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        self._t = 0
        return self.observation_space.sample(), {}

    def step(self, action: np.int64) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        self._t += 1
        return self.observation_space.sample(), float(action == 0), self._t >= 50, False, {}


def fill(buffer: ReplayBuffer, n: int, rng: np.random.Generator) -> None:
    """Add ``n`` random transitions; with PER, also spread the priorities out."""
    obs = rng.uniform(-1, 1, (n + 1, 1, OBS_DIM)).astype(np.float32)
    actions = rng.integers(0, N_ACTIONS, (n, 1))
    rewards = rng.normal(size=(n, 1)).astype(np.float32)
    dones = rng.random((n, 1)) < 0.02
    for i in range(n):
        buffer.add(obs[i], obs[i + 1], actions[i], rewards[i], dones[i], [{}])
    if isinstance(buffer, PrioritizedReplayBuffer):
        buffer.update_priorities(np.arange(n), rng.exponential(size=n))


def mlp(in_dim: int, hidden: list[int], out_dim: int | None) -> nn.Sequential:
    """ReLU MLP; ReLU after every hidden layer, linear output if ``out_dim``."""
    layers: list[nn.Module] = []
    for width in hidden:
        layers += [nn.Linear(in_dim, width), nn.ReLU()]
        in_dim = width
    if out_dim is not None:
        layers.append(nn.Linear(in_dim, out_dim))
    return nn.Sequential(*layers)


class RawDueling(nn.Module):
    """The paper's dueling network in plain torch."""

    def __init__(self) -> None:
        super().__init__()
        self.feature = mlp(OBS_DIM, [256, 256], None)
        self.value = mlp(256, [256, 256], 1)
        self.advantage = mlp(256, [256, 256], N_ACTIONS)

    def forward(self, obs: th.Tensor) -> th.Tensor:
        hidden = self.feature(obs)
        adv = self.advantage(hidden)
        return self.value(hidden) + adv - adv.mean(dim=1, keepdim=True)


def raw_step_fn(make_net: Callable[[], nn.Module], fused: bool, n: int) -> Callable[[int], None]:
    """Return ``run(k)`` doing ``k`` minimal raw-torch double-DQN steps on ``make_net()``."""
    online, target = make_net(), make_net()
    target.load_state_dict(online.state_dict())
    opt = th.optim.Adam(online.parameters(), lr=LR, fused=fused or None)
    obs, next_obs = th.rand(n, OBS_DIM) * 2 - 1, th.rand(n, OBS_DIM) * 2 - 1
    actions = th.randint(N_ACTIONS, (n, 1))
    rewards, dones = th.randn(n, 1), (th.rand(n, 1) < 0.02).float()

    def run(k: int) -> None:
        for _ in range(k):
            idx = th.randint(n, (BATCH,))
            with th.no_grad():
                next_a = online(next_obs[idx]).argmax(dim=1, keepdim=True)
                next_q = target(next_obs[idx]).gather(1, next_a)
                y = rewards[idx] + (1 - dones[idx]) * GAMMA * next_q
            q = online(obs[idx]).gather(1, actions[idx])
            loss = F.smooth_l1_loss(q, y)
            opt.zero_grad(set_to_none=True)
            loss.backward()
            opt.step()

    return run


def sb3_train_fn(model: DQN, gradient_steps: int) -> Callable[[int], None]:
    """Return ``run(k)`` doing ``k`` gradient steps via ``model.train`` calls."""
    model.set_logger(Logger(folder=None, output_formats=[]))

    def run(k: int) -> None:
        for _ in range(k // gradient_steps):
            model.train(gradient_steps=gradient_steps, batch_size=BATCH)

    return run


def main() -> None:
    """Parse options, build the cases, time them interleaved and print the table."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=int, default=100, help="gradient steps per case per round")
    parser.add_argument("--rounds", type=int, default=9, help="interleaved timing rounds")
    parser.add_argument("--warmup", type=int, default=50, help="untimed steps per case first")
    parser.add_argument("--fill", type=int, default=20_000, help="transitions in each buffer")
    parser.add_argument(
        "--gradient-steps", type=int, default=1, help="gradient steps per train() call"
    )
    parser.add_argument("--threads", type=int, default=0, help="torch threads (0: default)")
    args = parser.parse_args()
    if args.steps % args.gradient_steps:
        parser.error("--steps must be a multiple of --gradient-steps")
    if args.threads:
        th.set_num_threads(args.threads)
    th.manual_seed(0)
    rng = np.random.default_rng(0)

    ours = AyssDQN(DummyEnv(), DQNHyperParams(), seed=0)
    sb3 = DQN(
        "MlpPolicy", DummyEnv(), learning_rate=LR, buffer_size=100_000, batch_size=BATCH,
        gamma=GAMMA, policy_kwargs={"net_arch": [256, 256]}, seed=0, device="cpu",
    )  # fmt: skip
    sb3_same = DQN(
        AyssDQNPolicy, DummyEnv(), learning_rate=LR, buffer_size=100_000, batch_size=BATCH,
        gamma=GAMMA, seed=0, device="cpu",
    )  # fmt: skip
    for model in (ours, sb3, sb3_same):
        fill(model.replay_buffer, args.fill, rng)  # type: ignore[arg-type]

    def raw_256() -> nn.Module:
        return mlp(OBS_DIM, [256, 256], N_ACTIONS)

    # name -> (network, optimizer, floor it is compared with, run(k))
    cases: dict[str, tuple[str, str, str, Callable[[int], None]]] = {
        "ours": ("dueling", "fused Adam", "floor", sb3_train_fn(ours, args.gradient_steps)),
        "floor": ("dueling", "Adam", "floor", raw_step_fn(RawDueling, False, args.fill)),
        "floor-fused": ("dueling", "fused Adam", "floor", raw_step_fn(RawDueling, True, args.fill)),
        "sb3-same-net": ("dueling", "Adam", "floor", sb3_train_fn(sb3_same, args.gradient_steps)),
        "sb3": ("256-256", "Adam", "floor-256", sb3_train_fn(sb3, args.gradient_steps)),
        "floor-256": ("256-256", "Adam", "floor-256", raw_step_fn(raw_256, False, args.fill)),
    }
    warm = max(args.gradient_steps, args.warmup - args.warmup % args.gradient_steps)
    for *_, run in cases.values():
        run(warm)
    names = list(cases)
    rounds: list[dict[str, float]] = []
    for r in range(args.rounds):
        times: dict[str, float] = {}
        for name in names[r % len(names) :] + names[: r % len(names)]:  # rotate the order
            start = time.perf_counter()
            cases[name][3](args.steps)
            times[name] = (time.perf_counter() - start) / args.steps * 1e6
        rounds.append(times)

    def ratio(name: str, floor: str) -> float:
        """Median over rounds of the within-round time ratio ``name / floor``."""
        return statistics.median(times[name] / times[floor] for times in rounds)

    print(
        f"torch {th.__version__}, {th.get_num_threads()} thread(s), batch {BATCH}, "
        f"{args.gradient_steps} gradient step(s) per train() call, "
        f"{args.rounds} rounds x {args.steps} steps per case"
    )
    header = f"{'case':<13} {'network':<8} {'optimizer':<10} {'median us':>9} {'min us':>8}"
    print(f"{header} {'/floor':>7} {'/floor-fused':>12}")
    for name, (net, optim, floor, _) in cases.items():
        values = [times[name] for times in rounds]
        fused = f"{ratio(name, 'floor-fused'):>12.2f}" if net == "dueling" else f"{'-':>12}"
        print(
            f"{name:<13} {net:<8} {optim:<10} {statistics.median(values):>9.0f} "
            f"{min(values):>8.0f} {ratio(name, floor):>7.2f} {fused}"
        )
    print(
        "ratios are medians of within-round ratios; 'floor' columns use the floor of the same "
        "network (dueling: feature 256-256, value 256-256-1, advantage 256-256-21)"
    )
    print(
        f"ours/floor = {ratio('ours', 'floor'):.2f}, "
        f"ours/floor-fused = {ratio('ours', 'floor-fused'):.2f}, "
        f"sb3/floor-256 = {ratio('sb3', 'floor-256'):.2f}, "
        f"sb3-same-net/floor = {ratio('sb3-same-net', 'floor'):.2f}"
    )


if __name__ == "__main__":
    main()
