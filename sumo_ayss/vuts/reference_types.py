"""The reference drivers as catalog entries (VUT definitions), without importing their code.

The controllers themselves are :mod:`sumo_ayss.vuts.reference` (imported only when an env
that drives one is built, like any controller); this module holds what a configuration
needs: their names, their catalog entries, the default reference.
"""

from __future__ import annotations

from collections.abc import Mapping

from sumo_ayss.util.frozen import FrozenMap
from sumo_ayss.vuts.catalog import ControllerSpec, VehicleType

__all__ = ["DEFAULT_REFERENCE", "OVERBRAKER_VUT", "REFERENCE_VUTS"]


def _reference(target: str, description: str, max_decel_mps2: float) -> VehicleType:
    # ``target``: the controller's registered name (sumo_ayss.vuts.controller_spec.CONTROLLERS).
    # A reference driver of sumo_ayss.vuts.reference in SUMO's passenger body (5 m x 1.8 m).
    return VehicleType(
        model="IDM",
        params={"length": 5.0, "width": 1.8, "minGap": 0.0},
        description=description,
        controller=ControllerSpec(
            target=target,
            params={},
            max_accel_mps2=3.0,
            max_decel_mps2=max_decel_mps2,
            max_speed_mps=40.0,
        ),
    )


#: The reference drivers as VUTs (:mod:`sumo_ayss.vuts.reference`): R157's competent and
#: careful human driver, JRC's Fuzzy Safety Model, RSS's proper response. Name one in
#: ``grid.vuts`` (or add it to a catalog) to rank it; cross-play drives them against the
#: pooled opponents; the preventability labels replay every crash with one
#: (:mod:`sumo_ayss.scenarios.preventability`). Limits: 0.85 g (the CC driver's AEB),
#: 0.774 g (FSM's cap), 8 m/s² (RSS's b_max).
REFERENCE_VUTS: Mapping[str, VehicleType] = FrozenMap(
    {
        "cc_driver": _reference(
            "careful_driver",
            "R157 competent and careful human driver (reaction 0.75 s, 0.774 g in 0.6 s, AEB)",
            0.85 * 9.81,
        ),
        "fsm": _reference(
            "fuzzy_safety_driver", "JRC Fuzzy Safety Model (Mattas et al. 2020)", 0.774 * 9.81
        ),
        "rss": _reference(
            "rss_driver", "RSS longitudinal proper response (rho 1 s, b_min 4 m/s²)", 8.0
        ),
    }
)

#: The reference driver that labels crashes preventable or not unless configured otherwise.
DEFAULT_REFERENCE = "cc_driver"

#: Issue 33's over-braker (:class:`sumo_ayss.vuts.overbraking.OverBraker`): brakes at
#: 6 m/s² whenever a leader is within 2 s. Its limits are its own (2 m/s² up, 6 down).
OVERBRAKER_VUT = VehicleType(
    model="IDM",
    params={"length": 5.0, "width": 1.8, "minGap": 0.0},
    description="brakes at 6 m/s² whenever a leader is within 2 s (issue 33's over-braker)",
    controller=ControllerSpec(
        target="over_braker",
        params={},
        max_accel_mps2=2.0,
        max_decel_mps2=6.0,
        max_speed_mps=40.0,
    ),
)
