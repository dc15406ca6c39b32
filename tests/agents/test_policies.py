"""DuelingQNetwork and AyssDQNPolicy."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch as th
from gymnasium import spaces
from stable_baselines3.common.torch_layers import FlattenExtractor
from torch import nn

from sumo_ayss.agents.policies import AyssDQNPolicy, DuelingQNetwork, _is_mode_free

OBS_SPACE = spaces.Box(-1.0, 1.0, (3,), np.float32)
ACT_SPACE = spaces.Discrete(5)


def make_net(dueling: bool = True) -> DuelingQNetwork:
    return DuelingQNetwork(
        OBS_SPACE,
        ACT_SPACE,
        FlattenExtractor(OBS_SPACE),
        features_dim=3,
        feature_net_arch=(8, 6),
        value_net_arch=(7,),
        advantage_net_arch=(4, 4),
        dueling=dueling,
    )


def make_policy(**kwargs: object) -> AyssDQNPolicy:
    return AyssDQNPolicy(
        OBS_SPACE,
        ACT_SPACE,
        lambda _: 1e-3,
        feature_net_arch=(8,),
        value_net_arch=(8,),
        advantage_net_arch=(8,),
        **kwargs,  # type: ignore[arg-type]
    )


def test_dueling_output_is_v_plus_a_minus_mean_a() -> None:
    th.manual_seed(0)
    net = make_net()
    obs = th.rand(10, 3) * 2 - 1
    hidden = net.feature_net(obs)
    value, adv = net.value_net(hidden), net.advantage_net(hidden)
    assert value.shape == (10, 1) and adv.shape == (10, 5)
    expected = value + adv - adv.mean(dim=1, keepdim=True)
    th.testing.assert_close(net(obs), expected)
    # the advantages' mean is removed: the mean Q over actions equals V
    th.testing.assert_close(net(obs).mean(dim=1, keepdim=True), value)


def test_layer_layout() -> None:
    net = make_net()
    widths = [m.out_features for m in net.feature_net if isinstance(m, nn.Linear)]
    assert widths == [8, 6]
    assert isinstance(net.feature_net[-1], nn.ReLU)
    assert [m.out_features for m in net.value_net if isinstance(m, nn.Linear)] == [7, 1]
    assert [m.out_features for m in net.advantage_net if isinstance(m, nn.Linear)] == [4, 4, 5]


def test_plain_head_when_not_dueling() -> None:
    net = make_net(dueling=False)
    assert not hasattr(net, "value_net") and not hasattr(net, "advantage_net")
    obs = th.rand(4, 3)
    th.testing.assert_close(net(obs), net.q_head(net.feature_net(obs)))
    assert net(obs).shape == (4, 5)
    assert [m.out_features for m in net.q_head if isinstance(m, nn.Linear)] == [4, 4, 5]


def test_predict_is_argmax() -> None:
    net = make_net()
    obs = th.rand(6, 3)
    th.testing.assert_close(net._predict(obs), net(obs).argmax(dim=1))


def test_policy_builds_separate_online_and_target_nets() -> None:
    policy = make_policy()
    assert isinstance(policy.q_net, DuelingQNetwork)
    assert policy.q_net is not policy.q_net_target
    assert policy.q_net.features_extractor is not policy.q_net_target.features_extractor
    optimized = {id(p) for group in policy.optimizer.param_groups for p in group["params"]}
    assert optimized == {id(p) for p in policy.q_net.parameters()}
    obs = th.rand(3, 3)
    th.testing.assert_close(policy.q_net(obs), policy.q_net_target(obs))


def test_policy_save_load(tmp_path: Path) -> None:
    policy = make_policy(dueling=False)
    policy.save(str(tmp_path / "policy.pth"))
    loaded = AyssDQNPolicy.load(str(tmp_path / "policy.pth"))
    assert not loaded.q_net.dueling
    obs = th.rand(5, 3)
    th.testing.assert_close(loaded.q_net(obs), policy.q_net(obs))


def test_training_mode_flag_without_mode_dependent_layers() -> None:
    policy = make_policy()
    assert policy._mode_free
    policy.set_training_mode(False)
    assert not policy.training
    policy.set_training_mode(True)
    assert policy.training


@pytest.mark.parametrize(
    ("module", "free"),
    [
        (nn.Linear(2, 2), True),
        (nn.ReLU(), True),
        (nn.Tanh(), True),
        (nn.Dropout(0.1), False),
        (nn.BatchNorm1d(2), False),
    ],
)
def test_mode_free_detection(module: nn.Module, free: bool) -> None:
    assert _is_mode_free(module) is free


def test_mode_dependent_layers_get_the_mode() -> None:
    class DropoutExtractor(FlattenExtractor):
        def __init__(self, observation_space: spaces.Box) -> None:
            super().__init__(observation_space)
            self.dropout = nn.Dropout(0.5)

    policy = make_policy(features_extractor_class=DropoutExtractor)
    assert not policy._mode_free
    policy.set_training_mode(True)
    assert policy.q_net.features_extractor.training
    policy.set_training_mode(False)
    assert not policy.q_net.features_extractor.training


@pytest.mark.parametrize("dueling", [True, False])
def test_functional_forward_is_bitwise_the_module_forward(dueling: bool) -> None:
    """``_run_mlp`` (F.linear/F.relu on the layers) == calling the modules, values and grads."""
    import sumo_ayss.agents.policies as policies

    th.manual_seed(0)
    net = make_net(dueling=dueling)
    obs = th.rand(64, net.observation_space.shape[0])
    results = []
    for run in (policies._run_mlp, lambda mlp, x: mlp(x)):
        saved, policies._run_mlp = policies._run_mlp, run
        try:
            net.zero_grad(set_to_none=True)
            q = net(obs)
            (q * th.linspace(-1, 1, q.shape[1])).sum().backward()
        finally:
            policies._run_mlp = saved
        results.append((q.detach(), [p.grad.clone() for p in net.parameters()]))
    (q_lean, g_lean), (q_ref, g_ref) = results
    assert th.equal(q_lean, q_ref)
    assert all(th.equal(a, b) for a, b in zip(g_lean, g_ref, strict=True))


def test_functional_forward_falls_back_to_modules_for_other_layers() -> None:
    from sumo_ayss.agents.policies import _run_mlp

    mlp = nn.Sequential(nn.Linear(3, 4), nn.Tanh(), nn.Linear(4, 2))
    x = th.rand(5, 3)
    assert th.equal(_run_mlp(mlp, x), mlp(x))
