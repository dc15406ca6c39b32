"""Inevitable-collision states of a case's ODD: where no braking avoids contact.

An initial condition is an *inevitable-collision state* (ICS) when a VUT that brakes at
0.85 g from the first step (:class:`~sumo_ayss.vuts.reference.FullBraking`, the CC driver's
AEB level, no reaction time: better than any reference driver can do by braking) still
touches the POV under one of the POV's worst plain behaviours, each an action sequence of
the case's own action space held for the whole episode and run in the case's env (SUMO,
the POV's actuator and its limits, exactly as the episodes are driven):

* car-following: brake as hard as the actuator allows (target speed 0);
* cut-in: change lane at once, then brake as hard as the actuator allows (target 0), or
  change lane at once and hold the speed it has;
* lead-and-cut-in: the lead brakes as hard as it can, or the cut-in POV cuts in at once
  and brakes or holds its speed, the other POV holding its speed (only the primary's
  contact counts).

A POV behind the VUT that drives into its rear is excluded (only contacts where the POV's
centre was ahead of the VUT's at the decision before count): the VUT cannot be asked to
avoid being rammed by braking. The share of ICS in the ODD is a property of the scenario
set: crashes drawn there are nobody's failure. The paper's AYSS definition already keeps
only avoidable states (TTC >= 0.2 s); this share tells how much of the ODD the episodes
themselves start in.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

from sumo_ayss.analysis.stats import wilson_interval
from sumo_ayss.cases import get_case
from sumo_ayss.config import EnvConfig
from sumo_ayss.envs.odd import InitialCondition, scenario_set
from sumo_ayss.envs.pair_env import PairEnv
from sumo_ayss.vuts.catalog import ControllerSpec, VehicleType

__all__ = ["FULL_BRAKING", "IcsShare", "ics_share", "inevitable_collision", "pov_strategies"]

#: The VUT of the ICS check: full braking from the first step, in a passenger body.
FULL_BRAKING = VehicleType(
    model="IDM",
    params={"length": 5.0, "width": 1.8, "minGap": 0.0},
    description="brakes at 0.85 g from the first step",
    controller=ControllerSpec(
        target="full_braking",
        params={},
        max_accel_mps2=3.0,
        max_decel_mps2=0.85 * 9.81,
        max_speed_mps=40.0,
    ),
)


def pov_strategies(case: str) -> dict[str, tuple[int, ...]]:
    """The POV's worst plain behaviours of ``case``: name -> the first actions (the last
    is held); the case's env's :attr:`~sumo_ayss.envs.pair_env.PairEnv.ICS_STRATEGIES`."""
    env_class: type[PairEnv] = get_case(case).env_class()
    return dict(env_class.ICS_STRATEGIES)


def _collides(env: PairEnv, ic: InitialCondition, actions: Sequence[int]) -> bool:
    """Contact while the POV's centre was ahead of the VUT's at the decision before (a POV
    from behind driving into the braking VUT is a ram, not a state the VUT must avoid)."""
    env.reset(options={"initial_condition": ic})
    half_lengths = 0.5 * (env.config.pov.length_m + env.config.vut_type.length_m)
    k, before = 0, ic.gap_m
    while True:
        _o, _r, term, trunc, info = env.step(actions[min(k, len(actions) - 1)])
        k += 1
        if term:  # a case with several POVs: the primary's contact only
            return bool(info["collision"]) and before > -half_lengths
        if trunc:
            return False
        before = float(info["headway_m"])


def inevitable_collision(
    env: PairEnv, ic: InitialCondition, strategies: dict[str, tuple[int, ...]]
) -> bool:
    """Whether ``ic`` is an ICS in ``env`` (an env whose VUT brakes fully)."""
    return any(_collides(env, ic, actions) for actions in strategies.values())


@dataclass(frozen=True)
class IcsShare:
    """The share of a case's ODD draws that are inevitable-collision states.

    Attributes:
        case: The case.
        n: Initial conditions drawn (the outcome scenario set's seed and ODD).
        ics: Of those, inevitable-collision states.
        lo: Lower end of the Wilson interval of ``ics / n``.
        hi: Upper end.
        strategies: The POV behaviours tried.
    """

    case: str
    n: int
    ics: int
    lo: float
    hi: float
    strategies: tuple[str, ...]

    @property
    def share(self) -> float:
        return self.ics / self.n if self.n else math.nan


def ics_flags(
    config: EnvConfig, scenarios: Sequence[InitialCondition], *, sumo_seed: int = 0
) -> list[bool]:
    """Whether each of ``scenarios`` is an ICS of ``config``'s case (one env, in order)."""
    from sumo_ayss.envs import make_env

    cfg = dataclasses.replace(
        config, vuts={**config.vuts, "full_braking": FULL_BRAKING}, vut="full_braking"
    )
    strategies = pov_strategies(cfg.case)
    env = make_env(cfg, sumo_seed=sumo_seed)
    try:
        return [inevitable_collision(env, ic, strategies) for ic in scenarios]
    finally:
        env.close()


def ics_share(config: EnvConfig, n: int, seed: int, *, sumo_seed: int = 0) -> IcsShare:
    """The ICS share of ``n`` draws of ``config``'s ODD (seed ``seed``)."""
    flags = ics_flags(config, scenario_set(config, n, seed), sumo_seed=sumo_seed)
    hits = sum(flags)
    lo, hi = wilson_interval(hits, n)
    return IcsShare(config.case, n, int(hits), lo, hi, tuple(pov_strategies(config.case)))
