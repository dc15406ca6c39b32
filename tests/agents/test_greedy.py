"""The greedy policy's NumPy forward (small batches) against torch's (the network itself)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
import torch as th
from torch import nn

from sumo_ayss.agents.dqn import AyssDQN
from sumo_ayss.agents.greedy import HOST_MAX_BATCH, GreedyPolicy
from sumo_ayss.agents.hparams import DQNHyperParams
from sumo_ayss.envs.cut_in import CutInEnv


def _policy(dueling: bool) -> tuple[GreedyPolicy, CutInEnv]:
    hp = DQNHyperParams(
        feature_net_arch=(32,), value_net_arch=(16,), advantage_net_arch=(16, 8), dueling=dueling
    )
    env = CutInEnv()  # spaces only: SUMO never starts
    return GreedyPolicy(AyssDQN(env, hp, seed=5)), env


def _torch_q(policy: GreedyPolicy, obs: np.ndarray) -> np.ndarray:
    with th.no_grad():
        q: np.ndarray = policy.q_net(th.as_tensor(obs)).numpy()
        return q


@pytest.mark.parametrize("dueling", [True, False], ids=["dueling", "plain"])
def test_small_batches_take_the_numpy_path_and_agree_with_the_network(dueling: bool) -> None:
    policy, env = _policy(dueling)
    assert policy._host is not None
    obs = np.random.default_rng(1).uniform(0, 30, size=(200, 4)).astype(np.float32)
    for n in range(1, HOST_MAX_BATCH + 1):
        for i in range(0, 200, n):
            x = obs[i : i + n]
            q, want = policy.q_values(x), _torch_q(policy, x)
            assert q.dtype == np.float32 and q.shape == want.shape
            np.testing.assert_allclose(q, want, rtol=1e-5, atol=1e-6)
            np.testing.assert_array_equal(policy(x), want.argmax(axis=1))
    big = policy.q_values(obs)  # beyond HOST_MAX_BATCH: the network itself, bit for bit
    np.testing.assert_array_equal(big, _torch_q(policy, obs))
    env.close()


def test_the_numpy_path_sees_the_networks_weights_change_in_place() -> None:
    """A policy built once during training reads the weights as they are now (an optimizer
    step updates the parameters in place)."""
    policy, env = _policy(True)
    x = np.full((1, 4), 10.0, dtype=np.float32)
    before = policy.q_values(x).copy()
    with th.no_grad():
        for p in policy.q_net.parameters():
            p.mul_(1.5).add_(0.01)
    after = policy.q_values(x)
    assert not np.allclose(after, before)
    np.testing.assert_allclose(after, _torch_q(policy, x), rtol=1e-5, atol=1e-6)
    env.close()


def test_another_layout_runs_through_torch() -> None:
    policy, env = _policy(True)
    # not Linear/ReLU: the NumPy forward does not know it
    policy.q_net.feature_net[1] = nn.Tanh()  # type: ignore[operator, assignment]
    other = GreedyPolicy(SimpleNamespace(q_net=policy.q_net, device=th.device("cpu")))  # type: ignore[arg-type]
    assert other._host is None
    x = np.full((1, 4), 10.0, dtype=np.float32)
    np.testing.assert_array_equal(other.q_values(x), _torch_q(other, x))
    env.close()
