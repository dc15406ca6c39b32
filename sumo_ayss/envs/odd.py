"""Initial conditions and their sampling from the VUT's operational design domain (ODD)."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from sumo_ayss.cases import get_case
from sumo_ayss.config import EnvConfig, OddConfig
from sumo_ayss.config.follower import FollowerConfig
from sumo_ayss.util.errors import ConfigError


@dataclass(frozen=True)
class InitialCondition:
    """State of a pair at the start of an episode.

    Attributes:
        pov_speed_mps: POV speed [m/s].
        vut_speed_mps: VUT speed [m/s].
        gap_m: longitudinal gap, POV rear bumper minus VUT front bumper [m]. In cut-in the
            POV starts in the adjacent lane, so a negative gap (side by side) is possible.
        follower_gap_m: The follower's gap, VUT rear bumper minus follower front bumper [m]
            (> 0); None: no follower (:func:`with_followers` draws it).
        follower_speed_mps: The follower's speed [m/s]; None without a follower.
    """

    pov_speed_mps: float
    vut_speed_mps: float
    gap_m: float
    follower_gap_m: float | None = None
    follower_speed_mps: float | None = None

    def as_tuple(self) -> tuple[float, float, float]:
        return (self.pov_speed_mps, self.vut_speed_mps, self.gap_m)


#: Whether a start drawn from the ODD may be used (:func:`start_filter`).
StartFilter = Callable[[InitialCondition], bool]
#: Draws per start before an ODD whose starts the filter all refuses is reported.
MAX_DRAWS = 1000


def sample_initial_condition(
    odd: OddConfig, rng: np.random.Generator, admissible: StartFilter | None = None
) -> InitialCondition:
    """Uniform draw from the ODD's speed and gap ranges (one ``rng.random(3)``, field order);
    with ``admissible``, drawn again until it accepts the start (rejection sampling)."""
    for _ in range(MAX_DRAWS):
        u_pov, u_vut, u_gap = rng.random(3).tolist()
        ic = InitialCondition(
            _lerp(odd.pov_speed_mps, u_pov),
            _lerp(odd.vut_speed_mps, u_vut),
            _lerp(odd.gap_m, u_gap),
        )
        if admissible is None or admissible(ic):
            return ic
    raise ConfigError(f"env.odd: no admissible start in {MAX_DRAWS} draws of {odd}")


def start_filter(cfg: EnvConfig) -> StartFilter | None:
    """The case's admissible-start check when ``env.odd.exclude_inevitable`` is set, else
    None (every draw is used, as before the option)."""
    if not cfg.odd.exclude_inevitable:
        return None
    factory: Callable[[EnvConfig], StartFilter] = get_case(cfg.case).start_filter_factory()
    return factory(cfg)


def _lerp(bounds: tuple[float, float], u: float) -> float:
    return bounds[0] + (bounds[1] - bounds[0]) * u


def sample_initial_conditions(
    odd: OddConfig, n: int, seed: int, admissible: StartFilter | None = None
) -> list[InitialCondition]:
    """``n`` initial conditions from a seed: the fixed scenario set shared by every VUT."""
    rng = np.random.default_rng(seed)
    return [sample_initial_condition(odd, rng, admissible) for _ in range(n)]


def scenario_set(cfg: EnvConfig, n: int, seed: int) -> list[InitialCondition]:
    """The scenario set of ``cfg``'s ODD: :func:`sample_initial_conditions` with the
    case's :func:`start_filter` (the same draws as before where none applies)."""
    return sample_initial_conditions(cfg.odd, n, seed, start_filter(cfg))


#: Tag of the follower's random stream, so that its draws never shift the scenario set's.
FOLLOWER_STREAM = 33


def with_followers(
    scenarios: Sequence[InitialCondition], follower: FollowerConfig, seed: int
) -> list[InitialCondition]:
    """``scenarios`` with a follower start each (``follower.enabled``; else unchanged).

    The follower drives at the VUT's initial speed at a time headway drawn uniformly from
    ``follower.time_headway_s`` (at least its ``minGap``, 2.5 m by default, behind a VUT
    at rest), one draw per scenario in order from a stream of its own
    (``[FOLLOWER_STREAM, seed]``): the VUT-POV part of every scenario is the set's as
    without a follower, and scenario ``i`` has the same follower for every VUT.
    """
    if not follower.enabled:
        return list(scenarios)
    floor = float(follower.vtype.params.get("minGap", 2.5))  # a VUT at rest: standstill gap
    rng = np.random.default_rng([FOLLOWER_STREAM, seed])
    u = rng.random(len(scenarios)).tolist()
    lo, hi = follower.time_headway_s
    return [
        dataclasses.replace(
            ic,
            follower_gap_m=max((lo + (hi - lo) * u_i) * ic.vut_speed_mps, floor),
            follower_speed_mps=ic.vut_speed_mps,
        )
        for ic, u_i in zip(scenarios, u, strict=True)
    ]


def with_follower_at(
    ic: InitialCondition, follower: FollowerConfig, seed: int, index: int
) -> InitialCondition:
    """Scenario ``index`` of a set of ``seed`` with its follower start, as
    :func:`with_followers` gives it (a replay of one row); ``ic`` unchanged when the
    follower is off."""
    if not follower.enabled:
        return ic
    return with_followers([ic] * (index + 1), follower, seed)[index]
