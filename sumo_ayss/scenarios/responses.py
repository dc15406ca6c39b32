"""One-step responses of a VUT, measured in SUMO, at given states.

For each state ``(v_pov, v_vut, h)`` a fresh VUT-POV pair is placed exactly at that state
by the case's own env (:class:`~sumo_ayss.envs.vec_env.PairVecEnv`, many pairs in one SUMO
simulation), the POV acts for ``decisions`` decisions and the VUT's acceleration is read
back: the VUT's speed change over those SUMO steps divided by their duration [m/s²]
(SUMO's ``vehicle.getAcceleration`` of each step, averaged; for one step it *is* the speed
change over the step length). Because it is the env's own code, placement, SUMO options,
the cut-in's lane-change motion and user-controller VUTs (driven through
:class:`~sumo_ayss.vuts.controllers.ControlledVut`, as in training) are exactly those of the
training and evaluation episodes.

What the POV does while the response is measured (``RESPONSE_ACTION`` of the case's env
class, :class:`~sumo_ayss.envs.pair_env.PairEnv`):

* car-following: it holds its speed (action 2: target = its own speed, zero acceleration);
* cut-in: it starts a lane change into the VUT's lane in the first decision (action
  :data:`~sumo_ayss.envs.cut_in.LANE_CHANGE`) and keeps its speed; later decisions repeat the
  (then ignored) lane-change action, so the lateral motion runs on by itself.

A SUMO car-following model computes the speed of a step from the state before it, so the
first step's response does not depend on what the POV does in that step. In cut-in the POV
is still entirely in its own lane at the start, so a SUMO VUT drives freely in the first
step (it first reacts in the second step of a 1 s lane change, when the POV's body reaches
into its lane): use ``decisions >= 2`` to see the reaction to the cut-in.

Each decision is run as SUMO steps of ``sim.step_length_s``; ``decisions`` decisions of the
config's ``decision_period_s`` are ``decisions · steps_per_decision`` SUMO steps. A pair
that collides ends its measurement at the collision step (its response is the mean over
the steps until then; ``collided`` marks it).

VUT models that draw random numbers (``sigma``, ``speedDev``, EIDM's noise) give noisy
responses: such a VUT compared with itself differs where the noise exceeds the threshold.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from sumo_ayss.cases import get_case
from sumo_ayss.config import EnvConfig
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.envs.vec_env import PairVecEnv
from sumo_ayss.util.errors import ConfigError

__all__ = ["DEFAULT_N_PAIRS", "VutResponses", "measure_responses"]

#: Pairs in the one SUMO simulation: 256 roads cost ~0.2 s to build and start, and keep the
#: per-state cost near its floor (~0.1 ms per state and VUT on one core).
DEFAULT_N_PAIRS = 256


@dataclass(frozen=True)
class VutResponses:
    """A VUT's measured responses, one per state, in the order of the states.

    Attributes:
        vut: VUT name.
        accel_mps2: Mean acceleration of the VUT over the measured steps [m/s²].
        collided: The pair collided within the measured steps.
        steps: SUMO steps measured per state (before a collision).
        step_length_s: SUMO step length [s].
    """

    vut: str
    accel_mps2: npt.NDArray[np.float64]
    collided: npt.NDArray[np.bool_]
    steps: int
    step_length_s: float


def measure_responses(
    env: EnvConfig,
    vut: str,
    v_pov_mps: npt.ArrayLike,
    v_vut_mps: npt.ArrayLike,
    h_m: npt.ArrayLike,
    *,
    decisions: int = 1,
    n_pairs: int = DEFAULT_N_PAIRS,
    sumo_seed: int = 0,
    progress: Callable[[int, int], None] | None = None,
) -> VutResponses:
    """Measure ``vut``'s response at every state, in SUMO (a simulation of its own).

    Args:
        env: The experiment's env config (case, VUT catalog, SUMO options, POV). Its
            ``network`` is ignored: the pairs drive parallel copies of the built-in road.
        vut: VUT name in ``env.vuts``.
        v_pov_mps, v_vut_mps, h_m: The states (1-D, same length): speeds [m/s] and the
            headway, POV rear minus VUT front [m].
        decisions: Decisions measured per state, >= 1 (1: the paper's d = 1).
        n_pairs: Pairs simulated side by side, >= 1.
        sumo_seed: SUMO's ``--seed`` (matters only for stochastic VUT models).
        progress: Called as ``progress(done, total)`` after each chunk of states.

    Returns:
        The :class:`VutResponses`.

    Raises:
        ConfigError: On an unknown VUT, bad ``decisions``/``n_pairs`` or state arrays.
        SimulationError: If SUMO fails (or a libsumo simulation already runs in this
            process).
    """
    if vut not in env.vuts:
        raise ConfigError(f"vut must be one of {sorted(env.vuts)}, got {vut!r}")
    for name, value in (("decisions", decisions), ("n_pairs", n_pairs)):
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise ConfigError(f"{name} must be an integer >= 1, got {value!r}")
    vp, vv, hh = (np.asarray(x, dtype=float).ravel() for x in (v_pov_mps, v_vut_mps, h_m))
    if not (vp.shape == vv.shape == hh.shape):
        raise ConfigError(
            f"v_pov_mps, v_vut_mps and h_m must have the same length, got "
            f"{len(vp)}, {len(vv)}, {len(hh)}"
        )
    dt = env.sim.step_length_s
    steps = decisions * env.steps_per_decision
    # One SUMO step per decision, and an episode of exactly the measured steps: each trace's
    # infos then hold the VUT's acceleration of every measured step.
    cfg = dataclasses.replace(
        env, vut=vut, network=None, decision_period_s=dt, episode_s=steps * dt
    )
    env_class = get_case(cfg.case).env_class()
    if env_class.RESPONSE_HOLDS_SPEED and cfg.actuator.mode != "clipped":
        # The POV holds its speed: highway-env's law with target = v gives a = 0, exactly
        # the clipped law's constant speed, but costs Python sub-steps and a moveToXY per
        # step (about 10x slower). The VUT's sub-steps (``substeps``) are kept.
        cfg = dataclasses.replace(cfg, actuator=dataclasses.replace(cfg.actuator, mode="clipped"))
    action = int(env_class.RESPONSE_ACTION)
    n = len(hh)
    accel = np.full(n, math.nan)
    collided = np.zeros(n, dtype=bool)
    if n == 0:
        return VutResponses(vut, accel, collided, steps, dt)

    def policy(obs: npt.NDArray[np.float32]) -> npt.NDArray[np.int64]:
        return np.full(len(obs), action, dtype=np.int64)

    vec = PairVecEnv(cfg, n_envs=min(n_pairs, n), sumo_seed=sumo_seed)
    try:
        vec.reset()
        chunk = max(4096, 16 * vec.num_envs)  # traces of a chunk are held in memory
        for start in range(0, n, chunk):
            stop = min(n, start + chunk)
            ics = [
                InitialCondition(float(vp[i]), float(vv[i]), float(hh[i]))
                for i in range(start, stop)
            ]
            for j, trace in enumerate(vec.run_scenarios(policy, ics), start):
                acc = [info["vut_accel_mps2"] for info in trace.infos]
                accel[j] = sum(acc) / len(acc)
                collided[j] = trace.terminated
            if progress is not None:
                progress(stop, n)
    finally:
        vec.close()
    return VutResponses(vut, accel, collided, steps, dt)
