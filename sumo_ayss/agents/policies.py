"""Q-networks and the SB3 policy that builds them.

:class:`DuelingQNetwork` maps observations through a shared feature net and either a dueling
head, ``Q = V + A - mean(A)`` (Wang et al., 2016), or a plain MLP Q head. :class:`AyssDQNPolicy`
is SB3's :class:`~stable_baselines3.dqn.policies.DQNPolicy` with that network, so SB3's
``save``/``load``, ``predict``, callbacks and logger work unchanged.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, cast

import torch as th
from gymnasium import spaces
from stable_baselines3.common.policies import BasePolicy
from stable_baselines3.common.torch_layers import (
    BaseFeaturesExtractor,
    FlattenExtractor,
    create_mlp,
)
from stable_baselines3.common.type_aliases import PyTorchObs, Schedule
from stable_baselines3.dqn.policies import DQNPolicy
from torch import nn
from torch.nn import functional as F

DEFAULT_ARCH: tuple[int, ...] = (256, 256)


class DuelingQNetwork(BasePolicy):
    """Action-value network with an optional dueling head.

    Layout: ``features_extractor`` (SB3, flattens) -> ``feature_net`` (MLP, ReLU after every
    layer) -> either ``value_net`` (MLP -> 1) and ``advantage_net`` (MLP -> n_actions) combined
    as ``V + A - mean_a(A)``, or, with ``dueling=False``, ``q_head`` (MLP with the advantage
    stream's hidden layers -> n_actions).

    Args:
        observation_space: Observation space.
        action_space: Discrete action space.
        features_extractor: SB3 features extractor (e.g. ``FlattenExtractor``).
        features_dim: Output size of ``features_extractor``.
        feature_net_arch: Hidden widths of the shared feature net.
        value_net_arch: Hidden widths of the value stream.
        advantage_net_arch: Hidden widths of the advantage stream (or of the plain Q head).
        dueling: Dueling head if True, plain MLP Q head otherwise.
        activation_fn: Activation after each hidden layer.
        normalize_images: SB3 image normalisation flag.
    """

    action_space: spaces.Discrete

    def __init__(
        self,
        observation_space: spaces.Space[Any],
        action_space: spaces.Discrete,
        features_extractor: BaseFeaturesExtractor,
        features_dim: int,
        feature_net_arch: Sequence[int] = DEFAULT_ARCH,
        value_net_arch: Sequence[int] = DEFAULT_ARCH,
        advantage_net_arch: Sequence[int] = DEFAULT_ARCH,
        dueling: bool = True,
        activation_fn: type[nn.Module] = nn.ReLU,
        normalize_images: bool = True,
    ) -> None:
        super().__init__(
            observation_space,
            action_space,
            features_extractor=features_extractor,
            normalize_images=normalize_images,
        )
        self.features_dim = features_dim
        self.feature_net_arch = list(feature_net_arch)
        self.value_net_arch = list(value_net_arch)
        self.advantage_net_arch = list(advantage_net_arch)
        self.dueling = dueling
        self.activation_fn = activation_fn
        n_actions = int(action_space.n)

        trunk = create_mlp(features_dim, -1, self.feature_net_arch, activation_fn)
        self.feature_net = nn.Sequential(*trunk)
        hidden = self.feature_net_arch[-1] if self.feature_net_arch else features_dim
        if dueling:
            self.value_net = nn.Sequential(
                *create_mlp(hidden, 1, self.value_net_arch, activation_fn)
            )
            self.advantage_net = nn.Sequential(
                *create_mlp(hidden, n_actions, self.advantage_net_arch, activation_fn)
            )
        else:
            self.q_head = nn.Sequential(
                *create_mlp(hidden, n_actions, self.advantage_net_arch, activation_fn)
            )

    def forward(self, obs: PyTorchObs) -> th.Tensor:
        """Return Q-values, shape (batch, n_actions).

        The MLPs run as direct ``F.linear``/``F.relu`` calls on their layers' parameters (the
        same ops ``nn.Linear``/``nn.ReLU`` run, so bitwise the same result and gradients)
        without ``nn.Module.__call__`` per layer: about 20 module calls per forward, three
        forwards per gradient step. Forward hooks registered on the MLPs' layers are
        therefore not called; an MLP with any layer other than ``Linear``/``ReLU`` runs
        through its modules as usual.
        """
        hidden = _run_mlp(self.feature_net, self.extract_features(obs, self.features_extractor))
        if not self.dueling:
            return _run_mlp(self.q_head, hidden)
        advantages = _run_mlp(self.advantage_net, hidden)
        value = _run_mlp(self.value_net, hidden)
        return value + advantages - advantages.mean(dim=1, keepdim=True)

    def _predict(self, observation: PyTorchObs, deterministic: bool = True) -> th.Tensor:
        """Return the greedy action per observation, shape (batch,)."""
        action: th.Tensor = self(observation).argmax(dim=1).reshape(-1)
        return action

    def _get_constructor_parameters(self) -> dict[str, Any]:
        data = super()._get_constructor_parameters()
        data.update(
            features_dim=self.features_dim,
            feature_net_arch=self.feature_net_arch,
            value_net_arch=self.value_net_arch,
            advantage_net_arch=self.advantage_net_arch,
            dueling=self.dueling,
            activation_fn=self.activation_fn,
            features_extractor=self.features_extractor,
        )
        return data


class AyssDQNPolicy(DQNPolicy):
    """SB3 DQN policy (online + target :class:`DuelingQNetwork` and the optimizer).

    Args:
        observation_space: Observation space.
        action_space: Discrete action space.
        lr_schedule: Learning-rate schedule; ``lr_schedule(1)`` is the initial rate.
        feature_net_arch: Hidden widths of the shared feature net.
        value_net_arch: Hidden widths of the value stream.
        advantage_net_arch: Hidden widths of the advantage stream (or plain Q head).
        dueling: Dueling head if True, plain MLP Q head otherwise.
        activation_fn: Activation after each hidden layer.
        **kwargs: Passed to :class:`~stable_baselines3.dqn.policies.DQNPolicy`
            (``features_extractor_class``, ``optimizer_class``, ``optimizer_kwargs``, ...).
    """

    q_net: DuelingQNetwork  # type: ignore[assignment]
    q_net_target: DuelingQNetwork  # type: ignore[assignment]

    def __init__(
        self,
        observation_space: spaces.Space[Any],
        action_space: spaces.Discrete,
        lr_schedule: Schedule,
        feature_net_arch: Sequence[int] = DEFAULT_ARCH,
        value_net_arch: Sequence[int] = DEFAULT_ARCH,
        advantage_net_arch: Sequence[int] = DEFAULT_ARCH,
        dueling: bool = True,
        activation_fn: type[nn.Module] = nn.ReLU,
        **kwargs: Any,
    ) -> None:
        kwargs.pop("net_arch", None)  # replaced by the three *_net_arch arguments
        # DQNPolicy.__init__ builds the networks, so the head layout must be known before it.
        self._head_args: dict[str, Any] = {
            "feature_net_arch": list(feature_net_arch),
            "value_net_arch": list(value_net_arch),
            "advantage_net_arch": list(advantage_net_arch),
            "dueling": dueling,
        }
        super().__init__(
            observation_space,
            action_space,
            lr_schedule,
            net_arch=list(feature_net_arch),
            activation_fn=activation_fn,
            **kwargs,
        )

    def make_q_net(self) -> DuelingQNetwork:  # type: ignore[override]
        """Build one Q-network (with its own features extractor) on the policy's device."""
        net_args = self._update_features_extractor(self.net_args, features_extractor=None)
        net_args.pop("net_arch", None)
        return DuelingQNetwork(**net_args, **self._head_args).to(self.device)

    def _build(self, lr_schedule: Schedule) -> None:
        super()._build(lr_schedule)
        self._mode_free = all(_is_mode_free(module) for module in self.q_net.modules())

    def set_training_mode(self, mode: bool) -> None:
        """Put the policy in training or evaluation mode.

        When every layer of the Q-network behaves the same in both modes (no dropout, batch
        norm, ...), only the flag is set: SB3 flips the mode around every ``train()`` call and
        the recursive ``nn.Module.train`` walk costs more than the rest of the bookkeeping.

        Args:
            mode: True for training mode, False for evaluation mode.
        """
        if getattr(self, "_mode_free", False):
            self.training = mode
        else:
            super().set_training_mode(mode)

    def _get_constructor_parameters(self) -> dict[str, Any]:
        data = super()._get_constructor_parameters()
        data.pop("net_arch", None)
        data.update(self._head_args)
        return data


def _run_mlp(mlp: nn.Sequential, x: th.Tensor) -> th.Tensor:
    """``mlp(x)`` as direct functional calls when every layer is ``nn.Linear`` or ``nn.ReLU``.

    ``nn.Linear.forward`` is ``F.linear(x, weight, bias)`` and ``nn.ReLU.forward`` is
    ``F.relu(x, inplace)``: the same kernels on the same tensors, so the output and the
    gradients are bitwise those of ``mlp(x)``. Any other layer: ``mlp(x)`` itself.
    """
    y = x
    for layer in mlp:
        kind = type(layer)
        if kind is nn.Linear:
            linear = cast(nn.Linear, layer)
            y = F.linear(y, linear.weight, linear.bias)
        elif kind is nn.ReLU and not layer.inplace:
            y = F.relu(y)
        else:
            out: th.Tensor = mlp(x)  # start over, through the modules
            return out
    return y


_MODE_FREE_TYPES: frozenset[type[nn.Module]] = frozenset(
    {nn.Linear, nn.Sequential, nn.Flatten, nn.Identity, FlattenExtractor, DuelingQNetwork}
)


def _is_mode_free(module: nn.Module) -> bool:
    """Return whether ``module``'s own computation ignores ``module.training``.

    Exact types only (a subclass may read the flag), plus torch's activation functions.
    """
    kind = type(module)
    return kind in _MODE_FREE_TYPES or kind.__module__ == "torch.nn.modules.activation"
