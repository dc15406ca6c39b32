"""Adversarial-yet-safe scenarios (AYSS): Monte Carlo over an SPCP's observation space.

Paper Section IV-C and V: scenarios of ``d = 1`` step start from observations drawn by Monte
Carlo; the SPCP's action on each is read and its aggressiveness measured. Only
safety-critical, avoidable starts are kept. Procedure of :func:`run_ayss`:

1. **Sample** ``n_samples`` observations uniformly in the box of :class:`AyssConfig`
   (``v_pov``, ``v_vut`` in [0, 30] m/s, ``h`` in [0, 5] m by default; for cut-in
   ``same_lane = 0``: the POV is in the left lane, the cut-in moment). Draws are rounded to
   float32, the dtype the policy sees, so a table row holds exactly the policy's input.
2. **Filter** (the box is sampled first, then filtered, so a wider box can be given):
   keep ``h <= max_headway_m`` (5 m: safety-critical within one step) and
   ``TTC >= min_ttc_s`` (0.2 s: avoidable), with the longitudinal TTC of
   :func:`sumo_ayss.analysis.metrics.ttc_longitudinal`: ``h / (v_vut - v_pov)`` when the VUT
   closes in, ``+inf`` otherwise, ``0`` for ``h <= 0``.
3. **Act**: one batched forward pass of the policy over the kept samples (in chunks of
   ``batch_size``).
4. Cut-in only: keep the samples whose action is the lane change (action 0; with d = 1 no
   other action is safety-critical) and whose POV rear bumper is ahead of the VUT front
   bumper (``h > 0``; overlapping lane changes are too risky to count).
5. **Indicator** (smaller = more aggressive):

   * car-following: the POV acceleration [m/s²] the action implies, from the env's own
     actuator code (:func:`sumo_ayss.sim.actuator.pov_acceleration` on the target
     :func:`sumo_ayss.envs.car_following.target_speed_mps`); < 0 brakes. This is the
     acceleration of the decision's first SUMO step (the whole decision when
     ``decision_period_s == sim.step_length_s``, the default). No SUMO is needed.
   * cut-in: Δv̄ [m/s] (:mod:`sumo_ayss.envs.cut_in`): the 1-step scenario is run in SUMO
     with the env itself, ``reset(options={"initial_condition": ...})`` then
     ``step(LANE_CHANGE)``, and ``info["delta_v_bar_mps"]`` is read **after the step**:
     at the sampled state the POV has no lateral speed, so Δv̄ there does not depend on the
     action; one step later the lateral motion the lane change started (3.2 m/s by default,
     slower near standstill, as SUMO moves it) is part of Δv̄. Δv̄ at the sampled state is
     kept too (``delta_v_bar_before_mps``), and the headway after the step (``h_after_m``).

The output table follows :data:`sumo_ayss.run_folder.AYSS_SCHEMA`, one row per kept
sample in draw order; a seed gives the same table every time.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
from tqdm import tqdm

from sumo_ayss.analysis.metrics import ttc_longitudinal
from sumo_ayss.cases import CAR_FOLLOWING, CUT_IN, get_case
from sumo_ayss.config import ActuatorConfig, AyssConfig
from sumo_ayss.envs.car_following import target_speed_mps as cf_target_speed_mps
from sumo_ayss.envs.cut_in import LANE_CHANGE, CutInEnv
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.envs.pair_env import PairEnv
from sumo_ayss.records.table import Table
from sumo_ayss.run_folder import AYSS_SCHEMA
from sumo_ayss.scenarios.outcome import MeanInterval
from sumo_ayss.scenarios.rollout import Policy
from sumo_ayss.sim.actuator import pov_acceleration
from sumo_ayss.util.errors import ActionError, SimulationError

#: Aggressiveness indicator of car-following: POV acceleration [m/s²], < 0 brakes.
INDICATOR_ACCEL = CAR_FOLLOWING.indicator_column
#: Aggressiveness indicator of cut-in: Δv̄ [m/s], < 0 closes in.
INDICATOR_DELTA_V_BAR = CUT_IN.indicator_column

__all__ = [
    "INDICATOR_ACCEL",
    "INDICATOR_DELTA_V_BAR",
    "AyssResult",
    "CutInStepResult",
    "ayss_rows_table",
    "car_following_indicator",
    "car_following_rows",
    "cut_in_mask",
    "cut_in_rows",
    "policy_actions",
    "run_ayss",
    "safety_critical_mask",
    "sample_observations",
    "simulate_cut_ins",
    "ttc_s",
]

#: Reset must reproduce a sample to this tolerance [m, m/s] (float32 observation).
_RESET_TOL = 1e-3

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]
BoolArray = npt.NDArray[np.bool_]


# --------------------------------------------------------------------------- sampling, filters


def sample_observations(config: AyssConfig, case: str) -> npt.NDArray[np.float32]:
    """``n_samples`` observations drawn uniformly in the config's box.

    Columns: the case's observation (:attr:`~sumo_ayss.cases.Case.observation`),
    ``(v_pov, v_vut, h)`` drawn, any further column held at the case's
    :attr:`~sumo_ayss.cases.Case.ayss_fixed_obs` (cut-in: ``same_lane = 0``). One generator
    seeded with ``config.seed`` draws ``v_pov``, then ``v_vut``, then ``h`` (each a block of
    ``n_samples``): the same (seed, n_samples) give the same draws.

    Returns:
        float32 array, shape ``(n_samples, len(observation))``.

    Raises:
        ConfigError: If ``case`` is not a registered case.
    """
    fixed = get_case(case).ayss_fixed_obs
    rng = np.random.default_rng(config.seed)
    n = config.n_samples
    cols = [rng.uniform(*config.v_pov_mps, n), rng.uniform(*config.v_vut_mps, n)]
    cols.append(rng.uniform(*config.h_m, n))
    cols += [np.full(n, value) for value in fixed]
    return np.stack(cols, axis=1).astype(np.float32)


def ttc_s(v_pov_mps: npt.ArrayLike, v_vut_mps: npt.ArrayLike, h_m: npt.ArrayLike) -> FloatArray:
    """Longitudinal TTC [s] of the VUT behind the POV: h / (v_vut - v_pov) when closing.

    ``+inf`` when the gap does not close, ``0`` when ``h <= 0`` (see
    :func:`sumo_ayss.analysis.metrics.time_to_collision`).
    """
    return np.asarray(ttc_longitudinal(h_m, v_pov_mps, v_vut_mps), dtype=np.float64)


def safety_critical_mask(
    h_m: npt.ArrayLike, ttc: npt.ArrayLike, max_headway_m: float = 5.0, min_ttc_s: float = 0.2
) -> BoolArray:
    """Safety-critical and avoidable: ``h <= max_headway_m`` and ``TTC >= min_ttc_s``."""
    h, t = np.asarray(h_m, dtype=float), np.asarray(ttc, dtype=float)
    return np.asarray((h <= max_headway_m) & (t >= min_ttc_s), dtype=bool)


def cut_in_mask(h_m: npt.ArrayLike, actions: npt.ArrayLike) -> BoolArray:
    """Cut-in AYSS: the action is the lane change and the POV rear is ahead (``h > 0``)."""
    h, a = np.asarray(h_m, dtype=float), np.asarray(actions)
    return np.asarray((a == LANE_CHANGE) & (h > 0.0), dtype=bool)


def policy_actions(
    policy: Policy, obs: npt.NDArray[np.float32], n_actions: int, batch_size: int = 65_536
) -> IntArray:
    """The policy's actions on ``obs`` in batches, checked against the action space.

    Raises:
        ActionError: If the policy returns the wrong shape, non-integers, or actions
            outside ``[0, n_actions)``.
    """
    parts = []
    for start in range(0, len(obs), batch_size):
        chunk = obs[start : start + batch_size]
        out = np.asarray(policy(chunk))
        if out.shape != (len(chunk),):
            raise ActionError(f"policy returned shape {out.shape}, expected ({len(chunk)},)")
        if out.dtype.kind not in "iu":
            raise ActionError(f"policy returned dtype {out.dtype}, expected integers")
        parts.append(out.astype(np.int64))
    actions = np.concatenate(parts) if parts else np.zeros(0, dtype=np.int64)
    bad = np.flatnonzero((actions < 0) | (actions >= n_actions))
    if bad.size:
        raise ActionError(f"policy returned action {actions[bad[0]]}, outside [0, {n_actions})")
    return actions


# --------------------------------------------------------------------------- indicators


def car_following_indicator(
    v_pov_mps: npt.ArrayLike, actions: npt.ArrayLike, actuator: ActuatorConfig
) -> tuple[FloatArray, FloatArray]:
    """Target speeds [m/s] and POV accelerations [m/s²] of car-following actions.

    Through the env's own code: :func:`~sumo_ayss.envs.car_following.target_speed_mps`
    (``0.5·k·v_pov``) and :func:`~sumo_ayss.sim.actuator.pov_acceleration` (clipped
    proportional law). Acceleration < 0 brakes.

    Returns:
        ``(target_speed_mps, accel_mps2)``, each shaped like the inputs' broadcast (1-D).
    """
    v, a = np.broadcast_arrays(np.asarray(v_pov_mps, dtype=float), np.asarray(actions))
    targets = np.empty(v.shape, dtype=np.float64)
    accels = np.empty(v.shape, dtype=np.float64)
    for i, (vi, ai) in enumerate(zip(v.tolist(), a.tolist(), strict=True)):
        targets[i] = cf_target_speed_mps(int(ai), vi)
        accels[i] = pov_acceleration(vi, targets[i], actuator)
    return targets, accels


@dataclass(frozen=True)
class CutInStepResult:
    """1-step cut-in scenarios run in SUMO, one entry per start state.

    Attributes:
        delta_v_bar_mps: Δv̄ after the step [m/s], < 0 closing in.
        delta_v_bar_before_mps: Δv̄ at the start state [m/s] (no lateral speed yet).
        h_after_m: Headway after the step [m].
        target_speed_mps: The POV's target speed during the step [m/s] (its start speed).
        wall_s: Wall-clock time of the loop [s].
    """

    delta_v_bar_mps: FloatArray
    delta_v_bar_before_mps: FloatArray
    h_after_m: FloatArray
    target_speed_mps: FloatArray
    wall_s: float


def simulate_cut_ins(
    env: CutInEnv,
    v_pov_mps: npt.ArrayLike,
    v_vut_mps: npt.ArrayLike,
    h_m: npt.ArrayLike,
    *,
    progress: bool = False,
) -> CutInStepResult:
    """Run ``reset(initial_condition)`` + ``step(LANE_CHANGE)`` for each start state.

    Args:
        env: A cut-in env (SUMO starts at the first reset; the env's RNG is not consumed).
        v_pov_mps, v_vut_mps, h_m: Start states, 1-D, same length [m/s, m/s, m].
        progress: Show a tqdm progress bar.

    Raises:
        SimulationError: If SUMO does not reproduce a start state, or the lane change does
            not start.
    """
    starts = np.stack(np.broadcast_arrays(v_pov_mps, v_vut_mps, h_m), axis=1).astype(float)
    n = len(starts)
    out = {k: np.empty(n) for k in ("after", "before", "h_after", "target")}
    t0 = time.perf_counter()
    bar = tqdm(
        starts.tolist(), desc="ayss (SUMO)", unit="sample", disable=not progress, leave=False
    )
    for i, (vp, vv, h) in enumerate(bar):
        obs, info0 = env.reset(options={"initial_condition": InitialCondition(vp, vv, h)})
        if np.max(np.abs(obs[:3] - np.array((vp, vv, h)))) > _RESET_TOL:
            raise SimulationError(f"reset to {(vp, vv, h)} gave observation {obs.tolist()}")
        _, _, _, _, info = env.step(LANE_CHANGE)
        if not info["lane_change_started"]:
            raise SimulationError(f"the lane change did not start from {(vp, vv, h)}")
        out["after"][i] = info["delta_v_bar_mps"]
        out["before"][i] = info0["delta_v_bar_mps"]
        out["h_after"][i] = info["headway_m"]
        out["target"][i] = info["target_speed_mps"]
    wall = time.perf_counter() - t0
    return CutInStepResult(out["after"], out["before"], out["h_after"], out["target"], wall)


# --------------------------------------------------------------------------- the stage


@dataclass(frozen=True)
class AyssResult:
    """What :func:`run_ayss` returns.

    Attributes:
        table: One row per kept sample (:data:`AYSS_SCHEMA`).
        case: The case name.
        indicator_name: The case's :attr:`~sumo_ayss.cases.Case.indicator_column`
            (:data:`INDICATOR_ACCEL`, :data:`INDICATOR_DELTA_V_BAR`).
        config: The Monte Carlo settings used.
        counts: Samples left after each filter: ``n_samples``, ``n_headway`` (h <= max),
            ``n_safety_critical`` (and TTC >= min), cut-in: ``n_lane_change`` (and
            action 0), ``n_kept``; ``action_counts``: actions on the safety-critical
            samples (action index as text -> count).
        wall_s: Wall-clock time of the whole stage [s].
        sim_wall_s: Of which in SUMO [s] (0 in car-following).
    """

    table: Table
    case: str
    indicator_name: str
    config: AyssConfig
    counts: dict[str, Any]
    wall_s: float
    sim_wall_s: float

    def summary(self) -> dict[str, Any]:
        """JSON-ready summary: counts, throughput, config, mean indicator with its 95 % CI."""
        ind = MeanInterval.of(self.table["indicator"])
        return {
            "case": self.case,
            "indicator_name": self.indicator_name,
            "config": self.config.to_dict(),
            "counts": self.counts,
            "indicator_mean": dataclasses.asdict(ind),
            "wall_s": round(self.wall_s, 3),
            "sim_wall_s": round(self.sim_wall_s, 3),
            "samples_per_s": self.config.n_samples / self.wall_s if self.wall_s > 0 else None,
            "kept_per_s": len(self.table) / self.wall_s if self.wall_s > 0 else None,
        }


def run_ayss(
    env: PairEnv,
    policy: Policy,
    config: AyssConfig | None = None,
    *,
    progress: bool = False,
) -> AyssResult:
    """Monte Carlo AYSS of ``policy`` in ``env``'s case (see the module docstring).

    Args:
        env: The case's env. Car-following uses only its configuration (actuator); cut-in
            runs the 1-step scenarios in it (SUMO starts at the first reset if needed).
        policy: ``obs (N, d) float32 -> actions (N,)`` integer; called in batches.
        config: Monte Carlo settings; default :class:`AyssConfig()`.
        progress: Show a tqdm progress bar over the SUMO runs.

    Returns:
        The :class:`AyssResult`; identical tables for identical seeds.
    """
    cfg = config if config is not None else AyssConfig()
    base = env.unwrapped
    assert isinstance(base, PairEnv)
    case = get_case(base.config.case)
    t0 = time.perf_counter()
    obs = sample_observations(cfg, case.name)
    v_pov, v_vut, h = (obs[:, j].astype(np.float64) for j in range(3))
    ttc = ttc_s(v_pov, v_vut, h)
    in_h = h <= cfg.max_headway_m
    critical = np.flatnonzero(safety_critical_mask(h, ttc, cfg.max_headway_m, cfg.min_ttc_s))
    n_actions = int(base.action_space.n)  # type: ignore[attr-defined]
    actions = policy_actions(policy, obs[critical], n_actions, cfg.batch_size)
    counts: dict[str, Any] = {
        "n_samples": cfg.n_samples,
        "n_headway": int(in_h.sum()),
        "n_safety_critical": int(critical.size),
        "action_counts": _action_counts(actions),
    }
    build: Callable[..., tuple[Table, float]] = case.ayss_row_builder()
    table, sim_wall = build(base, obs, ttc, critical, actions, counts, progress)
    counts["n_kept"] = len(table)
    wall = time.perf_counter() - t0
    return AyssResult(table, case.name, case.indicator_column, cfg, counts, wall, sim_wall)


def _action_counts(actions: IntArray) -> dict[str, int]:
    values, counts = np.unique(actions, return_counts=True)
    return {str(int(v)): int(c) for v, c in zip(values, counts, strict=True)}


def ayss_rows_table(
    sample: IntArray,
    obs: npt.NDArray[np.float32],
    actions: IntArray,
    target: FloatArray,
    ttc: FloatArray,
    name: str,
    indicator: FloatArray,
    h_after: FloatArray,
    dvb_before: FloatArray,
) -> Table:
    """The ``ayss.csv`` table of kept samples (indices ``sample`` into the draws; ``obs``,
    ``actions``, ... one entry per kept sample); ``same_lane`` is the observation's 4th
    column in cut-in, else 1."""
    n = len(sample)
    same_lane = obs[:, 3].astype(np.int64) if obs.shape[1] == 4 else np.ones(n, dtype=np.int64)
    return Table(
        AYSS_SCHEMA,
        {
            "sample": sample,
            "v_pov_mps": obs[:, 0].astype(np.float64),
            "v_vut_mps": obs[:, 1].astype(np.float64),
            "h_m": obs[:, 2].astype(np.float64),
            "same_lane": same_lane,
            "action": actions,
            "target_speed_mps": target,
            "ttc_s": ttc,
            "indicator_name": np.full(n, name),
            "indicator": indicator,
            "h_after_m": h_after,
            "delta_v_bar_before_mps": dvb_before,
        },
    )


def car_following_rows(
    env: PairEnv,
    obs: npt.NDArray[np.float32],
    ttc: FloatArray,
    critical: IntArray,
    actions: IntArray,
    counts: dict[str, Any],
    progress: bool,
) -> tuple[Table, float]:
    """The car-following AYSS rows (the case's :attr:`~sumo_ayss.cases.Case.ayss_rows`).

    Args:
        env: The case's env (only its actuator configuration is used).
        obs: All Monte Carlo draws, shape ``(n_samples, d)``.
        ttc: TTC of every draw [s].
        critical: Indices of the safety-critical draws.
        actions: The policy's actions on ``obs[critical]``.
        counts: The stage's filter counts; a builder may add its own.
        progress: Show a progress bar (where the builder runs SUMO).

    Returns:
        ``(table, seconds spent in SUMO)``.
    """
    kept_obs = obs[critical]
    target, accel = car_following_indicator(
        kept_obs[:, 0].astype(np.float64), actions, env.config.actuator
    )
    nan = np.full(len(critical), np.nan)
    table = ayss_rows_table(
        critical, kept_obs, actions, target, ttc[critical], INDICATOR_ACCEL, accel, nan, nan
    )
    return table, 0.0


def cut_in_rows(
    env: PairEnv,
    obs: npt.NDArray[np.float32],
    ttc: FloatArray,
    critical: IntArray,
    actions: IntArray,
    counts: dict[str, Any],
    progress: bool,
) -> tuple[Table, float]:
    """The cut-in AYSS rows: lane changes with the POV ahead, run one step in SUMO
    (arguments as :func:`car_following_rows`; adds ``counts["n_lane_change"]``)."""
    assert isinstance(env, CutInEnv)
    counts["n_lane_change"] = int(np.count_nonzero(actions == LANE_CHANGE))
    keep = cut_in_mask(obs[critical, 2], actions)
    idx = critical[keep]
    kept_obs = obs[idx]
    sim = simulate_cut_ins(
        env,
        kept_obs[:, 0].astype(np.float64),
        kept_obs[:, 1].astype(np.float64),
        kept_obs[:, 2].astype(np.float64),
        progress=progress,
    )
    table = ayss_rows_table(
        idx,
        kept_obs,
        actions[keep],
        sim.target_speed_mps,
        ttc[idx],
        INDICATOR_DELTA_V_BAR,
        sim.delta_v_bar_mps,
        sim.h_after_m,
        sim.delta_v_bar_before_mps,
    )
    return table, sim.wall_s
