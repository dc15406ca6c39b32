"""The VUT driven by SUMO's own car-following model (its vType's ``carFollowModel``)."""

from __future__ import annotations

from sumo_ayss.laws.base import PovLaw, VutLaw
from sumo_ayss.sim.pair import VehiclePair

__all__ = ["SumoModelVut"]


class SumoModelVut(VutLaw):
    """SUMO moves the VUT itself, with all its checks on; nothing is commanded."""

    def start(self, pair: VehiclePair, speed_mps: float) -> None:
        """Nothing to take over: placement already gave SUMO the VUT's state."""
        del pair, speed_mps

    def command(self, pair: VehiclePair, pov: PovLaw) -> None:
        """Nothing to command: SUMO computes the VUT's speed in its step."""
        del pair, pov

    def accel_mps2(self, pair: VehiclePair) -> float:
        """SUMO's acceleration of the VUT in the last step [m/s²]."""
        return pair.vut_accel_mps2()
