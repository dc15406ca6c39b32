"""The training env(s) behind one interface: one env, or N pairs in one SUMO simulation.

A :class:`Collector` owns the ``VecEnv`` SB3 collects transitions from and everything the
trainer does to it between SB3's steps: evaluating a candidate on the process's one
simulation (borrowing the training env(s)), putting training back afterwards, recording the
*anchor* (the env state a resume restarts from) and restoring it.

- :class:`SingleEnvCollector` (``train.n_envs == 1``): one :class:`~sumo_ayss.envs.pair_env.
  PairEnv` in SB3's ``DummyVecEnv``. A candidate is evaluated at an episode boundary; the
  current episode's start is then restored exactly.
- :class:`PairsCollector` (``n_envs > 1``): a :class:`~sumo_ayss.envs.vec_env.PairVecEnv`.
  Its episodes never end together, so a candidate is evaluated at once, on the pairs, and
  every pair's unfinished episode is then cut (stored as a time-limit truncation) and
  restarted.
"""

from __future__ import annotations

import dataclasses
import time
from abc import ABC, abstractmethod
from collections.abc import MutableMapping, Sequence
from typing import Any

import numpy as np
from stable_baselines3.common.monitor import Monitor
from stable_baselines3.common.vec_env import DummyVecEnv, VecEnv, VecMonitor

from sumo_ayss.agents import sb3_adapter
from sumo_ayss.agents.dqn import AyssDQN
from sumo_ayss.agents.greedy import GreedyPolicy
from sumo_ayss.config import EnvConfig
from sumo_ayss.envs import make_env
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.envs.pair_env import PairEnv
from sumo_ayss.envs.vec_env import PairVecEnv
from sumo_ayss.scenarios.rollout import EpisodeResult, Policy, episode_result, run_episodes

#: SB3's rollout locals as a callback sees them (``BaseCallback.locals``); None outside.
Rollout = MutableMapping[str, Any]


class Collector(ABC):
    """The training env(s) of one run (see the module docstring).

    Attributes:
        vec_env: What SB3 collects from (wrapped in a monitor for episode statistics).
    """

    vec_env: VecEnv

    @abstractmethod
    def ready_for_candidate(self, rollout: Rollout) -> bool:
        """Whether a due candidate can be evaluated after the step just taken."""

    @abstractmethod
    def evaluate(
        self, model: AyssDQN, scenarios: Sequence[InitialCondition], rollout: Rollout | None
    ) -> tuple[list[EpisodeResult], float]:
        """Evaluate ``model``'s greedy policy on ``scenarios``, then put training back.

        Args:
            model: The learner (SB3's rollout start is updated where training restarts).
            scenarios: The evaluation's initial conditions, one episode each.
            rollout: SB3's rollout locals when called from the step callback, after
                :meth:`ready_for_candidate`; None at the end of ``learn``.

        Returns:
            The episodes' results, in order, and the evaluation's wall time [s].
        """

    @abstractmethod
    def anchor(self) -> dict[str, Any]:
        """The env state a resume restarts from (JSON-able): episode start(s) and RNGs."""

    @abstractmethod
    def restore(self, model: AyssDQN, state: dict[str, Any], seed: int) -> None:
        """Put the env(s) back at the anchor in ``state``, SB3's rollout start with them.

        Args:
            model: The resumed learner.
            state: A checkpoint state holding an :meth:`anchor`.
            seed: The run's seed (the env's first reset, which starts SUMO).
        """

    @abstractmethod
    def close(self) -> None:
        """Close the env(s) and SUMO."""


class SingleEnvCollector(Collector):
    """One env in SB3's ``DummyVecEnv`` (through a ``Monitor``)."""

    def __init__(self, config: EnvConfig, seed: int) -> None:
        env = make_env(config, sumo_seed=seed)
        self.env: PairEnv = env
        self.vec_env = DummyVecEnv([lambda: Monitor(env)])
        self._current_ic: InitialCondition | None = None  # the episode a candidate interrupted

    def ready_for_candidate(self, rollout: Rollout) -> bool:
        """At the first episode end (the env is borrowed and restored there)."""
        return sb3_adapter.rollout_episode_ended(rollout, 0)

    def evaluate(
        self, model: AyssDQN, scenarios: Sequence[InitialCondition], rollout: Rollout | None
    ) -> tuple[list[EpisodeResult], float]:
        """Borrow the training env; restore its current episode's start afterwards.

        Evaluation resets it to fixed initial conditions (this does not consume its RNG);
        called from the callback (an episode boundary), the current episode's start is then
        restored exactly, so the observation SB3 holds stays true.
        """
        env = self.env
        t0 = time.perf_counter()
        self._current_ic = current_ic = env.initial_condition
        results = run_episodes(env, GreedyPolicy(model), scenarios)
        wall = time.perf_counter() - t0
        if rollout is not None and current_ic is not None:
            env.reset(options={"initial_condition": current_ic})
        return results, wall

    def anchor(self) -> dict[str, Any]:
        """The current episode's start (before the last evaluation) and the env's RNG."""
        current_ic = self._current_ic
        ic_dict = dataclasses.asdict(current_ic) if current_ic is not None else None
        return {"initial_condition": ic_dict, "env_rng": self.env.np_random.bit_generator.state}

    def restore(self, model: AyssDQN, state: dict[str, Any], seed: int) -> None:
        """The env at the checkpoint's episode start, its RNG where it was (through the
        ``Monitor`` wrapper, which must see the reset too)."""
        assert isinstance(self.vec_env, DummyVecEnv)
        monitor = self.vec_env.envs[0]
        monitor.reset(seed=seed)  # starts SUMO and creates the env RNG
        self.env.np_random.bit_generator.state = state["env_rng"]
        ic = state["initial_condition"]
        obs, _ = monitor.reset(
            options={"initial_condition": InitialCondition(**ic)} if ic else None
        )
        sb3_adapter.set_rollout_start(model, obs[None, :], np.ones((1,), dtype=bool))

    def close(self) -> None:
        self.vec_env.close()
        self.env.close()


class PairsCollector(Collector):
    """N VUT-POV pairs in one SUMO simulation (:class:`PairVecEnv` in a ``VecMonitor``)."""

    def __init__(self, config: EnvConfig, n_envs: int, seed: int) -> None:
        self.pair_vec = PairVecEnv(config, n_envs, sumo_seed=seed)
        self.vec_env = VecMonitor(self.pair_vec)
        self.n_envs = n_envs

    def ready_for_candidate(self, rollout: Rollout) -> bool:
        """At once: the pairs' episodes never end together (they are cut and restarted)."""
        return True

    def evaluate(
        self, model: AyssDQN, scenarios: Sequence[InitialCondition], rollout: Rollout | None
    ) -> tuple[list[EpisodeResult], float]:
        """Evaluate on the pairs, then a fresh training episode on every pair.

        Each pair's unfinished episode is cut. Called from the callback (``rollout``), the
        step's transitions are not stored yet: they become time-limit truncations
        (:func:`~sumo_ayss.agents.sb3_adapter.truncate_rollout_step`) and SB3 continues
        from the fresh episodes' first observations.
        """
        t0 = time.perf_counter()
        results = evaluate_on_vec(self.pair_vec, GreedyPolicy(model), scenarios)
        wall = time.perf_counter() - t0
        obs = self.vec_env.reset()  # VecMonitor too: its running episode sums restart
        assert isinstance(obs, np.ndarray)
        if rollout is None:
            sb3_adapter.set_rollout_start(model, obs, np.ones((self.n_envs,), dtype=bool))
        else:
            sb3_adapter.truncate_rollout_step(rollout, obs)
        return results, wall

    def anchor(self) -> dict[str, Any]:
        """The pairs' current episode starts and RNGs."""
        return {
            "initial_conditions": [
                dataclasses.asdict(ic) if ic is not None else None
                for ic in self.pair_vec.initial_conditions
            ],
            "env_rngs": [env.np_random.bit_generator.state for env in self.pair_vec.envs],
        }

    def restore(self, model: AyssDQN, state: dict[str, Any], seed: int) -> None:
        """Restart every pair at its checkpointed episode start, RNGs where they were."""
        ics = state["initial_conditions"]
        self.vec_env.set_options(
            [{"initial_condition": InitialCondition(**ic)} if ic else {} for ic in ics]
        )
        obs = self.vec_env.reset()  # starts SUMO; given starts do not use the pairs' RNGs
        for env, rng_state in zip(self.pair_vec.envs, state["env_rngs"], strict=True):
            env.np_random.bit_generator.state = rng_state
        assert isinstance(obs, np.ndarray)
        sb3_adapter.set_rollout_start(model, obs, np.ones((self.n_envs,), dtype=bool))

    def close(self) -> None:
        self.vec_env.close()


def make_collector(config: EnvConfig, n_envs: int, seed: int) -> Collector:
    """The collector for ``n_envs`` training envs (``train.n_envs``), SUMO seed ``seed``."""
    if n_envs == 1:
        return SingleEnvCollector(config, seed)
    return PairsCollector(config, n_envs, seed)


def evaluate_on_vec(
    vec: PairVecEnv, policy: Policy, scenarios: Sequence[InitialCondition]
) -> list[EpisodeResult]:
    """:func:`~sumo_ayss.scenarios.rollout.run_episodes` on the pairs of ``vec``, N at a time.

    Each episode equals the single env's from the same initial condition under the same
    actions (:meth:`PairVecEnv.run_scenarios`); a greedy network policy called on a batch of
    N observations may differ from one called on one observation in the last float bits,
    which can only matter at exact ties of two actions' Q-values. ``vec`` needs a
    :meth:`~PairVecEnv.reset` afterwards.
    """
    return [episode_result(t.rewards, t.infos) for t in vec.run_scenarios(policy, scenarios)]
