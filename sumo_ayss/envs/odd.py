"""Initial conditions and their sampling from the VUT's operational design domain (ODD)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sumo_ayss.config import OddConfig


@dataclass(frozen=True)
class InitialCondition:
    """State of a pair at the start of an episode.

    Attributes:
        pov_speed_mps: POV speed [m/s].
        vut_speed_mps: VUT speed [m/s].
        gap_m: longitudinal gap, POV rear bumper minus VUT front bumper [m]. In cut-in the
            POV starts in the adjacent lane, so a negative gap (side by side) is possible.
    """

    pov_speed_mps: float
    vut_speed_mps: float
    gap_m: float

    def as_tuple(self) -> tuple[float, float, float]:
        return (self.pov_speed_mps, self.vut_speed_mps, self.gap_m)


def sample_initial_condition(odd: OddConfig, rng: np.random.Generator) -> InitialCondition:
    """Uniform draw from the ODD's speed and gap ranges (one ``rng.random(3)``, field order)."""
    u_pov, u_vut, u_gap = rng.random(3).tolist()
    return InitialCondition(
        _lerp(odd.pov_speed_mps, u_pov), _lerp(odd.vut_speed_mps, u_vut), _lerp(odd.gap_m, u_gap)
    )


def _lerp(bounds: tuple[float, float], u: float) -> float:
    return bounds[0] + (bounds[1] - bounds[0]) * u


def sample_initial_conditions(odd: OddConfig, n: int, seed: int) -> list[InitialCondition]:
    """``n`` initial conditions from a seed: the fixed scenario set shared by every VUT."""
    rng = np.random.default_rng(seed)
    return [sample_initial_condition(odd, rng) for _ in range(n)]
