"""Was a crash preventable? Replay it with a reference driver in the VUT's place.

For every episode that ended in a collision, the same initial condition is driven again with
a reference driver (:mod:`sumo_ayss.vuts.reference`; default ``cc_driver``, R157's
competent and careful human) in the VUT's body, while the POV replays the *actions it took*
in the original episode, open loop: it no longer reacts to what the vehicle behind it does.
This is the counterfactual of Waymo's NIEON comparisons and of the JAMA / JRC replays
(`../shared/research/reference-drivers.md` §2): the other vehicle's recorded behaviour, a
reference responder.

* The reference avoids contact over the whole episode: the VUT's crash was
  **preventable** (1.0).
* The reference collides too: **unpreventable** (0.0).
* No crash: nothing to label (NaN). A table written before the labels: NaN throughout
  ("not labelled").

**Why actions reproduce the POV's trajectory.** The POV's law (our clipped actuator, or
highway-env's ControlledVehicle) moves the POV from its own state and its action only:
target speeds in car-following are a share of the POV's own speed, in cut-in absolute
speeds and one lane change, executed by force (SUMO's checks off). So the same actions from
the same state give the same POV positions whatever the vehicle behind does, up to the
original crash (``tests/scenarios/test_preventability.py`` checks it step by step). After
the original crash, where no action was recorded, the POV keeps its last action to the end
of the episode (``env.episode_s``): the reference must survive what the POV was doing, not
only the instant the VUT crashed.

The replays run in an env of their own (:func:`reference_config`), after the original
episodes, so that they cannot perturb the original rollouts' SUMO state (a vehicle added in
between would shift SUMO's per-vehicle random streams of stochastic VUTs).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from sumo_ayss.config import EnvConfig
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.envs.pair_env import PairEnv
from sumo_ayss.envs.reference import reference_config
from sumo_ayss.util.errors import ConfigError
from sumo_ayss.vuts.reference_types import DEFAULT_REFERENCE

__all__ = [
    "DEFAULT_REFERENCE",
    "LABEL_PREVENTABLE",
    "LABEL_UNPREVENTABLE",
    "counterfactual_collides",
    "label_crashes",
    "reference_config",
]

#: Label values of the ``crash_preventable`` column (NaN: no crash, or not labelled).
LABEL_PREVENTABLE = 1.0
LABEL_UNPREVENTABLE = 0.0


def counterfactual_collides(env: PairEnv, ic: InitialCondition, actions: Sequence[int]) -> bool:
    """Drive ``env`` (a reference env) from ``ic`` with the POV's ``actions`` replayed, the
    last one held to the episode's end; whether it ends in a collision."""
    if not actions:
        raise ConfigError("counterfactual: no recorded actions to replay")
    base = env.unwrapped
    assert isinstance(base, PairEnv)
    base.reset(options={"initial_condition": ic})
    k = 0
    while True:
        action = actions[min(k, len(actions) - 1)]
        _obs, _r, terminated, truncated, info = base.step(action)
        k += 1
        if terminated or truncated:
            # A case with several POVs says whether the VUT touched any of them.
            return bool(info.get("vut_contact", info["collision"]))


def label_crashes(
    config: EnvConfig,
    scenarios: Sequence[InitialCondition],
    collided: Sequence[bool],
    actions: Sequence[Sequence[int]],
    *,
    sumo_seed: int,
    reference: str = DEFAULT_REFERENCE,
    params: Mapping[str, Any] | None = None,
) -> np.ndarray:
    """The ``crash_preventable`` value of each episode (same order as ``scenarios``).

    Args:
        config: The original episodes' env config (the VUT's).
        scenarios: Each episode's initial condition.
        collided: Whether each episode ended in a collision.
        actions: Each episode's recorded POV actions.
        sumo_seed: SUMO's seed of the replays (the original episodes').
        reference: A reference driver's name
            (:data:`~sumo_ayss.vuts.reference_types.REFERENCE_VUTS`).
        params: Parameters replacing the reference controller's (None: its defaults).

    Returns:
        float64 array: 1.0 preventable, 0.0 unpreventable, NaN for an episode without a
        collision. No SUMO is started when nothing crashed.
    """
    from sumo_ayss.envs import make_env

    if not len(scenarios) == len(collided) == len(actions):
        raise ConfigError(
            f"label_crashes: {len(scenarios)} scenarios, {len(collided)} collision flags, "
            f"{len(actions)} action sequences"
        )
    labels = np.full(len(scenarios), math.nan)
    crashed = [i for i, c in enumerate(collided) if c]
    if not crashed:
        return labels
    env = make_env(reference_config(config, reference, params=params), sumo_seed=sumo_seed)
    try:
        for i in crashed:
            hit = counterfactual_collides(env, scenarios[i], actions[i])
            labels[i] = LABEL_UNPREVENTABLE if hit else LABEL_PREVENTABLE
    finally:
        env.close()
    return labels
