"""DQN learner with switchable double-DQN, dueling and prioritized-replay extensions.

:class:`AyssDQN` is SB3's :class:`~stable_baselines3.DQN` configured from a
:class:`~sumo_ayss.agents.hparams.DQNHyperParams` with a leaner ``train()``:

* target ``r + γ(1 - d)·Q_target(s', argmax_a Q_online(s', a))`` when ``double`` (else
  ``max_a Q_target(s', a)``);
* Huber loss, weighted by the importance weights when ``prioritized``; the sampled
  transitions' priorities are then set to ``|δ| + eps``, and β is annealed linearly from
  ``per_beta0`` to 1 (:attr:`AyssDQN.per_beta`);
* per gradient step: one buffer sample, three forward passes (functional calls on the
  layers, :func:`~sumo_ayss.agents.policies._run_mlp`), one backward, a gradient-norm clip,
  one fused-Adam step, one device->host copy (the TD errors, only with PER) and no logger
  calls (the loss is logged once per ``train()`` call).
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from typing import Any

import torch as th
from stable_baselines3 import DQN
from stable_baselines3.common.buffers import ReplayBuffer
from stable_baselines3.common.type_aliases import GymEnv, ReplayBufferSamples
from stable_baselines3.common.utils import get_device
from torch.nn import functional as F

from sumo_ayss.agents.hparams import DQNHyperParams
from sumo_ayss.agents.policies import AyssDQNPolicy
from sumo_ayss.agents.replay import PrioritizedReplayBuffer, PrioritizedReplayBufferSamples
from sumo_ayss.agents.sb3_adapter import (
    add_gradient_updates,
    progress_remaining,
    update_learning_rate,
    vec_normalize_env,
)

logger = logging.getLogger(__name__)


def _optimizer_kwargs(device: th.device | str) -> dict[str, Any]:
    """Adam options for ``device``: the fused kernel where torch has one (much cheaper on CPU)."""
    kind = get_device(device).type
    return {"fused": True} if kind in ("cpu", "cuda") else {}


class AyssDQN(DQN):
    """SB3 DQN with double-DQN, dueling and prioritized replay, each switchable by hparams.

    Build it from an env and hyper-parameters; SB3's ``learn``, ``predict``, ``save``,
    ``AyssDQN.load``, ``save_replay_buffer`` and ``load_replay_buffer`` work as for ``DQN``.

    Args:
        env: Gymnasium env, VecEnv, or registered env id (Box observations, Discrete actions).
        hparams: Hyper-parameters; ``None`` means the paper's defaults.
        policy: Policy class (keep the default; SB3's ``load`` passes the stored one).
        seed: Seed for python, numpy, torch and the env.
        tensorboard_log: TensorBoard log folder, or ``None``.
        device: Torch device ("cpu", "cuda", "auto").
        verbose: SB3 verbosity (0 silent, 1 info, 2 debug).
        _init_setup_model: Build networks and buffer now (SB3's ``load`` passes False).
    """

    policy: AyssDQNPolicy
    replay_buffer: ReplayBuffer

    def __init__(
        self,
        env: GymEnv | str | None,
        hparams: DQNHyperParams | None = None,
        *,
        policy: type[AyssDQNPolicy] = AyssDQNPolicy,
        seed: int | None = None,
        tensorboard_log: str | None = None,
        device: th.device | str = "cpu",
        verbose: int = 0,
        _init_setup_model: bool = True,
    ) -> None:
        hp = DQNHyperParams() if hparams is None else hparams
        self.hparams = hp
        buffer_class: type[ReplayBuffer] = ReplayBuffer
        buffer_kwargs: dict[str, Any] = {}
        if hp.prioritized:
            buffer_class = PrioritizedReplayBuffer
            buffer_kwargs = {"alpha": hp.per_alpha, "eps": hp.per_eps}
        policy_kwargs: dict[str, Any] = {
            "feature_net_arch": list(hp.feature_net_arch),
            "value_net_arch": list(hp.value_net_arch),
            "advantage_net_arch": list(hp.advantage_net_arch),
            "dueling": hp.dueling,
            "optimizer_kwargs": _optimizer_kwargs(device),
        }
        super().__init__(
            policy,
            env,  # type: ignore[arg-type]
            learning_rate=hp.learning_rate,
            buffer_size=hp.buffer_size,
            learning_starts=hp.learning_starts,
            batch_size=hp.batch_size,
            tau=1.0,
            gamma=hp.gamma,
            train_freq=hp.train_freq,
            gradient_steps=hp.gradient_steps,
            replay_buffer_class=buffer_class,
            replay_buffer_kwargs=buffer_kwargs,
            target_update_interval=hp.target_update_interval,
            exploration_fraction=hp.exploration_fraction,
            exploration_initial_eps=hp.exploration_initial_eps,
            exploration_final_eps=hp.exploration_final_eps,
            max_grad_norm=hp.max_grad_norm,
            tensorboard_log=tensorboard_log,
            policy_kwargs=policy_kwargs,
            verbose=verbose,
            seed=seed,
            device=device,
            _init_setup_model=_init_setup_model,
        )
        logger.debug("AyssDQN built: %s", hp)

    @classmethod
    def from_hparams(
        cls,
        env: GymEnv | str,
        hparams: DQNHyperParams,
        **kwargs: Any,
    ) -> AyssDQN:
        """Build a model; same as ``AyssDQN(env, hparams, **kwargs)``.

        Args:
            env: The training env.
            hparams: Hyper-parameters.
            **kwargs: ``seed``, ``tensorboard_log``, ``device``, ``verbose``.

        Returns:
            The new model.
        """
        return cls(env, hparams, **kwargs)

    @property
    def per_beta(self) -> float:
        """Current importance-sampling exponent β, annealed linearly from ``per_beta0`` to 1.

        Over ``per_beta_steps`` environment steps, or the whole ``learn`` run when ``None``.
        """
        hp = self.hparams
        if hp.per_beta_steps is None:
            fraction = 1.0 - progress_remaining(self)
        else:
            fraction = self.num_timesteps / hp.per_beta_steps
        fraction = min(max(fraction, 0.0), 1.0)
        return hp.per_beta0 + fraction * (1.0 - hp.per_beta0)

    def _create_aliases(self) -> None:
        super()._create_aliases()
        self._q_params = [p for p in self.q_net.parameters() if p.requires_grad]

    def _excluded_save_params(self) -> list[str]:
        return [*super()._excluded_save_params(), "_q_params"]

    def train(self, gradient_steps: int, batch_size: int = 100) -> None:
        """Run ``gradient_steps`` gradient steps on minibatches of ``batch_size``.

        Args:
            gradient_steps: Number of gradient steps.
            batch_size: Minibatch size.
        """
        self.policy.set_training_mode(True)
        update_learning_rate(self, self.policy.optimizer)
        buffer = self.replay_buffer
        per_buffer = buffer if isinstance(buffer, PrioritizedReplayBuffer) else None
        beta = self.per_beta if per_buffer is not None else 1.0
        double = self.hparams.double
        q_net, q_net_target = self.q_net, self.q_net_target
        optimizer = self.policy.optimizer
        params = self._q_params
        max_norm = float(self.max_grad_norm)
        loss_sum = th.zeros((), device=self.device)
        normalizer = vec_normalize_env(self)

        for _ in range(gradient_steps):
            data: ReplayBufferSamples | PrioritizedReplayBufferSamples
            if per_buffer is not None:
                data = per_buffer.sample(batch_size, env=normalizer, beta=beta)
                weights, indices = data.weights, data.indices
            else:
                data = buffer.sample(batch_size, env=normalizer)
            discounts = data.discounts if data.discounts is not None else self.gamma

            with th.no_grad():
                next_q_target = q_net_target(data.next_observations)
                if double:
                    next_actions = q_net(data.next_observations).argmax(dim=1, keepdim=True)
                    next_q = next_q_target.gather(1, next_actions)
                else:
                    next_q = next_q_target.amax(dim=1, keepdim=True)
                target_q = data.rewards + (1.0 - data.dones) * discounts * next_q

            current_q = q_net(data.observations).gather(1, data.actions.long())
            if per_buffer is not None:
                elementwise = F.smooth_l1_loss(current_q, target_q, reduction="none")
                loss = (weights * elementwise).mean()
            else:
                loss = F.smooth_l1_loss(current_q, target_q)

            for param in params:  # optimizer.zero_grad(set_to_none=True), minus its wrappers
                param.grad = None
            loss.backward()
            _clip_grad_norm(params, max_norm)
            optimizer.step()

            if per_buffer is not None:
                td_errors = (current_q.detach() - target_q).abs_().reshape(-1)
                per_buffer.update_priorities(indices, td_errors.cpu().numpy())
            loss_sum += loss.detach()

        n_updates = add_gradient_updates(self, gradient_steps)
        self.logger.record("train/n_updates", n_updates, exclude="tensorboard")
        self.logger.record("train/loss", loss_sum.item() / gradient_steps)
        if per_buffer is not None:
            self.logger.record("train/per_beta", beta)


def _clip_grad_norm(params: Sequence[th.Tensor], max_norm: float) -> None:
    """Scale gradients in place so that their global L2 norm is at most ``max_norm``.

    Same result as ``torch.nn.utils.clip_grad_norm_`` (coefficient ``max_norm / (norm + 1e-6)``
    clamped to 1). On CPU the rescaling pass is skipped when it would multiply by 1; on an
    accelerator the coefficient stays on the device (no host sync).

    Args:
        params: Parameters whose ``.grad`` to clip (those without a gradient are skipped).
        max_norm: Maximum global norm.
    """
    grads = [p.grad for p in params if p.grad is not None]
    if not grads:
        return
    total = th.linalg.vector_norm(th.stack(th._foreach_norm(grads)))
    if total.device.type != "cpu":
        th._foreach_mul_(grads, th.clamp(max_norm / (total + 1e-6), max=1.0))
        return
    coef = max_norm / (float(total) + 1e-6)
    if coef < 1.0:
        th._foreach_mul_(grads, coef)
