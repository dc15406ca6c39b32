"""AyssDQN: targets, loss, β schedule, switchable extensions, save/load."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
import torch as th
from gymnasium import spaces
from stable_baselines3.common.buffers import ReplayBuffer
from stable_baselines3.common.env_util import make_vec_env
from stable_baselines3.common.logger import Logger
from torch import nn

from sumo_ayss.agents import AyssDQN, DQNHyperParams, PrioritizedReplayBuffer
from sumo_ayss.agents.dqn import _clip_grad_norm

TINY: dict[str, Any] = {
    "feature_net_arch": (8,),
    "value_net_arch": (8,),
    "advantage_net_arch": (8,),
    "learning_starts": 32,
    "batch_size": 16,
    "buffer_size": 500,
    "learning_rate": 1e-3,
    "target_update_interval": 50,
}


class TinyEnv(gym.Env[np.ndarray, np.int64]):
    """Box(1,) observations in [0, 4), Discrete(3) actions, 10-step episodes."""

    observation_space = spaces.Box(0.0, 4.0, (1,), np.float32)
    action_space = spaces.Discrete(3)

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        self._t = 0
        return self._obs(), {}

    def step(self, action: np.int64) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        self._t += 1
        return self._obs(), float(action == 1), False, self._t >= 10, {}

    def _obs(self) -> np.ndarray:
        return self.np_random.uniform(0.0, 4.0, (1,)).astype(np.float32)


class TableQ(nn.Module):
    """Q(s, ·) = table[int(s[0])]: hand-set Q-values for a hand-made batch."""

    def __init__(self, table: list[list[float]]) -> None:
        super().__init__()
        self.table = nn.Parameter(th.tensor(table))

    def forward(self, obs: th.Tensor) -> th.Tensor:
        return self.table[obs[:, 0].long()]


def tiny_model(**overrides: Any) -> AyssDQN:
    return AyssDQN(TinyEnv(), DQNHyperParams(**{**TINY, **overrides}), seed=0)


def table_model(**overrides: Any) -> AyssDQN:
    """Model whose buffer holds 2 hand-made transitions and whose nets are tables.

    Transition 0: s=0, a=0, r=1, s'=1, not done. Transition 1: s=2, a=1, r=-1, s'=3, done.
    Online net: argmax Q(1, ·) = 1; target net: Q_target(1, ·) = [10, 2, 3].
    """
    model = tiny_model(**overrides)
    model.set_logger(Logger(folder=None, output_formats=[]))
    buffer = model.replay_buffer
    for obs, action, reward, next_obs, done in [(0, 0, 1.0, 1, False), (2, 1, -1.0, 3, True)]:
        buffer.add(
            np.array([[obs]], np.float32),
            np.array([[next_obs]], np.float32),
            np.array([[action]]),
            np.array([reward]),
            np.array([done]),
            [{}],
        )
    online = TableQ([[0.5, 0.0, 0.0], [0.0, 5.0, 1.0], [0.0, 0.25, 0.0], [100.0, 100.0, 100.0]])
    target = TableQ([[0.0, 0.0, 0.0], [10.0, 2.0, 3.0], [0.0, 0.0, 0.0], [50.0, 50.0, 50.0]])
    model.q_net, model.q_net_target = online, target  # type: ignore[assignment]
    model._q_params = list(online.parameters())
    return model


def huber(x: float) -> float:
    return 0.5 * x * x if abs(x) < 1 else abs(x) - 0.5


# gamma = 0.8; current Q: transition 0 -> 0.5, transition 1 -> 0.25; transition 1 is terminal
DOUBLE_TD = [abs(0.5 - (1.0 + 0.8 * 2.0)), abs(0.25 - (-1.0))]  # target net at online argmax
VANILLA_TD = [abs(0.5 - (1.0 + 0.8 * 10.0)), abs(0.25 - (-1.0))]  # target net's own max


@pytest.mark.parametrize(("double", "expected"), [(True, DOUBLE_TD), (False, VANILLA_TD)])
def test_td_target_sets_priorities(double: bool, expected: list[float]) -> None:
    model = table_model(double=double)
    model.train(gradient_steps=1, batch_size=64)
    buffer = model.replay_buffer
    assert isinstance(buffer, PrioritizedReplayBuffer)
    np.testing.assert_allclose(buffer.priorities()[:2, 0], np.array(expected) + 1e-6, rtol=1e-6)


@pytest.mark.parametrize(("double", "td"), [(True, DOUBLE_TD), (False, VANILLA_TD)])
def test_unweighted_loss_without_per(
    double: bool, td: list[float], monkeypatch: pytest.MonkeyPatch
) -> None:
    model = table_model(double=double, prioritized=False)
    assert type(model.replay_buffer) is ReplayBuffer
    real_sample = model.replay_buffer.sample
    seen: list[np.ndarray] = []

    def spy(batch_size: int, env: Any = None) -> Any:
        data = real_sample(batch_size, env=env)
        seen.append(data.observations[:, 0].numpy().copy())
        return data

    monkeypatch.setattr(model.replay_buffer, "sample", spy)
    model.train(gradient_steps=1, batch_size=64)
    per_item = np.where(seen[0] == 0, huber(td[0]), huber(td[1]))
    assert model.logger.name_to_value["train/loss"] == pytest.approx(per_item.mean(), rel=1e-6)


def test_importance_weights_scale_the_loss(monkeypatch: pytest.MonkeyPatch) -> None:
    model = table_model()
    buffer = model.replay_buffer
    assert isinstance(buffer, PrioritizedReplayBuffer)
    real_sample = buffer.sample
    seen: list[Any] = []

    def spy(batch_size: int, env: Any = None, beta: float = 1.0) -> Any:
        data = real_sample(batch_size, env=env, beta=beta)
        weights = th.where(th.as_tensor(data.indices).reshape(-1, 1) == 0, 0.25, 1.0)
        seen.append((data.indices, beta))
        return data._replace(weights=weights)

    monkeypatch.setattr(buffer, "sample", spy)
    model._current_progress_remaining = 0.5
    model.train(gradient_steps=1, batch_size=64)
    indices, beta = seen[0]
    assert beta == pytest.approx(0.4 + 0.5 * 0.6)
    per_item = np.where(indices == 0, 0.25 * huber(DOUBLE_TD[0]), huber(DOUBLE_TD[1]))
    assert model.logger.name_to_value["train/loss"] == pytest.approx(per_item.mean(), rel=1e-6)
    assert model.logger.name_to_value["train/per_beta"] == pytest.approx(0.7)


def test_beta_annealing() -> None:
    model = tiny_model(per_beta0=0.4)
    assert model.per_beta == pytest.approx(0.4)  # progress remaining starts at 1
    model._current_progress_remaining = 0.25
    assert model.per_beta == pytest.approx(0.4 + 0.75 * 0.6)
    model._current_progress_remaining = 0.0
    assert model.per_beta == pytest.approx(1.0)
    model = tiny_model(per_beta0=0.5, per_beta_steps=100)
    model.num_timesteps = 50
    assert model.per_beta == pytest.approx(0.75)
    model.num_timesteps = 500
    assert model.per_beta == pytest.approx(1.0)


def test_hparams_reach_sb3() -> None:
    hp = DQNHyperParams(**{**TINY, "gamma": 0.9, "train_freq": 2, "gradient_steps": 3})
    model = AyssDQN.from_hparams(TinyEnv(), hp, seed=1)
    assert model.hparams is hp
    assert (model.gamma, model.learning_rate, model.batch_size) == (0.9, 1e-3, 16)
    assert (model.buffer_size, model.learning_starts, model.gradient_steps) == (500, 32, 3)
    assert model.train_freq.frequency == 2  # type: ignore[union-attr]
    assert (model.target_update_interval, model.tau, model.max_grad_norm) == (50, 1.0, 10.0)
    assert (model.exploration_fraction, model.exploration_final_eps) == (0.3, 0.05)
    buffer = model.replay_buffer
    assert isinstance(buffer, PrioritizedReplayBuffer)
    assert (buffer.alpha, buffer.eps, buffer.buffer_size) == (0.6, 1e-6, 500)
    assert model.policy.optimizer.param_groups[0]["lr"] == 1e-3
    assert model.policy.optimizer.defaults["fused"] is True


@pytest.mark.parametrize(
    "switches",
    [
        {},
        {"double": False},
        {"dueling": False},
        {"prioritized": False},
        {"double": False, "dueling": False, "prioritized": False},
    ],
)
def test_each_extension_switches_off(switches: dict[str, bool]) -> None:
    model = tiny_model(**switches)
    before = [p.detach().clone() for p in model.q_net.parameters()]
    model.learn(total_timesteps=200)
    assert model._n_updates == (200 - 32) // 4
    assert model.q_net.dueling is switches.get("dueling", True)
    prioritized = switches.get("prioritized", True)
    assert isinstance(model.replay_buffer, PrioritizedReplayBuffer) is prioritized
    assert any(not th.equal(b, p) for b, p in zip(before, model.q_net.parameters(), strict=True))


def test_learns_with_several_envs() -> None:
    env = make_vec_env(TinyEnv, n_envs=3, seed=0)
    model = AyssDQN(env, DQNHyperParams(**TINY), seed=0)
    model.learn(total_timesteps=300)
    buffer = model.replay_buffer
    assert isinstance(buffer, PrioritizedReplayBuffer)
    assert buffer.priorities().shape == (500 // 3, 3)
    assert model._n_updates > 0
    assert (buffer.priorities()[: buffer.pos] != 1.0).any()  # some were updated from TD errors


def test_save_load_round_trip(tmp_path: Path) -> None:
    model = tiny_model(dueling=False, double=False)
    model.learn(total_timesteps=160)  # a multiple of train_freq: SB3 collects 4 steps a round
    model.save(tmp_path / "model.zip")
    loaded = AyssDQN.load(tmp_path / "model.zip", env=TinyEnv())
    assert loaded.hparams == model.hparams
    assert not loaded.q_net.dueling
    assert isinstance(loaded.replay_buffer, PrioritizedReplayBuffer)
    assert loaded.policy.optimizer.defaults["fused"] is True
    saved_state = model.policy.optimizer.state_dict()["state"]
    loaded_state = loaded.policy.optimizer.state_dict()["state"]
    th.testing.assert_close(loaded_state[0]["exp_avg"], saved_state[0]["exp_avg"])
    obs = np.linspace(0, 4, 40, dtype=np.float32).reshape(-1, 1)
    np.testing.assert_array_equal(
        loaded.predict(obs, deterministic=True)[0], model.predict(obs, deterministic=True)[0]
    )
    with th.no_grad():
        th.testing.assert_close(loaded.q_net(th.as_tensor(obs)), model.q_net(th.as_tensor(obs)))
        th.testing.assert_close(
            loaded.q_net_target(th.as_tensor(obs)), model.q_net_target(th.as_tensor(obs))
        )
    loaded.learn(total_timesteps=40, reset_num_timesteps=False)  # keeps training
    assert loaded.num_timesteps == 200


def test_replay_buffer_save_load_keeps_priorities(tmp_path: Path) -> None:
    model = tiny_model()
    model.learn(total_timesteps=160)
    buffer = model.replay_buffer
    assert isinstance(buffer, PrioritizedReplayBuffer)
    model.save_replay_buffer(tmp_path / "replay.pkl")
    other = tiny_model()
    other.load_replay_buffer(tmp_path / "replay.pkl")
    restored = other.replay_buffer
    assert isinstance(restored, PrioritizedReplayBuffer)
    assert restored.size() == buffer.size() == 160
    np.testing.assert_array_equal(restored.priorities(), buffer.priorities())
    assert restored.tree.total == buffer.tree.total
    assert restored.max_priority == buffer.max_priority
    np.testing.assert_array_equal(restored.observations, buffer.observations)


@pytest.mark.parametrize("scale", [0.01, 100.0])
def test_clip_grad_norm_matches_torch(scale: float) -> None:
    th.manual_seed(0)
    grads = [th.randn(5, 4) * scale, th.randn(7) * scale]
    ours: list[th.Tensor] = [nn.Parameter(th.zeros_like(g)) for g in grads]
    ref = [nn.Parameter(th.zeros_like(g)) for g in grads]
    for p, q, g in zip(ours, ref, grads, strict=True):
        p.grad, q.grad = g.clone(), g.clone()
    _clip_grad_norm(ours, 10.0)
    nn.utils.clip_grad_norm_(ref, 10.0)
    for p, q in zip(ours, ref, strict=True):
        th.testing.assert_close(p.grad, q.grad)


class _ReferenceDQN(AyssDQN):
    """Frozen copy of ``AyssDQN.train`` before the lean paths: the Q-networks' MLPs called as
    ``nn.Module``s and the optimizer's own ``zero_grad``."""

    def train(self, gradient_steps: int, batch_size: int = 100) -> None:
        from torch.nn import functional as F

        import sumo_ayss.agents.policies as policies

        saved, policies._run_mlp = policies._run_mlp, lambda mlp, x: mlp(x)
        try:
            self.policy.set_training_mode(True)
            self._update_learning_rate(self.policy.optimizer)
            buffer = self.replay_buffer
            assert isinstance(buffer, PrioritizedReplayBuffer)
            beta = self.per_beta
            q_net, q_net_target = self.q_net, self.q_net_target
            optimizer = self.policy.optimizer
            for _ in range(gradient_steps):
                data = buffer.sample(batch_size, env=self._vec_normalize_env, beta=beta)
                with th.no_grad():
                    next_q_target = q_net_target(data.next_observations)
                    next_actions = q_net(data.next_observations).argmax(dim=1, keepdim=True)
                    next_q = next_q_target.gather(1, next_actions)
                    target_q = data.rewards + (1.0 - data.dones) * self.gamma * next_q
                current_q = q_net(data.observations).gather(1, data.actions.long())
                elementwise = F.smooth_l1_loss(current_q, target_q, reduction="none")
                loss = (data.weights * elementwise).mean()
                optimizer.zero_grad(set_to_none=True)
                loss.backward()
                _clip_grad_norm(self._q_params, float(self.max_grad_norm))
                optimizer.step()
                td_errors = (current_q.detach() - target_q).abs_().reshape(-1)
                buffer.update_priorities(data.indices, td_errors.cpu().numpy())
            self._n_updates += gradient_steps
        finally:
            policies._run_mlp = saved


@pytest.mark.parametrize("dueling", [True, False])
def test_lean_learner_is_bitwise_the_reference(dueling: bool) -> None:
    """Same seed, same transitions: the lean train() gives exactly the reference's weights
    (double DQN + PER, dueling or plain head)."""
    hp = DQNHyperParams(**{**TINY, "dueling": dueling})
    models = []
    for cls in (AyssDQN, _ReferenceDQN):
        model = cls(make_vec_env(TinyEnv, n_envs=2, seed=0), hp, seed=0)
        model.learn(total_timesteps=400)
        models.append(model)
    lean, ref = models
    assert lean._n_updates == ref._n_updates > 0
    for a, b in zip(lean.q_net.parameters(), ref.q_net.parameters(), strict=True):
        assert th.equal(a, b)
    buffers = lean.replay_buffer, ref.replay_buffer
    assert isinstance(buffers[0], PrioritizedReplayBuffer)
    assert isinstance(buffers[1], PrioritizedReplayBuffer)
    np.testing.assert_array_equal(buffers[0].priorities(), buffers[1].priorities())


def test_checkpoint_loads_with_plain_sb3(tmp_path: Path) -> None:
    """A saved AyssDQN is a plain SB3 zip: SB3's own ``DQN.load`` gives the same greedy policy."""
    from stable_baselines3 import DQN

    model = tiny_model()
    model.learn(total_timesteps=80)
    model.save(tmp_path / "model.zip")
    plain = DQN.load(tmp_path / "model.zip")
    obs = np.linspace(0, 4, 40, dtype=np.float32).reshape(-1, 1)
    np.testing.assert_array_equal(
        plain.predict(obs, deterministic=True)[0], model.predict(obs, deterministic=True)[0]
    )
    assert plain.num_timesteps == model.num_timesteps == 80
