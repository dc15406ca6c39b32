"""Which law drives which vehicle, by name: built once per env from its configuration.

* The POV's law is named by ``env.actuator.mode`` (:data:`POV_LAWS`).
* The VUT's law follows from its catalog entry (:attr:`~sumo_ayss.config.EnvConfig.
  vut_type`): SUMO's car-following model when it has no controller; a controller the
  testbed integrates itself when the controller's ``target`` is registered in
  :data:`INTEGRATED_CONTROLLERS` (highway-env's IDM); any other controller is asked once per
  SUMO step (:class:`~sumo_ayss.laws.controller.ControllerVut`).

A new law is one module with a class implementing :class:`~sumo_ayss.laws.base.PovLaw` or
:class:`~sumo_ayss.laws.base.VutLaw` and one entry here.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

from sumo_ayss.config import ActuatorMode, EnvConfig
from sumo_ayss.laws.base import PovLaw, VehicleLaws, VutLaw
from sumo_ayss.laws.clipped import ClippedPov
from sumo_ayss.laws.controller import ControllerVut
from sumo_ayss.laws.highway_env import HighwayEnvIdmVut, HighwayEnvPovLaw
from sumo_ayss.laws.hwenv import HIGHWAY_ENV_IDM_TARGET
from sumo_ayss.laws.sumo_model import SumoModelVut

__all__ = ["INTEGRATED_CONTROLLERS", "POV_LAWS", "build_laws", "pov_law", "vut_law"]

#: The POV's law of each ``env.actuator.mode``.
POV_LAWS: Mapping[ActuatorMode, Callable[[EnvConfig], PovLaw]] = {
    "clipped": ClippedPov.from_config,
    "highway_env": HighwayEnvPovLaw.from_config,
}

#: VUT controllers integrated by a law of their own instead of being asked once per SUMO
#: step, by their ``controller.target``.
INTEGRATED_CONTROLLERS: Mapping[str, Callable[[EnvConfig], VutLaw]] = {
    HIGHWAY_ENV_IDM_TARGET: HighwayEnvIdmVut.from_config,
}


def pov_law(config: EnvConfig) -> PovLaw:
    """The POV's law for ``config`` (a fresh instance: laws hold an episode's state)."""
    return POV_LAWS[config.actuator.mode](config)


def vut_law(config: EnvConfig) -> VutLaw:
    """The VUT's law for ``config.vut``; a user controller is imported and built here."""
    spec = config.vut_type.controller
    if spec is None:
        return SumoModelVut()
    return INTEGRATED_CONTROLLERS.get(spec.target, ControllerVut.from_config)(config)


def build_laws(config: EnvConfig) -> VehicleLaws:
    """Both laws of an env of ``config``."""
    return VehicleLaws(pov_law(config), vut_law(config))
