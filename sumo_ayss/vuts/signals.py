"""The VUT's sensor view by name: what an FMU's inputs and a process's request carry.

A Python controller reads :class:`~sumo_ayss.vuts.controllers.ControllerInput` directly. A
black box (an FMU, an external process) gets the same values as named *signals*: an FMU
maps its input variables to signal names (``inputs: {v_ego: speed_mps}``), a process is
told the names once and then gets their values in that order every step.

==================  ======  =====  =========================================================
signal              unit    kind   meaning
==================  ======  =====  =========================================================
``time_s``          s       real   simulation time of the reading
``dt_s``            s       real   step length: how long the returned command acts
``speed_mps``       m/s     real   own speed (>= 0)
``gap_m``           m       real   bumper-to-bumper gap to the leader; ``+inf`` without one
``rel_speed_mps``   m/s     real   leader speed minus own speed (> 0 opening); 0 without one
``lane_index``      -       int    own lane, 0 = rightmost
``has_leader``      -       bool   whether a leader is seen (``gap_m`` finite)
``lane_width_m``    m       real   width of the own lane (NaN where unknown)
``n_objects``       -       int    entries in the object list
==================  ======  =====  =========================================================

**The object list** (:class:`~sumo_ayss.sim.pair.SensedObject`, in the order of
``ControllerInput.objects``) as :data:`OBJECT_SLOTS` fixed slots ``i = 0, 1, ...``:
``objects.<i>.present`` (bool), ``objects.<i>.gap_m`` (m; ``+inf`` for an empty slot),
``objects.<i>.lateral_offset_m``, ``objects.<i>.rel_speed_mps``,
``objects.<i>.lateral_speed_mps`` (m, m/s; 0 for an empty slot), ``objects.<i>.length_m``,
``objects.<i>.width_m`` (m; 0 for an empty slot). An FMU with fixed inputs maps the slots
it has; a process names the ones it wants.

**Adding signals.** A signal is one entry of :data:`SIGNALS`: a name, a unit, a kind and a
function of the controller input; FMUs and processes can then name it like any other
(the FMU maps by name, the process protocol sends the names it was told).
"""

from __future__ import annotations

import math
import operator
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, Literal

from sumo_ayss.util.errors import ConfigError
from sumo_ayss.util.frozen import FrozenMap
from sumo_ayss.util.validation import suggest

__all__ = ["DEFAULT_SIGNALS", "OBJECT_SLOTS", "SIGNALS", "Signal", "SignalKind", "check_signal"]

#: Object-list slots offered as signals (``objects.0.*`` .. ``objects.3.*``).
OBJECT_SLOTS = 4

#: What a signal's value is: a real number, an integer or a truth value.
SignalKind = Literal["real", "int", "bool"]


@dataclass(frozen=True)
class Signal:
    """One named value of the VUT's sensor view.

    Attributes:
        name: The signal's name (configs and the process protocol use it).
        unit: Its unit (``"-"`` for none).
        kind: ``real``, ``int`` or ``bool`` (which FMU variable types it may feed).
        meaning: One line for docs and errors.
        read: The value from a :class:`~sumo_ayss.vuts.controllers.ControllerInput`.
    """

    name: str
    unit: str
    kind: SignalKind
    meaning: str
    read: Callable[[Any], float | int | bool]


def _signal(name: str, unit: str, kind: SignalKind, meaning: str) -> tuple[str, Signal]:
    return name, Signal(name, unit, kind, meaning, operator.attrgetter(name))


def _n_objects(state: Any) -> int:
    return len(state.objects)


#: An object-list field: (unit, value in an empty slot, meaning).
_OBJECT_FIELDS: dict[str, tuple[str, float, str]] = {
    "gap_m": ("m", math.inf, "rear bumper minus own front bumper, > 0 ahead"),
    "lateral_offset_m": ("m", 0.0, "centre line from the own lane's centre line, + left"),
    "rel_speed_mps": ("m/s", 0.0, "longitudinal speed minus own, < 0 closing in"),
    "lateral_speed_mps": ("m/s", 0.0, "lateral speed relative to own, + left"),
    "length_m": ("m", 0.0, "length"),
    "width_m": ("m", 0.0, "width"),
}


def _object_signals(i: int) -> list[tuple[str, Signal]]:
    """The signals of object-list slot ``i``."""

    def present(state: Any) -> bool:
        return len(state.objects) > i

    key = f"objects.{i}.present"
    out = [(key, Signal(key, "-", "bool", f"object slot {i} holds an object", present))]
    for name, (unit, empty, meaning) in _OBJECT_FIELDS.items():

        def read(state: Any, name: str = name, empty: float = empty) -> float:
            objects = state.objects
            return float(getattr(objects[i], name)) if len(objects) > i else empty

        key = f"objects.{i}.{name}"
        out.append((key, Signal(key, unit, "real", f"object {i}: {meaning}", read)))
    return out


#: Every signal, by name (see the module docstring's table).
SIGNALS: Mapping[str, Signal] = FrozenMap(
    dict(
        [
            _signal("time_s", "s", "real", "simulation time of the reading"),
            _signal("dt_s", "s", "real", "step length: how long the command acts"),
            _signal("speed_mps", "m/s", "real", "own speed"),
            _signal("gap_m", "m", "real", "bumper-to-bumper gap to the leader, +inf if none"),
            _signal("rel_speed_mps", "m/s", "real", "leader speed minus own speed, 0 if none"),
            _signal("lane_index", "-", "int", "own lane, 0 = rightmost"),
            _signal("has_leader", "-", "bool", "whether a leader is seen"),
            _signal("lane_width_m", "m", "real", "width of the own lane, NaN if unknown"),
            (
                "n_objects",
                Signal("n_objects", "-", "int", "entries in the object list", _n_objects),
            ),
            *(item for i in range(OBJECT_SLOTS) for item in _object_signals(i)),
        ]
    )
)

#: The signals a process gets when its config names none: the controller input's fields.
DEFAULT_SIGNALS: tuple[str, ...] = (
    "time_s",
    "dt_s",
    "speed_mps",
    "gap_m",
    "rel_speed_mps",
    "lane_index",
)


def check_signal(where: str, name: Any) -> Signal:
    """The signal called ``name``, or a :class:`ConfigError` naming ``where`` and the
    allowed names."""
    if not isinstance(name, str) or name not in SIGNALS:
        hint = suggest(name, set(SIGNALS)) if isinstance(name, str) else ""
        raise ConfigError(
            f"{where} must name a signal of the VUT's sensor view, got {name!r}{hint}; "
            f"allowed: {list(SIGNALS)}"
        )
    return SIGNALS[name]
