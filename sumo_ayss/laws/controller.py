"""The VUT driven by a user controller (:mod:`sumo_ayss.vuts.controllers`), once per SUMO step."""

from __future__ import annotations

from sumo_ayss.config import EnvConfig
from sumo_ayss.laws.base import PovLaw, VutLaw
from sumo_ayss.sim.pair import VehiclePair
from sumo_ayss.vuts.controllers import ControlledVut

__all__ = ["ControllerVut"]


class ControllerVut(VutLaw):
    """Before every SUMO step the controller sees what the VUT's sensors see and returns an
    acceleration [m/s²]; SUMO drives the bounded speed exactly (speed mode 0). The
    execution semantics are :class:`~sumo_ayss.vuts.controllers.ControlledVut`'s.

    Args:
        driver: The controller with its declared limits and the step length.
    """

    def __init__(self, driver: ControlledVut) -> None:
        self.driver = driver

    @classmethod
    def from_config(cls, config: EnvConfig) -> ControllerVut:
        """Import and build ``config.vut``'s controller (errors name the config field)."""
        spec = config.vut_type.controller
        assert spec is not None
        where = f"env.vuts.{config.vut}.{spec.yaml_key}"
        return cls(ControlledVut(spec.build(where), spec, config.sim.step_length_s))

    def start(self, pair: VehiclePair, speed_mps: float) -> None:
        """Speed mode 0 for the VUT, the controller's ``reset()``."""
        del speed_mps
        self.driver.start(pair)

    def command(self, pair: VehiclePair, pov: PovLaw) -> None:
        """Ask the controller and command the VUT's speed for the coming step."""
        del pov
        self.driver.before_step(pair)

    def accel_mps2(self, pair: VehiclePair) -> float:
        """SUMO's acceleration of the VUT in the last step [m/s²] (the realised command)."""
        return pair.vut_accel_mps2()

    def close(self) -> None:
        """Release the controller's FMU instance or process, if it has one."""
        self.driver.close()
