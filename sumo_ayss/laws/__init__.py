"""Vehicle laws: what moves the POV and the VUT over each SUMO step, as objects the env calls.

One class per law (:mod:`~sumo_ayss.laws.base` has the interfaces and the order of calls):

==========================  ===============================================================
law                         drives
==========================  ===============================================================
``ClippedPov``              the POV on our bounded speed law (``env.actuator.mode: clipped``)
``HighwayEnvPovLaw``        the POV on highway-env's ControlledVehicle (``mode: highway_env``)
``SumoModelVut``            the VUT on SUMO's own car-following model
``ControllerVut``           the VUT on a user controller, asked once per SUMO step
``HighwayEnvIdmVut``        the VUT on highway-env's IDMVehicle, at Euler sub-steps
==========================  ===============================================================

:func:`build_laws` picks them by name from the configuration (:mod:`~sumo_ayss.laws.
registry`). Laws reach SUMO only through :class:`~sumo_ayss.sim.pair.VehiclePair`.
:func:`braking_contact` forecasts the clipped law without SUMO (inevitable-start checks).
"""

from __future__ import annotations

from sumo_ayss.laws.base import PovLaw, VehicleLaw, VehicleLaws, VutLaw
from sumo_ayss.laws.braking import braking_contact
from sumo_ayss.laws.registry import build_laws

__all__ = ["PovLaw", "VehicleLaw", "VehicleLaws", "VutLaw", "braking_contact", "build_laws"]
