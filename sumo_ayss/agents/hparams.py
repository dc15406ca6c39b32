"""Hyper-parameters of the adversarial agent's DQN learner.

:class:`DQNHyperParams` is a frozen, validated record whose defaults are the paper's settings.
Build it directly or from a config mapping with :meth:`DQNHyperParams.from_mapping`, which
rejects unknown keys and suggests the closest allowed one.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from sumo_ayss.util.errors import ConfigError
from sumo_ayss.util.validation import check_int, check_keys, check_number

_DEFAULT_PREFIX = "agent"
_ARCH_FIELDS = ("feature_net_arch", "value_net_arch", "advantage_net_arch")
_BOOL_FIELDS = ("double", "dueling", "prioritized")


@dataclass(frozen=True)
class DQNHyperParams:
    """DQN hyper-parameters; the defaults are the paper's.

    Attributes:
        gamma: Discount factor, in (0, 1].
        learning_rate: Adam learning rate, > 0.
        double: Use the double-DQN target (online-net argmax, target-net value).
        dueling: Use the dueling head Q = V + A - mean(A); otherwise a plain MLP Q head.
        prioritized: Use proportional prioritized experience replay.
        feature_net_arch: Hidden layer widths of the shared feature net (ReLU).
        value_net_arch: Hidden layer widths of the value stream (ReLU).
        advantage_net_arch: Hidden layer widths of the advantage stream (ReLU); also the
            Q head's hidden layers when ``dueling`` is off.
        per_alpha: Priority exponent α in [0, 1] (0 = uniform sampling).
        per_beta0: Initial importance-sampling exponent β in [0, 1], annealed linearly to 1.
        per_beta_steps: Environment steps (SB3 ``num_timesteps``, all envs) over which β
            reaches 1; ``None`` = the whole ``total_timesteps`` of the ``learn`` run.
        per_eps: Added to ``|TD error|`` so that no priority is zero, > 0.
        buffer_size: Replay capacity in transitions (over all envs), >= 1.
        batch_size: Minibatch size, >= 1.
        learning_starts: Environment steps collected before the first gradient step, >= 0.
        train_freq: Vec-env steps between two training phases (each step adds one
            transition per env), >= 1.
        gradient_steps: Gradient steps per training phase, >= 1.
        target_update_interval: Environment steps between hard target-network copies, >= 1.
        exploration_fraction: Fraction of the run over which ε decays, in [0, 1].
        exploration_initial_eps: Initial ε, in [0, 1].
        exploration_final_eps: Final ε, in [0, 1].
        max_grad_norm: Gradient-norm clipping threshold, > 0.
    """

    gamma: float = 0.8
    learning_rate: float = 1e-5
    double: bool = True
    dueling: bool = True
    prioritized: bool = True
    feature_net_arch: tuple[int, ...] = (256, 256)
    value_net_arch: tuple[int, ...] = (256, 256)
    advantage_net_arch: tuple[int, ...] = (256, 256)
    per_alpha: float = 0.6
    per_beta0: float = 0.4
    per_beta_steps: int | None = None
    per_eps: float = 1e-6
    buffer_size: int = 100_000
    batch_size: int = 64
    learning_starts: int = 1000
    train_freq: int = 4
    gradient_steps: int = 1
    target_update_interval: int = 1000
    exploration_fraction: float = 0.3
    exploration_initial_eps: float = 1.0
    exploration_final_eps: float = 0.05
    max_grad_norm: float = 10.0

    def __post_init__(self) -> None:
        """Normalise list-valued architectures to tuples and validate every field.

        Raises:
            ConfigError: A field has a bad type or value; the message names it.
        """
        for name in _ARCH_FIELDS:
            value = getattr(self, name)
            if isinstance(value, list):
                object.__setattr__(self, name, tuple(value))
        self._validate()

    @property
    def update_to_data_ratio(self) -> float:
        """Gradient steps per environment step (per env): ``gradient_steps / train_freq``."""
        return self.gradient_steps / self.train_freq

    def to_dict(self) -> dict[str, Any]:
        """Return the fields as a plain dict (architectures as lists), e.g. for YAML dumps."""
        data = dataclasses.asdict(self)
        for name in _ARCH_FIELDS:
            data[name] = list(data[name])
        return data

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any], prefix: str = _DEFAULT_PREFIX) -> DQNHyperParams:
        """Build from a config mapping; missing keys take the defaults.

        Args:
            data: Field name -> value; architecture fields accept lists.
            prefix: Dotted config path of ``data``, used in error messages.

        Returns:
            The validated hyper-parameters.

        Raises:
            ConfigError: ``data`` is not a mapping, has an unknown key (the message suggests
                the closest allowed key and lists them all), or a value is invalid.
        """
        if not isinstance(data, Mapping):
            raise ConfigError(f"{prefix} must be a mapping, got {type(data).__name__}")
        check_keys(prefix, data, [f.name for f in dataclasses.fields(cls)])
        try:
            return cls(**dict(data))
        except ConfigError as err:
            message = str(err)
            if prefix != _DEFAULT_PREFIX and message.startswith(_DEFAULT_PREFIX + "."):
                message = prefix + message[len(_DEFAULT_PREFIX) :]
            raise ConfigError(message) from None

    def _validate(self) -> None:
        """Check every field; raise :class:`ConfigError` naming the first bad one."""
        p = _DEFAULT_PREFIX
        check_number(f"{p}.gamma", self.gamma, low=0.0, high=1.0, low_open=True)
        check_number(f"{p}.learning_rate", self.learning_rate, low=0.0, low_open=True)
        for name in _BOOL_FIELDS:
            value = getattr(self, name)
            if not isinstance(value, bool):
                raise ConfigError(f"{p}.{name} must be a bool, got {value!r}")
        for name in _ARCH_FIELDS:
            value = getattr(self, name)
            if not isinstance(value, tuple) or not all(_is_int(w) and w > 0 for w in value):
                raise ConfigError(
                    f"{p}.{name} must be a list of positive ints (layer widths), got {value!r}"
                )
        check_number(f"{p}.per_alpha", self.per_alpha, low=0.0, high=1.0)
        check_number(f"{p}.per_beta0", self.per_beta0, low=0.0, high=1.0)
        check_int(f"{p}.per_beta_steps", self.per_beta_steps, low=1, none_ok=True)
        check_number(f"{p}.per_eps", self.per_eps, low=0.0, low_open=True)
        check_int(f"{p}.buffer_size", self.buffer_size, low=1)
        check_int(f"{p}.batch_size", self.batch_size, low=1)
        check_int(f"{p}.learning_starts", self.learning_starts, low=0)
        if self.buffer_size < self.batch_size:
            raise ConfigError(
                f"{p}.buffer_size ({self.buffer_size}) must be >= {p}.batch_size "
                f"({self.batch_size}): a minibatch is drawn from the buffer"
            )
        check_int(f"{p}.train_freq", self.train_freq, low=1)
        check_int(f"{p}.gradient_steps", self.gradient_steps, low=1)
        check_int(f"{p}.target_update_interval", self.target_update_interval, low=1)
        check_number(f"{p}.exploration_fraction", self.exploration_fraction, low=0.0, high=1.0)
        check_number(f"{p}.exploration_initial_eps", self.exploration_initial_eps, 0.0, 1.0)
        check_number(f"{p}.exploration_final_eps", self.exploration_final_eps, 0.0, 1.0)
        check_number(f"{p}.max_grad_norm", self.max_grad_norm, low=0.0, low_open=True)


def _is_int(value: object) -> bool:
    """Return whether ``value`` is an int and not a bool."""
    return isinstance(value, int) and not isinstance(value, bool)
