"""Shared machinery of the VUT-POV Gymnasium envs: SUMO ownership, reset, stepping.

A case (car-following, cut-in) subclasses :class:`PairEnv` and supplies its observation,
action decoding and reward. Timing: the policy acts every ``decision_period_s`` (0.2 s,
5 Hz); an episode lasts ``episode_s`` (5 s, 25 decisions) and ends *truncated* after the
last decision, or *terminated* at a collision.

What moves the two vehicles over each SUMO step is their laws (:mod:`sumo_ayss.laws`): the
POV's (our clipped actuator, or highway-env's ControlledVehicle in paper-fidelity mode) and
the VUT's (SUMO's own model, a user controller, or highway-env's IDM), built once from the
configuration and called by the episode phases below.
"""

from __future__ import annotations

import dataclasses
import math
import weakref
from abc import abstractmethod
from typing import Any, ClassVar, NamedTuple, SupportsFloat, SupportsInt

import gymnasium as gym
import numpy as np
import numpy.typing as npt
from gymnasium import spaces

from sumo_ayss.config import EnvConfig
from sumo_ayss.envs.follower import (
    check_follower_start,
    follower_info,
    follower_wanted,
    place_follower,
)
from sumo_ayss.envs.odd import InitialCondition, sample_initial_condition, start_filter
from sumo_ayss.envs.rewards import total_reward
from sumo_ayss.laws import VehicleLaws, build_laws
from sumo_ayss.sim.network import ROAD_EDGE, ROAD_LENGTH_M, network_path
from sumo_ayss.sim.pair import PairPlacement, VehiclePair
from sumo_ayss.sim.session import SumoSession
from sumo_ayss.util.errors import ActionError, ConfigError
from sumo_ayss.util.validation import check_sumo_seed
from sumo_ayss.vuts.catalog import VehicleType

#: Front-bumper position of the VUT at the start of every episode [m].
VUT_START_POS_M = 150.0
#: Finite observation bounds: speeds [m/s] and headway [m] are clipped into them.
SPEED_HIGH_MPS = 50.0
HEADWAY_LOW_M = -20.0
HEADWAY_HIGH_M = 500.0


def time_to_collision_s(gap_m: float, v_follower_mps: float, v_leader_mps: float) -> float:
    """Longitudinal TTC [s]: gap / closing speed; +inf when the gap is not closing."""
    closing = v_follower_mps - v_leader_mps
    if gap_m <= 0.0:
        return 0.0
    return gap_m / closing if closing > 0.0 else math.inf


def session_vtypes(cfg: EnvConfig) -> dict[str, VehicleType]:
    """The vehicle types a simulation of ``cfg`` loads: ``vut_<name>`` per catalog VUT, ``pov``."""
    vtypes = {f"vut_{name}": vt for name, vt in cfg.vuts.items()}
    vtypes["pov"] = cfg.pov
    if cfg.follower.enabled:
        vtypes["follower"] = cfg.follower.sumo_type
    return vtypes


#: Largest gap [m] a given initial condition may ask for (the POV must stay on the road).
IC_GAP_MAX_M = HEADWAY_HIGH_M


def sumo_seed_of(seed: int) -> int:
    """SUMO's ``--seed`` for an env reset with ``seed``: ``seed`` itself when it fits SUMO's
    range [0, 2**31 - 1] (as :class:`~sumo_ayss.envs.vec_env.PairVecEnv` does), else a hash."""
    if 0 <= seed <= 2**31 - 1:
        return seed
    state = np.random.SeedSequence(seed).generate_state(1, np.uint32)
    return int(state[0]) >> 1


class PairKinematics(NamedTuple):
    """What a step reads back from SUMO (front-bumper positions, m; speeds, m/s).

    A NamedTuple, not a dataclass: built on every step, a frozen dataclass costs far more."""

    pov_pos_m: float
    pov_speed_mps: float
    vut_pos_m: float
    vut_speed_mps: float
    headway_m: float


class PairEnv(gym.Env[npt.NDArray[np.float32], np.int64]):
    """Base env: one VUT and one POV in the process's SUMO simulation.

    Args:
        config: environment configuration; defaults to :class:`EnvConfig` of the case.
        vut: shortcut to override ``config.vut`` (a name from ``config.vuts``).
        sumo_seed: SUMO's ``--seed``, an int in [0, 2**31 - 1]; default: drawn from the
            env's RNG at the first reset.
        laws: The POV's and the VUT's laws (fresh ones: they hold an episode's state);
            default: :func:`~sumo_ayss.laws.build_laws` of the (final) config, which
            imports and builds a controller VUT's controller.
    """

    # ``metadata`` is gymnasium.Env's own, ``{"render_modes": []}``: no rendering.
    #: The registered case (:mod:`sumo_ayss.cases`) this env runs.
    CASE: ClassVar[str]
    #: The POV's action while a VUT's one-step response is measured
    #: (:mod:`sumo_ayss.scenarios.responses`).
    RESPONSE_ACTION: ClassVar[int]
    #: :attr:`RESPONSE_ACTION` only holds the POV's speed: the clipped actuator law then
    #: moves the POV exactly as highway-env's does, and faster.
    RESPONSE_HOLDS_SPEED: ClassVar[bool] = False
    #: Observation bounds (finite; values are clipped into them) and number of actions.
    OBS_LOW: ClassVar[tuple[float, ...]]
    OBS_HIGH: ClassVar[tuple[float, ...]]
    N_ACTIONS: ClassVar[int]
    #: Smallest gap [m] a given initial condition may ask for (cut-in: side by side, < 0).
    IC_GAP_MIN_M: ClassVar[float] = 0.0
    ICS_STRATEGIES: ClassVar[dict[str, tuple[int, ...]]]  # worst POV plays: scenarios/inevitable

    def __init__(
        self,
        config: EnvConfig | None = None,
        *,
        vut: str | None = None,
        sumo_seed: int | None = None,
        laws: VehicleLaws | None = None,
    ) -> None:
        super().__init__()
        sumo_seed = check_sumo_seed(sumo_seed)
        config = config if config is not None else EnvConfig(case=self.CASE)
        if config.case != self.CASE:
            raise ConfigError(f"env.case must be {self.CASE!r} for {type(self).__name__}")
        if vut is not None:
            config = dataclasses.replace(config, vut=vut)
        self._check_road(config)
        self.config = config
        self.observation_space = spaces.Box(
            low=np.array(self.OBS_LOW, dtype=np.float32),
            high=np.array(self.OBS_HIGH, dtype=np.float32),
            dtype=np.float32,
        )
        self.action_space = spaces.Discrete(self.N_ACTIONS)
        self.sumo_seed = sumo_seed
        self._fixed_sumo_seed = sumo_seed is not None
        self._session: SumoSession | None = None
        self._finalizer: weakref.finalize[..., Any] | None = None
        self._done = False  # the episode ended (terminated or truncated): step() refuses
        self._pair: VehiclePair | None = None
        # Per-step constants, looked up once (config properties compute on each access).
        self._pov_length_m = config.pov.length_m
        self._substeps = config.steps_per_decision
        self._max_decisions = config.max_decisions
        self._reward_cfg = config.reward
        self._pov_law, self._vut_law = laws if laws is not None else build_laws(config)
        self._admissible = start_filter(config)  # env.odd.exclude_inevitable: the case's check
        self._decisions = 0
        self._target = 0.0  # the POV's target speed of the current decision [m/s]
        self._shared = False  # a member of a PairVecEnv (see join_shared)
        self._k: PairKinematics | None = None
        self.initial_condition: InitialCondition | None = None

    # ------------------------------------------------------------------ case hooks

    @classmethod
    def ayss_start(cls, sample: InitialCondition) -> InitialCondition:
        """The start of an AYSS sample's scenario (a case may fix more of the state)."""
        return sample

    @abstractmethod
    def _placement(self, ic: InitialCondition) -> PairPlacement: ...

    @abstractmethod
    def _observation_values(self, k: PairKinematics) -> tuple[float, ...]:
        """The observation's entries, clipped to the observation space (plain floats)."""

    def _observation(self, k: PairKinematics) -> npt.NDArray[np.float32]:
        """The observation (float32) of the state ``k``."""
        return np.array(self._observation_values(k), dtype=np.float32)

    @abstractmethod
    def _apply_action(self, action: int, k: PairKinematics) -> float:
        """Issue lane commands if any and return the POV's target speed [m/s]."""

    @abstractmethod
    def _reward_terms(self, k: PairKinematics, collided: bool) -> tuple[float, dict[str, Any]]:
        """R_A for this step and case-specific info entries."""

    # ------------------------------------------------------------------ gym API

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[npt.NDArray[np.float32], dict[str, Any]]:
        """Start an episode.

        Args:
            seed: seeds the env's RNG (ODD sampling).
            options: ``{"initial_condition": InitialCondition}`` to start from a given state
                instead of sampling the ODD (scenario sets, Monte Carlo, replays).
        """
        if self._shared:
            raise self._step_error()
        ic = self.begin_reset(seed, options)
        pair = self._ensure_sim()
        pair.add(follower=follower_wanted(self.config, ic))
        pair.session.step()  # inserts the fresh vehicles (they do not move in this step)
        values, info = self.start_episode(ic)
        return np.array(values, dtype=np.float32), info

    def step(
        self, action: SupportsInt
    ) -> tuple[npt.NDArray[np.float32], SupportsFloat, bool, bool, dict[str, Any]]:
        """One decision (``decision_period_s``).

        Raises:
            ActionError: Before the first reset, after the episode ended (a collision or the
                last decision: call ``reset``), or for an action outside the action space.
        """
        pair = self._pair
        if pair is None or self._k is None or self._shared:
            raise self._step_error()
        if self._done:
            raise ActionError(
                "step() after the episode ended (terminated at a collision or truncated at "
                f"env.episode_s = {self.config.episode_s} s); call reset() first"
            )
        self.begin_decision(action)
        session = pair.session
        collided = False
        for _ in range(self._substeps):
            self.command_pov()
            session.step()
            if pair.collided(session.colliding_ids()):
                collided = True
                break
        values, reward, terminated, truncated, info = self.end_decision(collided)
        return np.array(values, dtype=np.float32), reward, terminated, truncated, info

    def close(self) -> None:
        """Close SUMO and the VUT's law; safe to call twice. A vec-env member leaves the
        shared SUMO running."""
        self._close_sim()
        self._vut_law.close()
        self._pair = None
        super().close()

    def _close_sim(self) -> None:
        """Close this env's own simulation (if it owns one)."""
        if self._finalizer is not None:
            self._finalizer.detach()
            self._finalizer = None
        if self._session is not None:
            self._session.close()
            self._session = None
            self._pair = None
            self._k = None

    # ------------------------------------------------------------------ episode phases
    #
    # ``reset`` and ``step`` are built from the phases below, around their SUMO steps: the
    # public protocol :class:`~sumo_ayss.envs.protocol.EpisodePhases` (order of calls and
    # units there). A :class:`~sumo_ayss.envs.vec_env.PairVecEnv` runs many envs in one
    # simulation by calling the same phases of each member around one shared SUMO step, so
    # that observation, reward, termination and the POV's actuator are this code in both.

    def begin_reset(self, seed: int | None, options: dict[str, Any] | None) -> InitialCondition:
        """Seed the RNG (``seed``) and choose the episode's initial condition.

        A ``seed`` also reseeds SUMO: an env that owns its simulation restarts it with SUMO
        seed ``sumo_seed`` (the constructor's, else :func:`sumo_seed_of` ``(seed)``), so that
        the same seed and actions give the same trajectories on a fresh or a used env, for
        stochastic VUTs too (SUMO's own random state starts over). The SUMO seed never draws
        from the env's RNG, which is for initial conditions only.
        """
        if options is not None and not isinstance(options, dict):
            raise ConfigError(f"reset options must be a dict or None, got {options!r}")
        unknown = set(options or {}) - {"initial_condition"}
        if unknown:
            raise ConfigError(
                f"reset options: unknown keys {sorted(unknown)}; allowed: ['initial_condition']"
            )
        super().reset(seed=seed)
        if seed is not None and not self._shared:
            if not self._fixed_sumo_seed:
                self.sumo_seed = sumo_seed_of(int(seed))
            self._close_sim()  # restarted by the reset's _ensure_sim, with a fresh SUMO state
        ic = (options or {}).get("initial_condition")
        if ic is None:
            ic = sample_initial_condition(self.config.odd, self.np_random, self._admissible)
        elif not isinstance(ic, InitialCondition):
            raise ConfigError(
                f"reset options['initial_condition'] must be an InitialCondition, got {ic!r}"
            )
        else:
            self._check_initial_condition(ic)
        return ic

    def _check_initial_condition(self, ic: InitialCondition) -> None:
        """Refuse a given initial condition the road and the actuator cannot realise."""
        v_max = min(SPEED_HIGH_MPS, self.config.actuator.max_speed_mps)
        checks = (
            ("pov_speed_mps", ic.pov_speed_mps, 0.0, v_max),
            ("vut_speed_mps", ic.vut_speed_mps, 0.0, SPEED_HIGH_MPS),
            ("gap_m", ic.gap_m, self.IC_GAP_MIN_M, IC_GAP_MAX_M),
        )
        for name, value, low, high in checks:
            ok = isinstance(value, int | float) and not isinstance(value, bool)
            if not ok or not math.isfinite(value) or not low <= value <= high:
                raise ConfigError(
                    f"reset options['initial_condition'].{name} must be a finite number in "
                    f"[{low:g}, {high:g}], got {value!r}"
                )
        check_follower_start(ic)

    def start_episode(self, ic: InitialCondition) -> tuple[tuple[float, ...], dict[str, Any]]:
        """Place the pair's fresh vehicles at ``ic``: the reset's observation values and info.

        The vehicles must have been added (and, for the single env, inserted by a step).
        """
        pair = self._pair
        assert pair is not None
        placement = self._placement(ic)
        pair.place(placement)
        if pair.follower is not None:
            place_follower(pair, placement, ic, self.config)
        self._vut_law.start(pair, ic.vut_speed_mps)
        self._pov_law.start(pair, ic.pov_speed_mps)
        self.initial_condition = ic
        self._done = False
        self._decisions = 0
        k = self._k = self._kinematics()
        info = {
            "headway_m": k.headway_m,
            "ttc_s": time_to_collision_s(k.headway_m, k.vut_speed_mps, k.pov_speed_mps),
            "sumo_seed": self.sumo_seed,
            "initial_condition": ic,
            **self._positions_info(k),
        }
        if pair.follower is not None:  # no acceleration yet (SUMO's is the placement's)
            info.update(follower_info(pair.follower), follower_accel_mps2=math.nan)
        return self._observation_values(k), info

    def begin_decision(self, action: SupportsInt) -> None:
        """Validate and apply ``action`` (lane commands, the POV's target speed)."""
        assert self._k is not None
        self._target = self._apply_action(self._validate_action(action), self._k)

    def command_pov(self) -> None:
        """The POV's law, then the VUT's, command the coming SUMO step."""
        pair = self._pair
        assert pair is not None
        pov = self._pov_law
        pov.command(pair, self._target)
        self._vut_law.command(pair, pov)

    def end_decision(
        self, collided: bool
    ) -> tuple[tuple[float, ...], float, bool, bool, dict[str, Any]]:
        """Read SUMO back after the decision's steps.

        Args:
            collided: the pair collided in the last SUMO step (the decision ended there).

        Returns:
            ``(observation values, reward, terminated, truncated, info)``; the values are
            plain floats, made an array by the caller (the vec env makes one for all pairs).
        """
        pair = self._pair
        assert pair is not None
        vut_law = self._vut_law
        self._pov_law.sync(pair)
        vut_law.sync(pair)
        collided = vut_law.collided(collided)
        self._decisions += 1
        k = self._k = self._kinematics()
        r_a, extra = self._reward_terms(k, collided)
        if collided:
            r_a = 0.0
        reward = total_reward(r_a, collided, self._reward_cfg)
        terminated = collided
        truncated = not terminated and self._decisions >= self._max_decisions
        self._done = terminated or truncated
        info = {
            "headway_m": k.headway_m,
            "ttc_s": time_to_collision_s(k.headway_m, k.vut_speed_mps, k.pov_speed_mps),
            "pov_accel_mps2": self._pov_law.accel_mps2(pair),
            "vut_accel_mps2": vut_law.accel_mps2(pair),
            "target_speed_mps": self._target,
            "vut_speed_mps": k.vut_speed_mps,
            "collision": collided,
            "reward_adversarial": r_a,
            "reward_collision": -1.0 if collided else 0.0,
            "sumo_seed": self.sumo_seed,
            **self._positions_info(k),
            **extra,
        }
        if pair.follower is not None:
            info.update(follower_info(pair.follower))
        return self._observation_values(k), reward, terminated, truncated, info

    @staticmethod
    def _positions_info(k: PairKinematics) -> dict[str, float]:
        """Front-bumper lane positions [m] and speeds [m/s] of both vehicles, for the
        episode's trajectory (:mod:`sumo_ayss.scenarios.trajectory`)."""
        return {
            "pov_pos_m": k.pov_pos_m,
            "vut_pos_m": k.vut_pos_m,
            "pov_speed_mps": k.pov_speed_mps,
            "vut_speed_mps": k.vut_speed_mps,
        }

    def join_shared(self, pair: VehiclePair, sumo_seed: int) -> None:
        """Become a member of a vec env: drive ``pair`` in a simulation the env does not own.

        The member's own ``reset``/``step`` then refuse to run (each would step every pair of
        the shared simulation); the vec env calls the phases above instead.
        """
        self._pair = pair
        self._session = None
        self._shared = True
        self.sumo_seed = sumo_seed

    def _step_error(self) -> ActionError:
        if self._shared:
            return ActionError(
                f"{type(self).__name__} is a member of a PairVecEnv: step and reset it "
                "through the vec env (its own step would move every pair of the shared SUMO)"
            )
        return ActionError("step() called before reset()")

    # ------------------------------------------------------------------ internals

    def _validate_action(self, action: SupportsInt) -> int:
        n = int(self.action_space.n)  # type: ignore[attr-defined]
        if isinstance(action, int | np.integer) and not isinstance(action, bool):
            a = int(action)
        elif (
            isinstance(action, np.ndarray)
            and action.shape in ((), (1,))
            and action.dtype.kind in "iu"
        ):
            a = int(action.reshape(()))  # SB3's predict() returns a 0-d or 1-element array
        else:
            raise ActionError(f"action must be an integer in [0, {n - 1}], got {action!r}")
        if not 0 <= a < n:
            raise ActionError(f"action must be an integer in [0, {n - 1}], got {action!r}")
        return a

    def _kinematics(self) -> PairKinematics:
        assert self._pair is not None
        pov_pos, v_pov, vut_pos, v_vut = self._pair.longitudinal()
        headway = pov_pos - self._pov_length_m - vut_pos
        return PairKinematics(pov_pos, v_pov, vut_pos, v_vut, headway)

    def _ensure_sim(self) -> VehiclePair:
        if self._pair is not None:
            return self._pair
        cfg = self.config
        if self.sumo_seed is None:  # never seeded: fresh entropy, not the env's RNG
            self.sumo_seed = sumo_seed_of(int(np.random.SeedSequence().entropy))  # type: ignore[arg-type]
        vtypes = self._session_vtypes()
        network = cfg.network if cfg.network is not None else network_path(cfg.case)
        session = SumoSession(
            network, vtypes, cfg.sim, self.sumo_seed, owner=f"{type(self).__name__}({cfg.vut})"
        )
        session.start()
        self._session = session
        # An env dropped without close() must not hold the process's one simulation forever.
        self._finalizer = weakref.finalize(self, session.close)
        self._pair = VehiclePair(
            session,
            vut_type=f"vut_{cfg.vut}",
            pov_type="pov",
            edge=ROAD_EDGE,
            follower_type="follower" if cfg.follower.enabled else None,
        )
        return self._pair

    def _session_vtypes(self) -> dict[str, VehicleType]:
        """The vehicle types the env's simulation loads (a case may load more)."""
        return session_vtypes(self.config)

    @staticmethod
    def _check_road(cfg: EnvConfig) -> None:
        """The POV must not reach the road's end within an episode at full speed."""
        reach = (
            VUT_START_POS_M
            + cfg.odd.gap_m[1]
            + cfg.pov.length_m
            + cfg.actuator.max_speed_mps * cfg.episode_s
        )
        if cfg.network is None and reach > ROAD_LENGTH_M - 50.0:
            raise ConfigError(
                f"env.odd.gap_m max ({cfg.odd.gap_m[1]}) with env.episode_s ({cfg.episode_s}) "
                f"lets the POV reach {reach:.0f} m, beyond the {ROAD_LENGTH_M:.0f} m road"
            )
