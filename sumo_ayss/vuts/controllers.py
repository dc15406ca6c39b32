"""A user's controller as the VUT: the protocol, its limits, and how SUMO executes it.

A controller is any Python object with an ``acceleration(state) -> float`` method (and,
optionally, ``reset()``, called at the start of every episode). It sees what a real
automated vehicle's own sensors would see, nothing of the simulator:

==================  =======  ===========================================================
field               unit     meaning
==================  =======  ===========================================================
``time_s``          s        simulation time of the reading
``dt_s``            s        step length: how long the returned command will act
``speed_mps``       m/s      own speed (>= 0)
``gap_m``           m        bumper-to-bumper gap to the leader in the own lane, leader
                             rear minus own front; ``math.inf`` when there is no leader
                             within ``sensor_range_m``; may be <= 0 while a cutting-in
                             vehicle's rear is still beside the own front
``rel_speed_mps``   m/s      leader speed minus own speed: > 0 the gap opens, < 0 it
                             closes; 0.0 when there is no leader
``lane_index``      -        own lane, 0 = rightmost
``objects``         -        the object list: every other vehicle within
                             ``sensor_range_m`` (gap in ``[-range, range]``), in any lane,
                             as :class:`~sumo_ayss.sim.pair.SensedObject` (below)
``lane_width_m``    m        width of the own lane (NaN where unknown)
==================  =======  ===========================================================

An entry of ``objects`` is what a real vehicle's object list holds, in the own road frame:

=======================  =====  ==========================================================
``gap_m``                m      object rear bumper minus own front bumper (> 0 ahead,
                                <= 0 beside or behind)
``lateral_offset_m``     m      object centre line from the own lane's centre line,
                                + = left (about one lane width: centred in the next lane)
``rel_speed_mps``        m/s    object longitudinal speed minus own (< 0 closing in)
``lateral_speed_mps``    m/s    object lateral speed relative to own, + = left
``length_m``,            m      the object's body
``width_m``
=======================  =====  ==========================================================

A cut-in is visible in ``objects`` before it reaches ``gap_m``: the object's
``lateral_offset_m`` shrinks toward 0 at ``lateral_speed_mps`` while it is still in the next
lane. A controller that reads only the leader fields keeps working unchanged (the two new
fields come last, with defaults). The reference drivers (:mod:`sumo_ayss.vuts.reference`)
read the object list.

"Leader" is the vehicle ahead whose body reaches into the own lane, so a cut-in counts from
the moment the cutting-in vehicle crosses the lane edge (see
:meth:`sumo_ayss.sim.pair.VehiclePair.vut_sensing`). The controller returns an acceleration
[m/s²], positive forward, negative braking.

**Execution.** The testbed clips the command to the declared limits,
``[-max_decel_mps2, max_accel_mps2]`` (:func:`bound_acceleration`), integrates it over one
step, ``v' = clip(v + a·dt, 0, max_speed_mps)`` (:func:`commanded_speed`), and makes SUMO
drive exactly ``v'`` during the next step with all of SUMO's own checks off for the VUT
(speed mode 0: no safe-speed, acceleration or speed-limit check; SUMO does not brake for
the controller). SUMO's default (Euler) position update moves the vehicle by ``v'·dt`` in
that step. A non-finite command raises :class:`ControllerError`.

**Timing.** The state passed to the controller is read after SUMO step ``t`` (it includes
the POV's move during step ``t``); the returned command is applied during step ``t + 1``.
That is the information delay of SUMO's own car-following models, which also compute the
speed of step ``t + 1`` from the state after step ``t``; there is no extra delay. The
command is re-evaluated every SUMO step (``sim.step_length_s``, 0.2 s by default), not
every policy decision of the POV. At the start of an episode the first state is the
initial condition itself (the state after placement, before the first step).

**Configuration.** A VUT entry of ``env.vuts`` names the controller
(:class:`~sumo_ayss.vuts.catalog.ControllerSpec`)::

    acc_tg2:
      description: constant time-gap ACC, T = 2 s
      controller:
        target: examples.acc_controller:TimeGapACC   # or path/to/file.py:TimeGapACC
        params: {time_gap_s: 2.0}                    # keyword arguments of the target
        max_accel_mps2: 3.0                          # declared limits (required)
        max_decel_mps2: 6.0

A worked example is ``examples/acc_controller.py`` (constant time-gap ACC). An FMI
co-simulation FMU (``fmu:``, :mod:`sumo_ayss.vuts.fmu`) or another program (``process:``,
:mod:`sumo_ayss.vuts.process`) is executed the same way; every kind's calls are timed
against ``call_deadline_s`` (:mod:`sumo_ayss.vuts.call_budget`).
"""

from __future__ import annotations

import math
import numbers
import time
from typing import Any, NamedTuple, Protocol, runtime_checkable

from sumo_ayss.sim.pair import VehiclePair
from sumo_ayss.sim.sensing import SensedObject, VutSensing
from sumo_ayss.util.errors import ControllerError
from sumo_ayss.vuts.call_budget import CallBudget
from sumo_ayss.vuts.catalog import ControllerSpec, VehicleType

__all__ = [
    "ControlledVut",
    "Controller",
    "ControllerError",
    "ControllerInput",
    "SensedObject",
    "bound_acceleration",
    "commanded_speed",
]


class ControllerInput(NamedTuple):
    """The state a controller sees (see the module docstring for the table).

    Attributes:
        time_s: Simulation time of the reading [s].
        dt_s: Step length [s]: the returned command acts for this long.
        speed_mps: Own speed [m/s].
        gap_m: Bumper-to-bumper gap to the leader [m]; ``inf`` without a leader.
        rel_speed_mps: Leader speed minus own speed [m/s]; > 0 opening; 0 without leader.
        lane_index: Own lane index (0 = rightmost).
        objects: The object list: other vehicles within sensor range, any lane.
        lane_width_m: Width of the own lane [m]; NaN where unknown.
    """

    time_s: float
    dt_s: float
    speed_mps: float
    gap_m: float
    rel_speed_mps: float
    lane_index: int
    objects: tuple[SensedObject, ...] = ()
    lane_width_m: float = math.nan

    @property
    def has_leader(self) -> bool:
        """Whether a leader is seen (``gap_m`` is finite)."""
        return math.isfinite(self.gap_m)

    @classmethod
    def from_sensing(cls, s: VutSensing, dt_s: float) -> ControllerInput:
        """Build from a sim-layer reading (NaN leader speed -> relative speed 0)."""
        lead = math.isfinite(s.gap_m)
        rel = s.leader_speed_mps - s.speed_mps if lead else 0.0
        return cls(
            s.time_s, dt_s, s.speed_mps, s.gap_m, rel, s.lane_index, s.objects, s.lane_width_m
        )


@runtime_checkable
class Controller(Protocol):
    """What a VUT controller implements. ``reset()`` is optional (called if present)."""

    def acceleration(self, state: ControllerInput) -> float:
        """Acceleration command [m/s²] (> 0 forward, < 0 braking) for the next step."""
        ...


def bound_acceleration(accel_mps2: Any, max_accel_mps2: float, max_decel_mps2: float) -> float:
    """Clip a command to ``[-max_decel_mps2, max_accel_mps2]`` [m/s²].

    Args:
        accel_mps2: The controller's command [m/s²] (any real number type).
        max_accel_mps2: Declared acceleration limit [m/s²], > 0.
        max_decel_mps2: Declared deceleration limit [m/s²], a positive number.

    Raises:
        ControllerError: If the command is not a finite real number.
    """
    # A real number only: float('2.5') would accept a string, float(True) a bool.
    if isinstance(accel_mps2, bool) or not isinstance(accel_mps2, numbers.Real):
        raise ControllerError(
            f"controller returned {accel_mps2!r} ({type(accel_mps2).__name__}); "
            "acceleration(state) must return a finite real number [m/s²]"
        )
    a = float(accel_mps2)
    if not math.isfinite(a):
        raise ControllerError(
            f"controller returned {accel_mps2!r}; acceleration(state) must return a finite "
            "real number [m/s²]"
        )
    return min(max(a, -max_decel_mps2), max_accel_mps2)


def commanded_speed(
    speed_mps: float, accel_mps2: float, dt_s: float, max_speed_mps: float
) -> tuple[float, float]:
    """Speed after one step at a bounded acceleration, and the acceleration realised.

    ``v' = clip(v + a·dt, 0, max_speed_mps)``; the realised acceleration ``(v' - v) / dt``
    differs from ``a`` only where the clip acts (stopping, top speed).

    Returns:
        ``(v' [m/s], realised acceleration [m/s²])``.
    """
    v_next = min(max(speed_mps + accel_mps2 * dt_s, 0.0), max_speed_mps)
    return v_next, (v_next - speed_mps) / dt_s


class ControlledVut:
    """Drives a pair's VUT with a user controller through SUMO (one per env / pair).

    Args:
        controller: The controller instance (see :class:`Controller`).
        spec: Its configuration (declared limits, sensor range).
        dt_s: SUMO step length [s].

    Attributes:
        last_state: The state given to the controller before the last step.
        last_request_mps2: What the controller asked for [m/s²], before bounding.
        last_command_mps2: The acceleration realised in the last step [m/s²] (bounded,
            and zero-speed / top-speed clipped).
        budget: Per-call wall time against ``spec.call_deadline_s``
            (:mod:`sumo_ayss.vuts.call_budget`).
    """

    def __init__(self, controller: Any, spec: ControllerSpec, dt_s: float) -> None:
        self.controller = controller
        self.spec = spec
        self.dt_s = float(dt_s)
        self.last_state: ControllerInput | None = None
        self.last_request_mps2 = 0.0
        self.last_command_mps2 = 0.0
        self.budget = CallBudget(spec.label, spec.call_deadline_s)

    @classmethod
    def from_vehicle_type(
        cls, vt: VehicleType, dt_s: float, where: str = "controller"
    ) -> ControlledVut | None:
        """A driver for ``vt``'s controller (a fresh instance), or ``None`` for a SUMO model.

        This is where a user controller is imported and built (reading a config only checks
        its form); ``where`` names the config field in the errors.
        """
        if vt.controller is None:
            return None
        return cls(vt.controller.build(where), vt.controller, dt_s)

    def start(self, pair: VehiclePair) -> None:
        """Take over the freshly placed VUT (speed mode 0) and reset the controller."""
        pair.take_vut_control()
        reset = getattr(self.controller, "reset", None)
        if reset is not None:
            try:
                reset()
            except Exception as e:
                raise ControllerError(
                    f"controller {self.spec.target!r}: reset() raised {type(e).__name__}: {e}"
                ) from e
        self.last_state = None
        self.last_request_mps2 = self.last_command_mps2 = 0.0

    def observe(self, pair: VehiclePair) -> ControllerInput:
        """The controller's view of the pair now."""
        return ControllerInput.from_sensing(pair.vut_sensing(self.spec.sensor_range_m), self.dt_s)

    def before_step(self, pair: VehiclePair) -> float:
        """Ask the controller and command the VUT's speed for the coming SUMO step.

        Returns:
            The acceleration that will be realised during the step [m/s²].
        """
        state = self.observe(pair)
        spec = self.spec
        start_s = time.perf_counter()
        try:
            request = self.controller.acceleration(state)
        except ControllerError:  # an FMU or process driver's own, already naming the VUT
            raise
        except Exception as e:  # user code: stop the run with the controller named
            raise ControllerError(
                f"controller {self.spec.target!r} raised {type(e).__name__}: {e} (state {state})"
            ) from e
        self.budget.record(start_s, time.perf_counter() - start_s)
        try:
            accel = bound_acceleration(request, spec.max_accel_mps2, spec.max_decel_mps2)
        except ControllerError as e:
            raise ControllerError(f"{spec.label}: {e}") from None
        v_next, realised = commanded_speed(state.speed_mps, accel, self.dt_s, spec.max_speed_mps)
        pair.command_vut_speed(v_next)
        self.last_state = state
        self.last_request_mps2 = float(request)
        self.last_command_mps2 = realised
        return realised

    def close(self) -> None:
        """Release what the controller holds (an FMU instance, a process), if it can."""
        close = getattr(self.controller, "close", None)
        if callable(close):
            close()
