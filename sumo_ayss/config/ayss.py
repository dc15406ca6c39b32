"""Monte Carlo settings of the AYSS stage (:mod:`sumo_ayss.scenarios.ayss`), section
``evaluate.ayss`` of a pipeline YAML. Units m, m/s, s."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

from sumo_ayss.config.env import OddConfig
from sumo_ayss.util.validation import check_int, check_number, check_range, check_seed

#: Default Monte Carlo seed, shared by every SPCP (common random numbers across VUTs).
DEFAULT_AYSS_SEED = 4242


@dataclass(frozen=True)
class AyssConfig:
    """Monte Carlo settings of the AYSS stage. Units m, m/s, s.

    Defaults: speeds over the whole observed range up to the 30 m/s speed limit, [0, 30] m/s
    (the ODD only says where episodes *start*; within an episode the POV brakes down towards
    0, so the SPCP acts on slower states too; :meth:`from_odd` restricts the speeds to the
    ODD instead). Headways in [0, 5] m, the kept range, so that no draw is wasted on the h
    filter; a wider ``h_m`` box is sampled and then filtered the same way. 100,000 draws
    keep about 10,000 samples per 0.5 m headway bin in car-following, so a bin's 95 %
    interval of the mean acceleration is about ±0.05 m/s² wide for a 3 m/s² spread.

    Attributes:
        n_samples: Monte Carlo draws (before filtering), >= 1.
        v_pov_mps: Sampled POV speed range [m/s].
        v_vut_mps: Sampled VUT speed range [m/s].
        h_m: Sampled headway range [m] (POV rear bumper minus VUT front bumper).
        max_headway_m: Keep ``h <= max_headway_m`` (paper: 5 m).
        min_ttc_s: Keep ``TTC >= min_ttc_s`` (paper: 0.2 s).
        seed: Seed of the draws; the same seed gives the same samples for every SPCP.
        batch_size: Observations per policy forward pass.
    """

    SECTION: ClassVar[str] = "ayss"

    n_samples: int = 100_000
    v_pov_mps: tuple[float, float] = (0.0, 30.0)
    v_vut_mps: tuple[float, float] = (0.0, 30.0)
    h_m: tuple[float, float] = (0.0, 5.0)
    max_headway_m: float = 5.0
    min_ttc_s: float = 0.2
    seed: int = DEFAULT_AYSS_SEED
    batch_size: int = 65_536

    def __post_init__(self) -> None:
        s = self.SECTION
        check_int(f"{s}.n_samples", self.n_samples, low=1)
        check_int(f"{s}.batch_size", self.batch_size, low=1)
        for name, low in (("v_pov_mps", 0.0), ("v_vut_mps", 0.0), ("h_m", -math.inf)):
            object.__setattr__(self, name, check_range(f"{s}.{name}", getattr(self, name), low))
        check_number(f"{s}.max_headway_m", self.max_headway_m, low=0.0, low_open=True)
        check_number(f"{s}.min_ttc_s", self.min_ttc_s, low=0.0)
        check_seed(self.seed, f"{s}.seed")

    @classmethod
    def from_odd(cls, odd: OddConfig, **overrides: Any) -> AyssConfig:
        """Speeds sampled in the ODD's ranges instead of [0, 30] m/s."""
        return cls(**{"v_pov_mps": odd.pov_speed_mps, "v_vut_mps": odd.vut_speed_mps, **overrides})

    def to_dict(self) -> dict[str, Any]:
        return {k: list(v) if isinstance(v, tuple) else v for k, v in self.__dict__.items()}
