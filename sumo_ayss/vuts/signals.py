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
==================  ======  =====  =========================================================

**Adding signals.** A signal is one entry of :data:`SIGNALS`: a name, a unit, a kind and a
function of the controller input. A richer sensor view (an object list of nearby vehicles)
adds one entry per object slot and field, e.g. ``objects.0.gap_m``,
``objects.0.lateral_offset_m``, ... for slots ``0..N-1`` with a fixed default for an
empty slot; FMUs and processes can then name them like any other signal, and nothing else
changes (the FMU maps by name, the process protocol sends the names it was told).
"""

from __future__ import annotations

import operator
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, Literal

from sumo_ayss.util.errors import ConfigError
from sumo_ayss.util.frozen import FrozenMap
from sumo_ayss.util.validation import suggest

__all__ = ["DEFAULT_SIGNALS", "SIGNALS", "Signal", "SignalKind", "check_signal"]

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
