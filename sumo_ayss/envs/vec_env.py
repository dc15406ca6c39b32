"""Many VUT-POV pairs in one SUMO simulation, as a stable-baselines3 ``VecEnv``.

libsumo holds one simulation per process, so SB3's ``DummyVecEnv`` cannot hold two of our
envs, and ``SubprocVecEnv`` pays a process and a pipe round trip per env and step.
:class:`PairVecEnv` instead hosts N independent episodes of ``CarFollowing-v0`` or
``CutIn-v0`` in *one* simulation: pair ``i`` drives on road ``i`` of a network of N parallel
copies of the built-in road (:func:`~sumo_ayss.sim.network.build_parallel_network`, built
into a temporary folder; roads 50 m apart, no shared node, so pairs never perceive or touch
each other), and one ``simulationStep`` advances all pairs.

Same code as the single env. Each pair is an ordinary :class:`~sumo_ayss.envs.pair_env.
PairEnv` (``CarFollowingEnv``/``CutInEnv``) joined to the shared simulation; the vec env
calls its public episode phases (:class:`~sumo_ayss.envs.protocol.EpisodePhases`, where the
order of calls is documented: ``begin_decision`` → ``command_pov`` → shared step →
``end_decision``; ``begin_reset`` → vehicles → ``start_episode``), exactly the code the
single env's ``step``/``reset`` are made of. Observation, reward, termination, info and the
POV's actuator are therefore the single env's, not a copy.

Per-pair auto-reset, SB3 style: when a pair's episode ends, its info gets
``terminal_observation`` (the last observation of the episode) and ``TimeLimit.truncated``
(True when the 5 s ran out, False at a collision), and the observation returned for it is
the first one of its next episode, sampled from that pair's own RNG (``reset`` with
``seed(s)`` seeds pair ``i`` with ``s + i``, as SB3 does).

Insertion without a step. The single env spends one SUMO step of its own on inserting an
episode's two fresh vehicles, then moves them into place. Here every step moves all pairs,
so no pair can have a private insertion step. Instead a pair's fresh vehicles are placed
while still *waiting* for insertion: libsumo's ``vehicle.moveTo`` on a vehicle that has not
departed takes it out of the insertion queue and inserts it at once at the given lane
position, as departing (SUMO's ``Vehicle::moveTo``: ``alreadyDeparted`` +
``forceVehicleInsertion(..., NOTIFICATION_DEPARTED)``). So a reset, automatic or by
:meth:`PairVecEnv.reset`, is: remove the old vehicles, add two fresh ones, and place them
with the single env's own placement (``moveTo`` + ``setPreviousSpeed``), between two shared
steps and without one of its own; the next shared step is the new episode's first. No
spare vehicles wait on the roads, and SUMO steps only the N running pairs.

Equivalence with the single env (``tests/envs/test_vec_env.py``): a pair of the vec env,
seeded like a single env (same seed, same ``sumo_seed``) and given the same actions,
produces bit-identical observations, rewards (float32 in the vec env, as in SB3's
``DummyVecEnv``), terminations, truncations and info values across auto-resets and
collisions, except the world y positions in cut-in's info, offset by the road's lateral
position (road i lies 50·i m to the right of road 0), and Δv̄ computed from them, equal to
1e-9 m/s (measured: 1e-13). This holds for VUT models without random numbers: checked
bit-identical for the built-in IDM VUTs, ACC, CACC, Krauss with ``sigma = 0`` and EIDM with
its noise off, memory models included (a pair's vehicles are fresh every episode in both
envs). SUMO draws a stochastic model's random numbers (``sigma``, ``speedDev``, EIDM's
noise) from streams shared by all vehicles, so such pairs are statistically, not bitwise,
equivalent to the single env.

Observations are built as one float32 array for all pairs from each pair's observation
values (the single env makes the same float32 conversion per pair), and ``run_scenarios``
evaluates a policy on a scenario list N episodes at a time (SPCP candidates in training).
"""

from __future__ import annotations

import tempfile
from collections import deque
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, NamedTuple

import gymnasium as gym
import numpy as np
import numpy.typing as npt
from stable_baselines3.common.vec_env.base_vec_env import (
    VecEnv,
    VecEnvIndices,
    VecEnvObs,
    VecEnvStepReturn,
)

from sumo_ayss.cases import get_case
from sumo_ayss.config import EnvConfig
from sumo_ayss.envs import make_env
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.envs.pair_env import PairEnv, session_vtypes, sumo_seed_of
from sumo_ayss.envs.protocol import EpisodePhases, StepResult
from sumo_ayss.sim.network import build_parallel_network, parallel_road_edge
from sumo_ayss.sim.pair import VehiclePair
from sumo_ayss.sim.session import SumoSession
from sumo_ayss.util.errors import ActionError, ConfigError
from sumo_ayss.util.validation import check_sumo_seed

#: A batch policy: observations ``(n, obs_dim)`` -> actions ``(n,)``.
Policy = Callable[[npt.NDArray[np.float32]], npt.ArrayLike]


class EpisodeTrace(NamedTuple):
    """One episode run by :meth:`PairVecEnv.run_scenarios`.

    Attributes:
        initial_condition: where it started.
        rewards: the reward of each decision.
        infos: the info of each decision (as the single env's ``step`` returns it).
        terminated: it ended by a collision.
        truncated: it ended because its time ran out.
    """

    initial_condition: InitialCondition
    rewards: list[float]
    infos: list[dict[str, Any]]
    terminated: bool
    truncated: bool


class PairVecEnv(VecEnv):
    """N independent episodes of one case in one SUMO simulation (SB3 ``VecEnv``).

    Args:
        config: the case, VUT, ODD, reward, timing and SUMO options of every pair (as for
            the single env); ``config.network`` must be unset (the vec env builds parallel
            copies of the case's built-in road).
        n_envs: number of pairs N, >= 1.
        sumo_seed: SUMO's ``--seed``, an int in [0, 2**31 - 1]; default: the seed given to
            the first reset (through :meth:`seed`), or a random one.

    SUMO starts at the first :meth:`reset`; :meth:`close` ends it. The process's one
    simulation is owned by the vec env: a single env cannot run beside it.
    """

    def __init__(
        self,
        config: EnvConfig | None = None,
        n_envs: int = 8,
        *,
        sumo_seed: int | None = None,
    ) -> None:
        sumo_seed = check_sumo_seed(sumo_seed)
        config = config if config is not None else EnvConfig()
        if isinstance(n_envs, bool) or not isinstance(n_envs, int) or n_envs < 1:
            raise ConfigError(f"PairVecEnv needs n_envs >= 1, got {n_envs!r}")
        if config.network is not None:
            raise ConfigError(
                "PairVecEnv builds its own network of parallel copies of the built-in road; "
                f"env.network must be unset, got {config.network}"
            )
        self.config = config
        self.sumo_seed = sumo_seed
        self._fixed_sumo_seed = sumo_seed is not None
        #: The pairs' envs (``envs[i]`` drives road i); step them through the vec env only.
        self.envs: list[PairEnv] = [make_env(config) for _ in range(n_envs)]
        first = self.envs[0]
        super().__init__(n_envs, first.observation_space, first.action_space)
        self._substeps = config.steps_per_decision
        self._n_actions = int(first.action_space.n)  # type: ignore[attr-defined]
        self._session: SumoSession | None = None
        self._pairs: list[VehiclePair] = []
        self._tmp: tempfile.TemporaryDirectory[str] | None = None
        self._actions: list[Any] | None = None
        self._needs_reset = True

    # ------------------------------------------------------------------ VecEnv API

    def reset(self) -> VecEnvObs:
        """Start a fresh episode on every pair (no SUMO step); their observations.

        Uses and then forgets the seeds of :meth:`seed` and the options of
        :meth:`set_options` (``{"initial_condition": InitialCondition}`` per pair). Seeds
        given to a running vec env restart SUMO (with ``sumo_seed``, else the first seed),
        so that its own random state starts over as for a fresh vec env.
        """
        if self._session is not None and any(s is not None for s in self._seeds):
            self._close_sim()
            if not self._fixed_sumo_seed:
                self.sumo_seed = None  # _ensure_sim takes the first seed
        ics = [
            env.begin_reset(self._seeds[i], self._options[i] or None)
            for i, env in enumerate(self.envs)
        ]
        self._ensure_sim()
        obs = []
        for i, env in enumerate(self.envs):
            self._pairs[i].add()
            values, self.reset_infos[i] = env.start_episode(ics[i])  # placing inserts them
            obs.append(values)
        self._reset_seeds()
        self._reset_options()
        self._needs_reset = False
        return np.array(obs, dtype=np.float32)

    def step_async(self, actions: np.ndarray) -> None:
        """Store one action per pair for :meth:`step_wait` (nothing runs yet)."""
        if self._needs_reset:
            raise ActionError("PairVecEnv: call reset() before step()")
        self._actions = self._check_actions(actions)

    def step_wait(self) -> VecEnvStepReturn:
        """Advance every pair by one decision; auto-reset the pairs whose episode ended."""
        actions = self._actions
        if actions is None:
            raise ActionError("PairVecEnv: step_wait() without step_async()")
        self._actions = None
        obs = []
        rewards = []
        dones = []
        infos = []
        try:
            results = self._advance(actions)
            for i, (values, reward, terminated, truncated, info) in enumerate(results):
                done = terminated or truncated
                info["TimeLimit.truncated"] = truncated and not terminated
                if done:
                    info["terminal_observation"] = np.array(values, dtype=np.float32)
                    values = self._restart(i, None)
                obs.append(values)
                rewards.append(reward)
                dones.append(done)
                infos.append(info)
        except BaseException:
            self._needs_reset = True  # some pairs may have moved: their episodes are void
            raise
        # One array for all pairs: the same float32 conversion as the single env's, per row.
        return (
            np.array(obs, dtype=np.float32),
            np.array(rewards, dtype=np.float32),
            np.array(dones, dtype=bool),
            infos,
        )

    def close(self) -> None:
        """Close SUMO and the pairs; safe to call twice."""
        self._close_sim()

    def _close_sim(self) -> None:
        for env in self.envs:
            env.close()
        if self._session is not None:
            self._session.close()
        self._session = None
        self._pairs = []
        if self._tmp is not None:
            self._tmp.cleanup()
            self._tmp = None
        self._needs_reset = True

    def get_attr(self, attr_name: str, indices: VecEnvIndices = None) -> list[Any]:
        """``getattr`` of each pair's env (see SB3's ``VecEnv``)."""
        return [getattr(self.envs[i], attr_name) for i in self._get_indices(indices)]

    def set_attr(self, attr_name: str, value: Any, indices: VecEnvIndices = None) -> None:
        """``setattr`` on each pair's env (see SB3's ``VecEnv``)."""
        for i in self._get_indices(indices):
            setattr(self.envs[i], attr_name, value)

    def env_method(
        self,
        method_name: str,
        *method_args: Any,
        indices: VecEnvIndices = None,
        **method_kwargs: Any,
    ) -> list[Any]:
        """Call a method of each pair's env; ``reset`` and ``step`` refuse (they would move
        every pair of the shared simulation)."""
        return [
            getattr(self.envs[i], method_name)(*method_args, **method_kwargs)
            for i in self._get_indices(indices)
        ]

    def env_is_wrapped(
        self, wrapper_class: type[gym.Wrapper], indices: VecEnvIndices = None
    ) -> list[bool]:
        """Always False: the pairs are bare envs (wrap the vec env, e.g. in ``VecMonitor``)."""
        return [False for _ in self._get_indices(indices)]

    # ------------------------------------------------------------------ beyond the VecEnv API

    @property
    def initial_conditions(self) -> list[InitialCondition | None]:
        """Each pair's current episode start (None before the first reset)."""
        return [env.initial_condition for env in self.envs]

    def run_scenarios(
        self, policy: Policy, initial_conditions: Sequence[InitialCondition]
    ) -> list[EpisodeTrace]:
        """Run one episode from each initial condition, N at a time; their traces, in order.

        Each pair takes the next waiting initial condition whenever its episode ends; pairs
        left without one replay the first condition, unrecorded, until all are done. The
        pairs' RNGs are not used. The pairs' training episodes are abandoned: call
        :meth:`reset` before the next :meth:`step` (it raises otherwise).

        Args:
            policy: batch policy, called on all N observations at every decision.
            initial_conditions: episode starts.

        Returns:
            One :class:`EpisodeTrace` per initial condition, in the given order; each equals
            the single env's episode from that condition under the same actions.
        """
        ics = list(initial_conditions)
        if not ics:
            return []
        if self._session is None:
            self.reset()
        waiting = deque(enumerate(ics))
        running: list[int | None] = [None] * self.num_envs
        rewards: list[list[float]] = [[] for _ in ics]
        infos: list[list[dict[str, Any]]] = [[] for _ in ics]
        traces: list[EpisodeTrace | None] = [None] * len(ics)
        self._needs_reset = True  # whatever happens below, the training episodes are gone

        def start(i: int) -> tuple[float, ...]:
            j, ic = waiting.popleft() if waiting else (None, ics[0])
            running[i] = j
            return self._restart(i, ic)

        obs = [start(i) for i in range(self.num_envs)]
        left = len(ics)
        while left:
            actions = self._check_actions(policy(np.array(obs, dtype=np.float32)))
            results = self._advance(actions)
            for i, (values, reward, terminated, truncated, info) in enumerate(results):
                j = running[i]
                if j is not None:
                    rewards[j].append(reward)
                    infos[j].append(info)
                if terminated or truncated:
                    if j is not None:
                        traces[j] = EpisodeTrace(
                            ics[j], rewards[j], infos[j], terminated, truncated
                        )
                        left -= 1
                    values = start(i)
                obs[i] = values
        assert all(t is not None for t in traces)
        return traces  # type: ignore[return-value]

    # ------------------------------------------------------------------ internals

    def _ensure_sim(self) -> None:
        """Build the parallel network, start SUMO and join every pair to it (first reset)."""
        if self._session is not None:
            return
        cfg = self.config
        if self.sumo_seed is None:
            seed = self._seeds[0]
            self.sumo_seed = (
                sumo_seed_of(int(seed))
                if seed is not None
                else int(np.random.default_rng().integers(2**31 - 1))
            )
        self._tmp = tempfile.TemporaryDirectory(prefix="sumo_ayss_vec_")
        try:
            network = build_parallel_network(
                self.num_envs, get_case(cfg.case).lanes, Path(self._tmp.name)
            )
            session = SumoSession(
                network,
                session_vtypes(cfg),
                cfg.sim,
                self.sumo_seed,
                owner=f"PairVecEnv({cfg.case}, {cfg.vut}, n_envs={self.num_envs})",
            )
            session.start()
        except BaseException:
            self._tmp.cleanup()
            self._tmp = None
            raise
        self._session = session
        self._pairs = [
            VehiclePair(
                session, f"vut_{cfg.vut}", "pov", edge=parallel_road_edge(i), prefix=f"p{i}"
            )
            for i in range(self.num_envs)
        ]
        for env, pair in zip(self.envs, self._pairs, strict=True):
            env.join_shared(pair, self.sumo_seed)

    def _check_actions(self, actions: npt.ArrayLike) -> list[Any]:
        """One valid action per pair, as Python scalars, or :class:`ActionError`.

        All are checked before any pair acts (a cut-in lane change is commanded at once), so a
        bad batch changes nothing. Each pair validates its own again, in the single env's code.
        """
        flat = np.asarray(actions)
        if flat.size != self.num_envs:
            raise ActionError(
                f"PairVecEnv needs one action per pair ({self.num_envs}), got shape {flat.shape}"
            )
        values: list[Any] = flat.reshape(self.num_envs).tolist()
        n = self._n_actions
        # Python's min/max over a short list beat numpy's reductions here.
        if flat.dtype.kind not in "iu" or min(values) < 0 or max(values) >= n:
            raise ActionError(f"actions must be integers in [0, {n - 1}], got {flat!r}")
        return values

    def _advance(self, actions: Sequence[Any]) -> list[StepResult]:
        """One decision of every pair: actions, the decision's shared SUMO steps, read-back.

        A pair that collides in a step ends its decision there (read back at once, as the
        single env does); its vehicles still move in later steps of the same decision (only
        when a decision spans several SUMO steps), unobserved, until its reset.
        """
        session = self._session
        assert session is not None
        envs: Sequence[EpisodePhases] = self.envs  # the phases only (envs/protocol.py)
        pairs = self._pairs
        for env, action in zip(envs, actions, strict=True):
            env.begin_decision(action)
        if self._substeps == 1:  # the usual case (5 Hz decisions, 0.2 s steps), kept lean
            for env in envs:
                env.command_pov()
            session.step()
            colliding = session.colliding_ids()
            if colliding:
                return [
                    env.end_decision(pair.collided(colliding))
                    for env, pair in zip(envs, pairs, strict=True)
                ]
            return [env.end_decision(False) for env in envs]
        results: list[StepResult | None] = [None] * len(envs)
        active = list(enumerate(envs))
        for _ in range(self._substeps):
            for _i, env in active:
                env.command_pov()
            session.step()
            colliding = session.colliding_ids()
            if colliding:
                still = []
                for i, env in active:
                    if pairs[i].collided(colliding):
                        results[i] = env.end_decision(True)
                    else:
                        still.append((i, env))
                active = still
        for i, env in active:
            results[i] = env.end_decision(False)
        return results  # type: ignore[return-value]

    def _restart(self, i: int, ic: InitialCondition | None) -> tuple[float, ...]:
        """Start pair ``i``'s next episode on fresh vehicles, without a SUMO step.

        Returns the episode's first observation values.

        ``ic`` None: sampled from the pair's RNG (SB3's auto-reset, no seed).
        """
        env = self.envs[i]
        ic = env.begin_reset(None, None if ic is None else {"initial_condition": ic})
        self._pairs[i].add()  # the old vehicles go, two fresh ones wait for insertion ...
        values, self.reset_infos[i] = env.start_episode(ic)  # ... and placing inserts them
        return values
