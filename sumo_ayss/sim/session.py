"""The process's one libsumo simulation.

libsumo holds exactly one simulation per process (SUMO maintainers, eclipse-sumo/sumo
#7694). :class:`SumoSession` makes that explicit: it starts SUMO lazily, knows its owner,
and a second owner asking for a live simulation gets a clear :class:`SimulationError`
instead of a libsumo crash or, worse, silently sharing (and corrupting) the first one.
"""

from __future__ import annotations

import logging
import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, ClassVar

import libsumo
from libsumo import _libsumo

from sumo_ayss.config import SimConfig, integration_method
from sumo_ayss.sim.network import sumo_binary
from sumo_ayss.util.errors import SimulationError
from sumo_ayss.vuts.catalog import VehicleType, vtypes_xml

logger = logging.getLogger(__name__)

#: libsumo's exception types; wrapped into SimulationError at this layer's boundary.
SUMO_ERRORS: tuple[type[BaseException], ...] = (libsumo.TraCIException, libsumo.FatalTraCIError)


_step = _libsumo.simulation_step
_n_colliding = _libsumo.simulation_getCollidingVehiclesNumber
_colliding_ids = _libsumo.simulation_getCollidingVehiclesIDList


def sumo_version() -> str:
    """Version string of the libsumo in use (e.g. ``1.28.0``)."""
    return str(libsumo.__version__) if hasattr(libsumo, "__version__") else "unknown"


class SumoSession:
    """Owner of the process's libsumo simulation.

    Args:
        network: ``.net.xml`` to load.
        vtypes: vehicle types to load, by type id.
        sim: SUMO options.
        seed: SUMO's ``--seed`` (SUMO is deterministic for a fixed seed).
        owner: a short description of who owns it, shown in the error a second owner gets.
    """

    _live: ClassVar[SumoSession | None] = None

    def __init__(
        self,
        network: Path,
        vtypes: Mapping[str, VehicleType],
        sim: SimConfig,
        seed: int,
        owner: str,
    ) -> None:
        if not Path(network).is_file():
            raise SimulationError(f"network file not found: {network}")
        self.network = Path(network)
        self.vtypes = dict(vtypes)
        self.sim = sim
        self.seed = int(seed)
        self.owner = owner
        self._tmp: tempfile.TemporaryDirectory[str] | None = None
        self._routes: set[str] = set()  # routes known to be in the running simulation

    @property
    def integration(self) -> str:
        """``"euler"`` or ``"ballistic"``: how SUMO moves every vehicle of this simulation."""
        return integration_method(self.sim, self.vtypes.values())

    @property
    def running(self) -> bool:
        return SumoSession._live is self

    def command(self, additional: Path) -> list[str]:
        """The SUMO command line (without starting it)."""
        s = self.sim
        return [
            str(sumo_binary("sumo")),
            "--net-file", str(self.network),
            "--additional-files", str(additional),
            "--step-length", repr(s.step_length_s),
            "--seed", str(self.seed),
            # Always explicit: SUMO would switch every vehicle to ballistic on its own when a
            # loaded type has a longer action step (env.sim.step_method).
            "--step-method.ballistic",
            str(self.integration == "ballistic").lower(),
            # A collision is reported and the vehicles keep driving (they pass through each
            # other); the default action teleports them away and hides the crash.
            "--collision.action", "warn",
            # 0: only physical overlap is a collision (the default flags a 0.3 m gap).
            "--collision.mingap-factor", repr(s.collision_mingap_factor),
            "--time-to-teleport", "-1",
            # Continuous lateral motion for lane changes (the POV's cut-in has a real
            # lateral velocity); without it SUMO changes lanes instantaneously. The sublane
            # model (free lateral positions, for highway-env's POV) excludes this option.
            *(
                ("--lanechange.duration", repr(s.lanechange_duration_s))
                if s.lateral_resolution_m is None
                # The sublane model's lane-change model (SL2015) has no per-vehicle
                # lcOvertakeRight: allow overtaking on the right globally instead.
                else (
                    "--lateral-resolution", repr(s.lateral_resolution_m),
                    "--lanechange.overtake-right", "true",
                )
            ),
            "--no-step-log", "true",
            "--no-warnings", "true",
            "--duration-log.disable", "true",
            "--begin", "0",
            *s.extra_args,
        ]  # fmt: skip

    def start(self) -> None:
        """Start SUMO if it is not running; raise if another owner holds the simulation."""
        if self.running:
            return
        live = SumoSession._live
        if live is not None:
            # The owner may be an env dropped without close(): collecting it runs its
            # finalizer, which closes the simulation (see PairEnv._ensure_sim).
            import gc

            gc.collect()
            live = SumoSession._live
        if live is not None:
            raise SimulationError(
                f"a libsumo simulation is already running in this process (owner: "
                f"{live.owner}); libsumo holds one simulation per process. Close it first "
                f"(env.close()) or run the second one in another process."
            )
        self._tmp = tempfile.TemporaryDirectory(prefix="sumo_ayss_")
        additional = Path(self._tmp.name) / "vtypes.add.xml"
        additional.write_text(vtypes_xml(self.vtypes))
        cmd = self.command(additional)
        logger.debug("starting SUMO: %s", " ".join(cmd))
        try:
            libsumo.start(cmd)
        except SUMO_ERRORS as e:
            self._cleanup()
            raise SimulationError(f"SUMO failed to start ({e}); command: {' '.join(cmd)}") from e
        SumoSession._live = self

    def close(self) -> None:
        """Close the simulation; safe to call twice and on a session that never started."""
        if self.running:
            try:
                libsumo.close()
            except SUMO_ERRORS as e:  # pragma: no cover - SUMO already gone
                logger.warning("libsumo.close() failed: %s", e)
            finally:
                SumoSession._live = None
        self._routes.clear()
        self._cleanup()

    def _cleanup(self) -> None:
        if self._tmp is not None:
            self._tmp.cleanup()
            self._tmp = None

    # ------------------------------------------------------------------ simulation calls

    def step(self) -> None:
        """Advance SUMO by one ``step_length_s``."""
        # The compiled step, without libsumo's Python step-listener bookkeeping (we register
        # no listeners); the public wrapper costs ~2 µs per call on a ~10 µs step.
        _step(0.0)

    def time_s(self) -> float:
        return float(libsumo.simulation.getTime())

    def colliding_ids(self) -> Sequence[str]:
        """Ids of vehicles involved in a collision during the last step."""
        if _n_colliding() == 0:
            return ()
        return tuple(_colliding_ids())

    def collision_pairs(self) -> tuple[tuple[str, str], ...]:
        """``(collider, victim)`` of each collision of the last step (SUMO's
        ``simulation.getCollisions``): who hit whom, where a third vehicle is near."""
        if _n_colliding() == 0:
            return ()
        return tuple((c.collider, c.victim) for c in libsumo.simulation.getCollisions())

    def add_route(self, route_id: str, edges: Sequence[str]) -> None:
        """Add route ``route_id`` over ``edges`` unless this simulation has it already."""
        # Known routes are remembered: libsumo's getIDList costs O(routes) per call, and a
        # pair asks at every episode start (N pairs in one simulation: O(N) each).
        if route_id in self._routes:
            return
        if route_id not in libsumo.route.getIDList():
            libsumo.route.add(route_id, list(edges))
        self._routes.add(route_id)

    def call(self, fn: Any, *args: Any) -> Any:
        """Call a libsumo function, turning its errors into :class:`SimulationError`."""
        try:
            return fn(*args)
        except SUMO_ERRORS as e:
            raise SimulationError(
                f"SUMO call {getattr(fn, '__name__', fn)}{args} failed: {e}"
            ) from e
