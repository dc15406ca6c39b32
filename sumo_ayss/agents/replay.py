"""Proportional prioritized experience replay (Schaul et al., 2016) for stable-baselines3.

:class:`SumTree` stores one non-negative value per slot and answers prefix-sum queries, all
batched in numpy. :class:`PrioritizedReplayBuffer` is a drop-in subclass of SB3's
:class:`~stable_baselines3.common.buffers.ReplayBuffer`: it samples transition ``i`` with
probability ``P(i) = p_i^α / Σ_k p_k^α``, returns importance weights
``w_i = (N·P(i))^-β / max_j w_j`` (max over the sampled batch) and the indices whose priorities
the learner then sets to ``|δ| + eps``. It pickles as a whole, so SB3's ``save_replay_buffer`` /
``load_replay_buffer`` keep the priorities.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
import torch as th
from gymnasium import spaces
from stable_baselines3.common.buffers import ReplayBuffer
from stable_baselines3.common.vec_env import VecNormalize

from sumo_ayss.util.errors import ConfigError


class SumTree:
    """Wide (``fanout``-ary) sum tree over ``capacity`` non-negative leaf values.

    Level ``k`` (0 = leaves) keeps its node values in blocks of ``fanout`` siblings, and for
    each block the running sums ``[0, v0, v0+v1, ...]``; a node's value is the last running
    sum of its child block. A query descends by comparing against those stored running sums,
    so each level costs a few numpy calls on a (batch, fanout) array and no cumsum. Both
    operations are batched: O(batch · fanout · log_fanout(capacity)).

    Args:
        capacity: Number of leaves, >= 1.
        fanout: Children per node, >= 2.
    """

    def __init__(self, capacity: int, fanout: int = 16) -> None:
        if capacity < 1 or fanout < 2:
            raise ConfigError(
                f"SumTree needs capacity >= 1 and fanout >= 2, got {capacity}, {fanout}"
            )
        self.capacity = capacity
        self.fanout = fanout
        self._values: list[np.ndarray] = []  # per level, flat, length a multiple of fanout
        self._prefix: list[np.ndarray] = []  # per level, (blocks, fanout + 1) running sums
        size = capacity
        while True:
            blocks = -(-size // fanout)
            self._values.append(np.zeros(blocks * fanout, dtype=np.float64))
            self._prefix.append(np.zeros((blocks, fanout + 1), dtype=np.float64))
            if blocks == 1:
                break
            size = blocks

    @property
    def total(self) -> float:
        """Sum of all leaf values."""
        return float(self._prefix[-1][0, -1])

    @property
    def leaves(self) -> np.ndarray:
        """Read-only view of the ``capacity`` leaf values."""
        view = self._values[0][: self.capacity]
        view.flags.writeable = False
        return view

    def get(self, indices: np.ndarray) -> np.ndarray:
        """Return the leaf values at ``indices``."""
        values: np.ndarray = self._values[0][indices]
        return values

    def update(self, indices: np.ndarray, values: np.ndarray | float) -> None:
        """Set leaves ``indices`` to ``values`` and refresh their ancestors.

        Args:
            indices: Leaf indices in ``[0, capacity)``; duplicates keep the last value.
            values: Non-negative values, broadcastable to ``indices``.
        """
        fan = self.fanout
        self._values[0][indices] = values
        blocks = np.asarray(indices) // fan
        last = len(self._values) - 1
        for k in range(last + 1):
            prefix = self._prefix[k]
            prefix[blocks, 1:] = np.cumsum(self._values[k].reshape(-1, fan)[blocks], axis=1)
            if k < last:
                self._values[k + 1][blocks] = prefix[blocks, -1]
                blocks = blocks // fan

    def find(self, prefix_sums: np.ndarray) -> np.ndarray:
        """Return per value ``v`` the leaf ``i`` with ``sum(leaves[:i]) <= v < sum(leaves[:i+1])``.

        Values at or past :attr:`total` (rounding) map to the last non-empty leaf, so a
        returned leaf always has a positive value when :attr:`total` is positive.

        Args:
            prefix_sums: Query values in ``[0, total)``, shape (batch,).

        Returns:
            Leaf indices, shape (batch,), dtype int64.
        """
        values = np.asarray(prefix_sums, dtype=np.float64)
        rows = np.arange(values.shape[0])
        nodes = np.zeros(values.shape[0], dtype=np.int64)
        for prefix in reversed(self._prefix):
            sums = prefix[nodes]  # (batch, fanout + 1) running sums of each node's children
            values = np.minimum(values, np.nextafter(sums[:, -1], 0.0))  # strictly below total
            child = (sums[:, 1:] <= values[:, None]).sum(axis=1)  # first child ending past v
            values = values - sums[rows, child]
            nodes = nodes * self.fanout + child
        return nodes


class PrioritizedReplayBufferSamples(NamedTuple):
    """A minibatch from :class:`PrioritizedReplayBuffer`.

    The first five fields match SB3's ``ReplayBufferSamples``; ``weights`` are the
    importance-sampling weights (shape (batch, 1)) and ``indices`` the flat slot indices to pass
    back to :meth:`PrioritizedReplayBuffer.update_priorities`.
    """

    observations: th.Tensor
    actions: th.Tensor
    next_observations: th.Tensor
    dones: th.Tensor
    rewards: th.Tensor
    weights: th.Tensor
    indices: np.ndarray
    discounts: th.Tensor | None = None


class PrioritizedReplayBuffer(ReplayBuffer):
    """SB3 replay buffer with proportional prioritized sampling.

    Slot ``(row, env)`` of SB3's ``(buffer_size, n_envs)`` storage has flat index
    ``row * n_envs + env``; the sum tree holds ``priority^alpha`` per flat index. New
    transitions enter at the largest priority seen so far (1.0 initially).

    Args:
        buffer_size: Capacity in transitions over all envs (SB3 semantics).
        observation_space: Observation space.
        action_space: Action space.
        device: Torch device of the returned tensors.
        n_envs: Number of parallel environments.
        optimize_memory_usage: Must be False (not supported with priorities).
        handle_timeout_termination: As in SB3: time-limit truncations are not terminal.
        alpha: Priority exponent α in [0, 1].
        eps: Added to ``|TD error|`` so that no priority is zero, > 0.
        fanout: Sum-tree fanout.
    """

    def __init__(
        self,
        buffer_size: int,
        observation_space: spaces.Space[Any],
        action_space: spaces.Space[Any],
        device: th.device | str = "auto",
        n_envs: int = 1,
        optimize_memory_usage: bool = False,
        handle_timeout_termination: bool = True,
        alpha: float = 0.6,
        eps: float = 1e-6,
        fanout: int = 16,
    ) -> None:
        if optimize_memory_usage:
            raise ConfigError("PrioritizedReplayBuffer does not support optimize_memory_usage=True")
        if not 0.0 <= alpha <= 1.0:
            raise ConfigError(f"agent.per_alpha must be in [0, 1], got {alpha!r}")
        if not eps > 0.0:
            raise ConfigError(f"agent.per_eps must be in (0, inf), got {eps!r}")
        super().__init__(
            buffer_size,
            observation_space,
            action_space,
            device=device,
            n_envs=n_envs,
            optimize_memory_usage=False,
            handle_timeout_termination=handle_timeout_termination,
        )
        self.alpha = float(alpha)
        self.eps = float(eps)
        self.max_priority = 1.0
        self.tree = SumTree(self.buffer_size * self.n_envs, fanout=fanout)
        self._priorities = np.zeros(self.buffer_size * self.n_envs, dtype=np.float64)
        self._env_offsets = np.arange(self.n_envs, dtype=np.int64)

    def add(
        self,
        obs: np.ndarray,
        next_obs: np.ndarray,
        action: np.ndarray,
        reward: np.ndarray,
        done: np.ndarray,
        infos: list[dict[str, Any]],
    ) -> None:
        """Store one step of every env (as SB3) at the current maximum priority."""
        slots = self.pos * self.n_envs + self._env_offsets
        super().add(obs, next_obs, action, reward, done, infos)
        self._priorities[slots] = self.max_priority
        self.tree.update(slots, self.max_priority**self.alpha)

    def reset(self) -> None:
        """Empty the buffer and forget all priorities."""
        super().reset()
        if hasattr(self, "tree"):
            self.tree = SumTree(self.tree.capacity, fanout=self.tree.fanout)
            self._priorities[:] = 0.0
            self.max_priority = 1.0

    def sample(  # type: ignore[override]
        self,
        batch_size: int,
        env: VecNormalize | None = None,
        beta: float = 1.0,
    ) -> PrioritizedReplayBufferSamples:
        """Draw ``batch_size`` transitions i.i.d. with probability ∝ priority^α.

        Args:
            batch_size: Number of transitions (drawn with replacement).
            env: Optional VecNormalize used to normalise observations and rewards.
            beta: Importance-sampling exponent β in [0, 1].

        Returns:
            The minibatch, its importance weights (max 1) and flat indices.
        """
        if self.size() == 0:
            raise RuntimeError("cannot sample from an empty replay buffer")
        total = self.tree.total
        # numpy's global RNG, as SB3's buffers: seeded by the model's ``seed``.
        indices = self.tree.find(np.random.random(batch_size) * total)  # noqa: NPY002
        probs = self.tree.get(indices)
        weights = (probs / probs.min()) ** -beta  # == (N·P)^-β / max over the batch
        return self._get_prioritized_samples(indices, weights.astype(np.float32), env)

    def update_priorities(self, indices: np.ndarray, td_errors: np.ndarray) -> None:
        """Set the priorities of ``indices`` to ``|td_errors| + eps``.

        Args:
            indices: Flat indices, as returned in the samples.
            td_errors: TD errors of those transitions, shape (batch,).
        """
        priorities = np.abs(np.asarray(td_errors, dtype=np.float64)).reshape(-1) + self.eps
        self._priorities[indices] = priorities
        self.tree.update(indices, priorities**self.alpha)
        self.max_priority = max(self.max_priority, float(priorities.max()))

    def priorities(self) -> np.ndarray:
        """Return a copy of the priorities ``p`` (before ``^α``), shape (buffer_size, n_envs).

        Empty slots read 0.
        """
        return self._priorities.reshape(self.buffer_size, self.n_envs).copy()

    def _get_prioritized_samples(
        self, indices: np.ndarray, weights: np.ndarray, env: VecNormalize | None
    ) -> PrioritizedReplayBufferSamples:
        """Gather the transitions at flat ``indices`` as tensors on the buffer's device."""
        rows, envs = np.divmod(indices, self.n_envs)
        dones = self.dones[rows, envs] * (1.0 - self.timeouts[rows, envs])
        obs = self.observations[rows, envs]
        next_obs = self.next_observations[rows, envs]
        rewards = self.rewards[rows, envs]
        if env is not None:
            obs = self._normalize_obs(obs, env)  # type: ignore[assignment]
            next_obs = self._normalize_obs(next_obs, env)  # type: ignore[assignment]
            rewards = self._normalize_reward(rewards, env)
        device = self.device
        return PrioritizedReplayBufferSamples(
            observations=th.as_tensor(obs, device=device),
            actions=th.as_tensor(self.actions[rows, envs], device=device),
            next_observations=th.as_tensor(next_obs, device=device),
            dones=th.as_tensor(dones.reshape(-1, 1), device=device),
            rewards=th.as_tensor(rewards.reshape(-1, 1), device=device),
            weights=th.as_tensor(weights.reshape(-1, 1), device=device),
            indices=indices,
        )
