"""Every access to stable-baselines3's private state, in one place.

SB3 exposes no public way to set where a rollout continues from, to edit a step's transitions
before they are stored, or to read a learner's progress and update count from a ``train()``
override. Training needs all of these (exact resume, candidate evaluation between rollouts,
:class:`~sumo_ayss.agents.dqn.AyssDQN`'s lean ``train()``), so they are done here and only
here, each with the SB3 behaviour it relies on. Written against **stable-baselines3 2.9.2**
(:data:`SB3_VERSION`); ``tests/agents/test_sb3_adapter.py`` checks each access against the
installed SB3, so an upgrade that moves one fails there first.

What is *not* here: SB3's documented extension hooks that our subclasses override
(``DQN._create_aliases`` / ``_excluded_save_params`` in :mod:`~sumo_ayss.agents.dqn`,
``DQNPolicy._build`` / ``_predict`` / ``_get_constructor_parameters`` in
:mod:`~sumo_ayss.agents.policies`, ``ReplayBuffer._normalize_*`` in
:mod:`~sumo_ayss.agents.replay`): subclassing is SB3's extension mechanism, and those
overrides must live on the subclass. Checkpoints stay plain SB3 zips: nothing here changes
what ``save`` writes, so ``DQN.load`` and ``AyssDQN.load`` read them
(``tests/agents/test_dqn.py``).
"""

from __future__ import annotations

from collections.abc import MutableMapping, MutableSequence
from typing import Any

import numpy as np
import numpy.typing as npt
import torch as th
from stable_baselines3.common.off_policy_algorithm import OffPolicyAlgorithm
from stable_baselines3.common.vec_env import VecNormalize

#: The SB3 release whose internals this module was written against (``pip show``).
SB3_VERSION = "2.9.2"

#: Rollout locals read or written (names of local variables of SB3 2.9.2's
#: ``OffPolicyAlgorithm.collect_rollouts``, passed to callbacks by ``update_locals(locals())``
#: right after ``env.step`` and before ``_store_transition``).
ROLLOUT_LOCALS = ("actions", "new_obs", "dones", "infos")


def set_rollout_start(
    model: OffPolicyAlgorithm, obs: npt.NDArray[Any], episode_starts: npt.NDArray[np.bool_]
) -> None:
    """Make the next collected step start from ``obs`` (one row per env).

    Args:
        model: The learner.
        obs: Observations, shape ``(n_envs, obs_dim)``: what the envs show now.
        episode_starts: Shape ``(n_envs,)``, True where an episode has just begun.
    """
    # SB3 2.9.2: ``collect_rollouts`` predicts from ``self._last_obs`` and stores it as the
    # transition's observation; ``learn`` only resets it when ``reset_num_timesteps`` or it
    # is None (``_setup_learn``), so a value set here survives into the next ``learn``.
    model._last_obs = obs
    # SB3 2.9.2: ``_last_episode_starts`` is passed to ``predict`` as ``episode_start``
    # (recurrent policies only) and reset to ones by ``_setup_learn``; kept consistent.
    model._last_episode_starts = episode_starts


def rollout_actions(rollout: MutableMapping[str, Any]) -> npt.NDArray[Any]:
    """The actions of the step just taken, from a callback's ``locals`` (``(n_envs,)``)."""
    # SB3 2.9.2 ``collect_rollouts``: local ``actions`` (env actions, unscaled).
    actions: np.ndarray = rollout["actions"]
    return actions


def rollout_episode_ended(rollout: MutableMapping[str, Any], env_index: int = 0) -> bool:
    """Whether env ``env_index``'s episode ended at the step just taken (callback locals)."""
    # SB3 2.9.2 ``collect_rollouts``: local ``dones`` from ``env.step``.
    return bool(rollout["dones"][env_index])


def truncate_rollout_step(rollout: MutableMapping[str, Any], fresh_obs: npt.NDArray[Any]) -> None:
    """Cut every env's running episode at the step just taken, before SB3 stores it.

    Called from a callback's ``_on_step`` (``rollout`` = its ``locals``): an env whose episode
    was still running gets ``done`` with its observation as ``terminal_observation`` and
    ``TimeLimit.truncated`` (the replay buffer then bootstraps it, as at a time limit), and
    the observation SB3 continues from becomes ``fresh_obs`` (the fresh episodes' first).

    Args:
        rollout: SB3's rollout locals (edited in place).
        fresh_obs: The envs' observations after a reset, shape ``(n_envs, obs_dim)``.
    """
    # SB3 2.9.2 ``collect_rollouts``: after ``on_step`` it calls ``_store_transition`` with
    # these very objects (``new_obs``, ``dones``, ``infos``), which reads
    # ``infos[i]["terminal_observation"]`` for done envs and ``TimeLimit.truncated`` in
    # ``ReplayBuffer.add`` (``handle_timeout_termination``), then sets
    # ``self._last_obs = new_obs``: edited in place, they are what is stored and continued.
    new_obs: npt.NDArray[Any] = rollout["new_obs"]
    dones: MutableSequence[bool] = rollout["dones"]
    infos: list[dict[str, Any]] = rollout["infos"]
    for i in range(len(dones)):
        if not dones[i]:
            infos[i]["terminal_observation"] = new_obs[i].copy()
            infos[i]["TimeLimit.truncated"] = True
            dones[i] = True
    new_obs[:] = fresh_obs


def progress_remaining(model: OffPolicyAlgorithm) -> float:
    """SB3's remaining progress of the current ``learn`` call: 1 at its start, 0 at its end."""
    # SB3 2.9.2: ``_current_progress_remaining``, updated by ``_update_current_progress_remaining``
    # every step in ``collect_rollouts``; drives the exploration and learning-rate schedules.
    return float(model._current_progress_remaining)


def vec_normalize_env(model: OffPolicyAlgorithm) -> VecNormalize | None:
    """The model's ``VecNormalize`` wrapper, if any (what ``ReplayBuffer.sample`` takes)."""
    # SB3 2.9.2: ``_vec_normalize_env``, set by ``_wrap_env``/``set_env``; SB3's own
    # ``DQN.train`` passes it to ``replay_buffer.sample(..., env=...)``.
    return model._vec_normalize_env


def update_learning_rate(model: OffPolicyAlgorithm, optimizer: th.optim.Optimizer) -> None:
    """Set ``optimizer``'s learning rate from the model's schedule at the current progress."""
    # SB3 2.9.2: ``_update_learning_rate`` (BaseAlgorithm), also logs ``train/learning_rate``;
    # SB3's own ``DQN.train`` calls it first.
    model._update_learning_rate(optimizer)


def add_gradient_updates(model: OffPolicyAlgorithm, n: int) -> int:
    """Count ``n`` more gradient steps; return the total (logged as ``train/n_updates``)."""
    # SB3 2.9.2: ``_n_updates`` is saved with the model and only logged; SB3's own
    # ``DQN.train`` increments it by ``gradient_steps``.
    model._n_updates += n
    return int(model._n_updates)
