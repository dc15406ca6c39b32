"""SumTree and PrioritizedReplayBuffer."""

from __future__ import annotations

import pickle
from typing import Any

import numpy as np
import pytest
from gymnasium import spaces
from hypothesis import given, settings
from hypothesis import strategies as st
from stable_baselines3.common.utils import set_random_seed  # seeds numpy's global RNG

from sumo_ayss.agents.replay import PrioritizedReplayBuffer, SumTree
from sumo_ayss.util.errors import ConfigError

OBS_SPACE = spaces.Box(-1e6, 1e6, (2,), np.float32)
ACT_SPACE = spaces.Discrete(4)


def make_buffer(size: int = 16, n_envs: int = 1, **kwargs: Any) -> PrioritizedReplayBuffer:
    return PrioritizedReplayBuffer(
        size, OBS_SPACE, ACT_SPACE, device="cpu", n_envs=n_envs, **kwargs
    )


def add(buffer: PrioritizedReplayBuffer, tag: float) -> None:
    """Add one step of every env; obs = (tag, env), reward = tag."""
    n = buffer.n_envs
    obs = np.stack([np.full(n, tag), np.arange(n)], axis=1).astype(np.float32)
    buffer.add(obs, obs + 1, np.zeros(n, np.int64), np.full(n, tag), np.zeros(n), [{}] * n)


# -- SumTree ---------------------------------------------------------------------------


@settings(max_examples=60, deadline=None)
@given(
    capacity=st.integers(1, 300),
    fanout=st.integers(2, 9),
    updates=st.lists(st.tuples(st.integers(0, 10_000), st.integers(0, 50)), max_size=60),
)
def test_sum_tree_total_and_find_match_brute_force(
    capacity: int, fanout: int, updates: list[tuple[int, int]]
) -> None:
    tree = SumTree(capacity, fanout=fanout)
    expected = np.zeros(capacity)
    for index, value in updates:  # integer values: every sum is exact in float64
        tree.update(np.array([index % capacity]), float(value))
        expected[index % capacity] = value
    assert tree.total == expected.sum()
    np.testing.assert_array_equal(tree.leaves, expected)
    if expected.sum() > 0:
        queries = np.arange(int(expected.sum())) + 0.5
        cumulative = np.cumsum(expected)
        np.testing.assert_array_equal(
            tree.find(queries), np.searchsorted(cumulative, queries, side="right")
        )


@given(st.lists(st.floats(0.0, 1e3), min_size=1, max_size=200), st.integers(2, 17))
def test_sum_tree_batched_update_total(values: list[float], fanout: int) -> None:
    tree = SumTree(len(values), fanout=fanout)
    tree.update(np.arange(len(values)), np.array(values))
    assert tree.total == pytest.approx(sum(values), rel=1e-12, abs=1e-12)


def test_sum_tree_never_returns_empty_leaf() -> None:
    tree = SumTree(1000, fanout=8)
    values = np.random.default_rng(0).random(1000) * 1e-3
    values[137:] = 0.0
    tree.update(np.arange(1000), values)
    queries = np.concatenate([np.linspace(0, tree.total, 5000), [tree.total * 2, np.inf]])
    found = tree.find(queries)
    assert (values[found] > 0).all()
    assert found.max() == 136


def test_sum_tree_rejects_bad_shape() -> None:
    with pytest.raises(ConfigError):
        SumTree(0)
    with pytest.raises(ConfigError):
        SumTree(10, fanout=1)


# -- PrioritizedReplayBuffer -------------------------------------------------------------


def test_new_transitions_get_max_priority() -> None:
    buffer = make_buffer()
    add(buffer, 0.0)
    assert buffer.priorities()[0, 0] == 1.0
    add(buffer, 1.0)
    buffer.update_priorities(np.array([0, 1]), np.array([3.0, 0.5]))
    add(buffer, 2.0)
    np.testing.assert_allclose(buffer.priorities()[:3, 0], [3.0 + 1e-6, 0.5 + 1e-6, 3.0 + 1e-6])
    assert buffer.max_priority == pytest.approx(3.0 + 1e-6)
    buffer.update_priorities(np.array([0]), np.array([0.1]))  # max is the max ever seen
    add(buffer, 3.0)
    assert buffer.priorities()[3, 0] == pytest.approx(3.0 + 1e-6)


def test_update_priorities_from_td_errors() -> None:
    buffer = make_buffer(alpha=0.5, eps=0.01)
    for tag in range(4):
        add(buffer, tag)
    buffer.update_priorities(np.array([1, 3]), np.array([-2.0, 0.25]))
    np.testing.assert_allclose(buffer.priorities()[:4, 0], [1.0, 2.01, 1.0, 0.26])
    np.testing.assert_allclose(buffer.tree.leaves[:4], np.array([1.0, 2.01, 1.0, 0.26]) ** 0.5)


def test_sampling_is_proportional_to_priority_power_alpha() -> None:
    alpha = 0.6
    buffer = make_buffer(alpha=alpha, eps=1e-6)
    for tag in range(8):
        add(buffer, tag)
    priorities = np.arange(1.0, 9.0)
    buffer.update_priorities(np.arange(8), priorities - 1e-6)
    set_random_seed(0)
    n = 200_000
    counts = np.zeros(8)
    for _ in range(n // 1000):
        samples = buffer.sample(1000)
        counts += np.bincount(samples.indices, minlength=8)
        # the sampled data are the stored transitions of those indices
        np.testing.assert_array_equal(samples.rewards.numpy().ravel(), samples.indices)
    expected = priorities**alpha / (priorities**alpha).sum()
    np.testing.assert_allclose(counts / n, expected, atol=0.004)


def test_importance_weights_formula() -> None:
    alpha, beta = 0.7, 0.55
    buffer = make_buffer(alpha=alpha)
    for tag in range(5):
        add(buffer, tag)
    priorities = np.array([0.5, 1.0, 2.0, 4.0, 8.0])
    buffer.update_priorities(np.arange(5), priorities - buffer.eps)
    set_random_seed(1)
    samples = buffer.sample(64, beta=beta)
    probs = priorities**alpha / (priorities**alpha).sum()
    raw = (5 * probs[samples.indices]) ** -beta
    np.testing.assert_allclose(samples.weights.numpy().ravel(), raw / raw.max(), rtol=1e-6)
    assert samples.weights.shape == (64, 1)
    assert samples.weights.max().item() == pytest.approx(1.0)


def test_unwritten_slots_are_never_sampled() -> None:
    buffer = make_buffer(size=100)
    for tag in range(3):
        add(buffer, tag)
    set_random_seed(2)
    assert buffer.sample(5000).indices.max() == 2


def test_multiple_envs() -> None:
    buffer = make_buffer(size=12, n_envs=3)
    for tag in range(4):
        add(buffer, tag)
    assert buffer.priorities().shape == (4, 3)
    buffer.update_priorities(np.array([3 * 2 + 1]), np.array([5.0]))  # row 2, env 1
    assert buffer.priorities()[2, 1] == pytest.approx(5.0 + 1e-6)
    set_random_seed(3)
    samples = buffer.sample(500)
    rows, envs = np.divmod(samples.indices, 3)
    np.testing.assert_array_equal(samples.observations.numpy()[:, 0], rows)
    np.testing.assert_array_equal(samples.observations.numpy()[:, 1], envs)
    np.testing.assert_array_equal(samples.next_observations.numpy()[:, 0], rows + 1)
    assert set(samples.indices) == set(range(12))


def test_wraparound_overwrites_priority() -> None:
    buffer = make_buffer(size=4)
    for tag in range(4):
        add(buffer, tag)
    buffer.update_priorities(np.arange(4), np.array([0.1, 0.1, 9.0, 0.1]))
    add(buffer, 4.0)  # overwrites slot 0 at the max priority
    assert buffer.full and buffer.pos == 1
    assert buffer.priorities()[0, 0] == pytest.approx(9.0 + 1e-6)
    assert buffer.rewards[0, 0] == 4.0


def test_pickle_keeps_priorities() -> None:
    buffer = make_buffer(size=32)
    for tag in range(10):
        add(buffer, tag)
    buffer.update_priorities(np.arange(10), np.linspace(0.1, 3.0, 10))
    restored = pickle.loads(pickle.dumps(buffer))
    np.testing.assert_array_equal(restored.priorities(), buffer.priorities())
    assert restored.tree.total == buffer.tree.total
    assert restored.max_priority == buffer.max_priority
    set_random_seed(4)
    first = buffer.sample(16).indices
    set_random_seed(4)
    np.testing.assert_array_equal(restored.sample(16).indices, first)


def test_reset_forgets_priorities() -> None:
    buffer = make_buffer()
    add(buffer, 0.0)
    buffer.update_priorities(np.array([0]), np.array([7.0]))
    buffer.reset()
    assert buffer.size() == 0 and buffer.tree.total == 0.0 and buffer.max_priority == 1.0
    with pytest.raises(RuntimeError, match="empty"):
        buffer.sample(1)


def test_rejects_bad_options() -> None:
    with pytest.raises(ConfigError, match="optimize_memory_usage"):
        make_buffer(optimize_memory_usage=True, handle_timeout_termination=False)
    with pytest.raises(ConfigError, match="per_alpha"):
        make_buffer(alpha=1.5)
    with pytest.raises(ConfigError, match="per_eps"):
        make_buffer(eps=0.0)
