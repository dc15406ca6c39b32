"""Vehicle types: the VUT catalog, the POV type, their validation and their SUMO XML form.

A vehicle type is a SUMO car-following model plus its parameters, or a user's controller
(a Python object that returns an acceleration, see :mod:`sumo_ayss.controllers`) driving a
SUMO vehicle body. Validation happens here, in Python, before any SUMO simulation starts,
so that a typo or an out-of-range value gives an error that names the field, the allowed
values and their unit instead of a libsumo traceback (or, worse, SUMO silently ignoring the
attribute: SUMO drops a vType attribute the chosen model does not read without a word).

Which parameters each model reads was checked on SUMO 1.28 itself: a vType carrying every
candidate attribute was loaded per model and the attributes SUMO kept were read back from a
saved simulation state (``--save-state.files``), the same parser SUMO uses for route files.
The value ranges are SUMO's where SUMO has one (it refuses the value at load time, or its
XML schema ``data/xsd/types/route.xsd`` restricts it); a few are ours, marked "ours" in
:data:`PARAM_SPECS` with the reason (a value outside breaks the model's equations, SUMO
merely warns or misbehaves). ``PARAM_SPECS[name].source`` says which.

Units follow SUMO: lengths in m, speeds in m/s, accelerations in m/s², times in s.
Decelerations (``decel``, ``emergencyDecel``, ``apparentDecel``) are positive numbers.
"""

from __future__ import annotations

import contextlib
import contextvars
import difflib
import hashlib
import importlib
import importlib.util
import math
import sys
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any, Literal
from xml.sax.saxutils import quoteattr

from sumo_ayss.errors import ConfigError

Source = Literal["SUMO", "SUMO schema", "ours"]


@dataclass(frozen=True)
class ParamSpec:
    """Unit, meaning and allowed range of one vType parameter.

    Attributes:
        unit: SUMO's unit (``"m"``, ``"m/s"``, ``"m/s²"``, ``"s"``, ``"-"``).
        meaning: What the parameter does (shown in error messages and docs).
        low: Lower bound, or ``None`` for none.
        high: Upper bound, or ``None`` for none.
        low_open: The lower bound itself is not allowed (``> low``).
        high_open: The upper bound itself is not allowed (``< high``).
        integer: Only whole numbers (e.g. counts, 0/1 switches).
        source: Who sets the range: ``"SUMO"`` (SUMO 1.28 refuses other values at load
            time), ``"SUMO schema"`` (SUMO's XML schema restricts it; SUMO itself may accept
            and misbehave) or ``"ours"`` (the model's equations need it; see ``meaning``).
    """

    unit: str
    meaning: str
    low: float | None = None
    high: float | None = None
    low_open: bool = False
    high_open: bool = False
    integer: bool = False
    source: Source = "SUMO schema"

    def interval(self) -> str:
        """The allowed range in interval notation, e.g. ``(0, inf)`` or ``[0, 1]``."""
        lo = "-inf" if self.low is None else _fmt(self.low)
        hi = "inf" if self.high is None else _fmt(self.high)
        left = "(" if self.low is None or self.low_open else "["
        right = ")" if self.high is None or self.high_open else "]"
        kind = "integers in " if self.integer else ""
        return f"{kind}{left}{lo}, {hi}{right}"

    def condition(self) -> str:
        """Short condition for messages: ``> 0``, ``>= 0``, ``in [0, 1]``..."""
        if self.low is not None and self.high is None:
            return f"{'>' if self.low_open else '>='} {_fmt(self.low)}"
        if self.high is not None and self.low is None:
            return f"{'<' if self.high_open else '<='} {_fmt(self.high)}"
        return f"in {self.interval()}"

    def violation(self, value: float) -> str | None:
        """Why ``value`` is not allowed, or ``None`` if it is."""
        if self.integer and not float(value).is_integer():
            return "must be an integer"
        low_bad = self.low is not None and (
            value < self.low or (self.low_open and value == self.low)
        )
        high_bad = self.high is not None and (
            value > self.high or (self.high_open and value == self.high)
        )
        if low_bad or high_bad:
            return f"must be {self.condition()}"
        return None


def _p(unit: str, meaning: str, **kw: Any) -> ParamSpec:
    return ParamSpec(unit, meaning, **kw)


_POS: dict[str, Any] = {"low": 0.0, "low_open": True}
_NONNEG: dict[str, Any] = {"low": 0.0}
_UNIT: dict[str, Any] = {"low": 0.0, "high": 1.0}
_SWITCH: dict[str, Any] = {"low": 0.0, "high": 1.0, "integer": True}

#: Unit, meaning and range of every parameter in :data:`COMMON_PARAMS` and
#: :data:`MODEL_PARAMS`.
PARAM_SPECS: Mapping[str, ParamSpec] = MappingProxyType(
    {
        # --- every model (MSCFModel base) and the vehicle body -------------------------
        "accel": _p("m/s²", "maximum acceleration", **_POS, source="SUMO"),
        "decel": _p("m/s²", "comfortable deceleration (positive number)", **_POS, source="SUMO"),
        "emergencyDecel": _p(
            "m/s²", "physical braking limit (positive number)", **_POS, source="SUMO"
        ),
        "apparentDecel": _p(
            "m/s²", "deceleration the followers assume (positive number)", **_POS, source="SUMO"
        ),
        "tau": _p("s", "desired time headway (driver reaction time)", **_POS, source="SUMO"),
        "startupDelay": _p("s", "delay when starting from standstill", **_NONNEG),
        "minGap": _p("m", "standstill gap, bumper to bumper", **_NONNEG, source="SUMO"),
        "length": _p("m", "vehicle length", **_POS, source="SUMO"),
        "width": _p("m", "vehicle width", **_POS, source="SUMO"),
        "height": _p("m", "vehicle height (drawing only)", **_POS),
        "maxSpeed": _p("m/s", "maximum speed of the vehicle", **_POS, source="SUMO"),
        "desiredMaxSpeed": _p("m/s", "desired free speed (before speedFactor)", **_POS),
        "speedFactor": _p(
            "-",
            "multiplier on the lane speed limit (a number; SUMO's distributions are not "
            "supported here); ours: > 0, a vehicle with factor 0 never drives",
            **_POS,
            source="ours",
        ),
        "speedDev": _p("-", "standard deviation of speedFactor", **_NONNEG),
        "actionStepLength": _p(
            "s",
            "time between the driver's decisions; SUMO rounds it to a multiple of the "
            "step length (with a warning)",
            **_POS,
        ),
        "collisionMinGapFactor": _p(
            "-",
            "share of minGap that counts as a collision; the testbed's global "
            "--collision.mingap-factor (env.sim.collision_mingap_factor) overrides it",
            **_UNIT,
            source="ours",
        ),
        # --- Krauss family, SmartSK, Daniel1, PWagner2009 -----------------------------
        "sigma": _p("-", "driver imperfection (random deceleration)", **_UNIT, source="SUMO"),
        "sigmaStep": _p("s", "time between two draws of the imperfection noise", **_POS),
        "tmp1": _p("-", "model-specific parameter 1 (no documented range)"),
        "tmp2": _p("-", "model-specific parameter 2 (no documented range)"),
        "tmp3": _p("-", "model-specific parameter 3 (no documented range)"),
        "tmp4": _p("-", "model-specific parameter 4 (no documented range)"),
        "tmp5": _p("-", "model-specific parameter 5 (no documented range)"),
        # --- IDM, IDMM, EIDM -------------------------------------------------------------
        "delta": _p(
            "-",
            "acceleration exponent; ours: > 0, (v/v0)^delta needs a positive exponent "
            "(SUMO accepts any number and then brakes without cause)",
            **_POS,
            source="ours",
        ),
        "stepping": _p("s", "internal integration step of the model", **_POS, source="SUMO"),
        "adaptFactor": _p(
            "-",
            "IDMM: factor on the time headway in congestion; ours: > 0 (a time headway "
            "factor of 0 or below is meaningless)",
            **_POS,
            source="ours",
        ),
        "adaptTime": _p(
            "s",
            "IDMM: relaxation time of the adaptation; ours: > 0 (0 divides by zero; SUMO "
            "then brakes without cause)",
            **_POS,
            source="ours",
        ),
        "tPersDrive": _p("s", "EIDM: persistence of the driving (action point) error", **_POS),
        "tpreview": _p("s", "EIDM: look-ahead time", **_POS),
        "tPersEstimate": _p("s", "EIDM: persistence of the estimation error", **_POS),
        "treaction": _p("s", "EIDM: reaction time", **_NONNEG),
        "ccoolness": _p("-", "EIDM: coolness (constant-acceleration heuristic weight)", **_UNIT),
        "sigmaleader": _p("-", "EIDM: estimation error of the leader's speed", **_NONNEG),
        "sigmagap": _p("-", "EIDM: estimation error of the gap", **_NONNEG),
        "sigmaerror": _p("-", "EIDM: driving error", **_NONNEG),
        "jerkmax": _p("m/s³", "EIDM: maximum jerk", **_POS),
        "epsilonacc": _p("m/s²", "EIDM: acceleration threshold of the jerk limit", **_NONNEG),
        "taccmax": _p("s", "EIDM: time to reach maximum acceleration from standstill", **_NONNEG),
        "Mflatness": _p("-", "EIDM: flatness of the start-up acceleration profile", **_POS),
        "Mbegin": _p("-", "EIDM: start of the start-up acceleration profile", **_POS),
        "maxvehpreview": _p(
            "-", "EIDM: vehicles considered ahead", low=1.0, integer=True, source="SUMO schema"
        ),
        "vehdynamics": _p("-", "EIDM: vehicle dynamics on (1) or off (0)", **_SWITCH),
        # --- PWagner2009, BKerner, Wiedemann ----------------------------------------------
        "tauLast": _p(
            "s", "PWagner2009: time constant of the last action; ours: > 0", **_POS, source="ours"
        ),
        "apProb": _p("-", "PWagner2009: probability of a new action point", **_UNIT, source="ours"),
        "k": _p("-", "BKerner: Kerner's k (no documented range)"),
        "phi": _p("-", "BKerner: Kerner's phi (no documented range)"),
        "security": _p("-", "Wiedemann: desire for security (no documented range)"),
        "estimation": _p("-", "Wiedemann: accuracy of estimation (no documented range)"),
        # --- W99 (SUMO defaults in brackets; cc0 is SUMO's minGap) ----------------------
        "cc1": _p(
            "s",
            "W99: headway time [1.3]; ours: > 0, it is SUMO's tau for this model and SUMO "
            "refuses tau <= 0",
            **_POS,
            source="ours",
        ),
        "cc2": _p(
            "m",
            "W99: following variation, extra distance of the following zone [8.0]; ours: "
            ">= 0, the zone's upper limit is minGap + cc1·v + cc2",
            **_NONNEG,
            source="ours",
        ),
        "cc3": _p("s", "W99: threshold for entering 'following' [-12.0], normally negative"),
        "cc4": _p("m/s", "W99: negative 'following' threshold [-0.25], normally negative"),
        "cc5": _p(
            "m/s",
            "W99: positive 'following' threshold [0.35]; ours: >= 0, the opening-speed threshold",
            **_NONNEG,
            source="ours",
        ),
        "cc6": _p(
            "10⁻⁴ rad/s",
            "W99: speed dependency of the oscillation [6.0]; ours: >= 0, it scales a squared "
            "distance",
            **_NONNEG,
            source="ours",
        ),
        "cc7": _p(
            "m/s²",
            "W99: oscillation acceleration [0.25]; ours: >= 0, applied as -cc7 / +cc7",
            **_NONNEG,
            source="ours",
        ),
        "cc8": _p(
            "m/s²",
            "W99: standstill acceleration [2.0]; ours: > 0, it replaces accel, which SUMO "
            "requires > 0",
            **_POS,
            source="ours",
        ),
        "cc9": _p(
            "m/s²",
            "W99: acceleration at 80 km/h [1.5]; ours: >= 0, added to cc8 per m/s",
            **_NONNEG,
            source="ours",
        ),
        # --- ACC, CACC (SUMO defaults in brackets; gains may be negative) ------------------
        "speedControlGain": _p("1/s", "ACC: speed-control gain [-0.4]"),
        "gapClosingControlGainSpeed": _p("1/s", "ACC/CACC: gap-closing gain on speed [0.8]"),
        "gapClosingControlGainSpace": _p("1/s²", "ACC/CACC: gap-closing gain on space [0.04]"),
        "gapControlGainSpeed": _p("1/s", "ACC/CACC: gap-control gain on speed [0.07]"),
        "gapControlGainSpace": _p("1/s²", "ACC/CACC: gap-control gain on space [0.23]"),
        "collisionAvoidanceGainSpeed": _p("1/s", "ACC/CACC: collision-avoidance gain [0.8]"),
        "collisionAvoidanceGainSpace": _p("1/s²", "ACC/CACC: collision-avoidance gain [0.23]"),
        "collisionAvoidanceOverride": _p(
            "m/s", "ACC/CACC: speed deviation that triggers collision avoidance [2.0]"
        ),
        "applyDriverState": _p("-", "ACC/CACC: apply the driver-state model (1) or not", **_SWITCH),
        "speedControlGainCACC": _p("1/s", "CACC: speed-control gain [-0.4]"),
        "gapClosingControlGainGap": _p("1/s²", "CACC: gap-closing gain on the gap [0.005]"),
        "gapClosingControlGainGapDot": _p("1/s", "CACC: gap-closing gain on its rate [0.05]"),
        "gapControlGainGap": _p("1/s²", "CACC: gap-control gain on the gap [0.45]"),
        "gapControlGainGapDot": _p("1/s", "CACC: gap-control gain on its rate [0.0125]"),
        "collisionAvoidanceGainGap": _p("1/s²", "CACC: collision-avoidance gain [0.45]"),
        "collisionAvoidanceGainGapDot": _p("1/s", "CACC: collision-avoidance gain [0.05]"),
        "tauCACCToACC": _p(
            "s", "CACC: time gap when falling back to ACC [1.1]; ours: > 0", **_POS, source="ours"
        ),
        "speedControlMinGap": _p(
            "m",
            "CACC: gap above which speed control is used [1.66]; ours: >= 0",
            **_NONNEG,
            source="ours",
        ),
        # --- CC (Plexe cruise controllers) ------------------------------------------------
        "lanesCount": _p(
            "-",
            "CC: lanes of the road; SUMO refuses a CC vType without it (the range is ours: "
            "a road has at least one lane, SUMO accepts 0)",
            low=1.0,
            integer=True,
            source="ours",
        ),
        "ccDecel": _p("m/s²", "CC: cruise-control deceleration (positive number)", **_POS),
        "ccAccel": _p("m/s²", "CC: cruise-control acceleration", **_POS),
        "constSpacing": _p("m", "CC: constant spacing of the CACC", **_NONNEG),
        "c1": _p("-", "CC: weighting of leader vs. predecessor (CACC)", **_UNIT),
        "kp": _p("-", "CC: cruise-control gain (no documented range)"),
        "lambda": _p("-", "CC: ACC design parameter (no documented range)"),
        "omegaN": _p("rad/s", "CC: bandwidth of the CACC", **_POS),
        "xi": _p("-", "CC: damping ratio of the CACC", **_POS),
        "tauEngine": _p("s", "CC: engine time constant", **_POS),
        "ploegKp": _p("-", "CC: Ploeg's controller gain kp (no documented range)"),
        "ploegKd": _p("-", "CC: Ploeg's controller gain kd (no documented range)"),
        "ploegH": _p("s", "CC: Ploeg's time headway", **_POS),
        "flatbedKa": _p("-", "CC: flatbed controller gain ka (no documented range)"),
        "flatbedKv": _p("-", "CC: flatbed controller gain kv (no documented range)"),
        "flatbedKp": _p("-", "CC: flatbed controller gain kp (no documented range)"),
        "flatbedD": _p("m", "CC: flatbed distance (no documented range)"),
        "flatbedH": _p("s", "CC: flatbed headway (no documented range)"),
    }
)

#: vType attributes every SUMO car-following model reads (SUMO 1.28: kept for every model).
COMMON_PARAMS: frozenset[str] = frozenset(
    {
        "accel",
        "decel",
        "emergencyDecel",
        "apparentDecel",
        "startupDelay",
        "tau",
        "minGap",
        "length",
        "width",
        "height",
        "maxSpeed",
        "desiredMaxSpeed",
        "speedFactor",
        "speedDev",
        "actionStepLength",
        "collisionMinGapFactor",
    }
)

_KRAUSS = frozenset({"sigma", "sigmaStep"})
_TMP = frozenset({f"tmp{i}" for i in range(1, 6)})
_ACC_GAINS = frozenset(
    {
        "gapClosingControlGainSpeed",
        "gapClosingControlGainSpace",
        "gapControlGainSpeed",
        "gapControlGainSpace",
        "collisionAvoidanceGainSpeed",
        "collisionAvoidanceGainSpace",
        "collisionAvoidanceOverride",
        "applyDriverState",
    }
)

#: Model-specific parameters by SUMO ``carFollowModel`` name: the attributes SUMO 1.28 keeps
#: for that model beyond :data:`COMMON_PARAMS` (checked on SUMO itself, see the module
#: docstring). Every model of SUMO 1.28 is here except ``Rail`` (see
#: :data:`UNSUPPORTED_MODELS`).
MODEL_PARAMS: Mapping[str, frozenset[str]] = MappingProxyType(
    {
        "Krauss": _KRAUSS,
        "KraussOrig1": _KRAUSS,
        "KraussPS": _KRAUSS,
        "KraussX": _KRAUSS | _TMP,
        "SmartSK": frozenset({"sigma"}) | _TMP,
        "Daniel1": frozenset({"sigma"}) | _TMP,
        "PWagner2009": frozenset({"sigma", "tauLast", "apProb"}),
        "IDM": frozenset({"delta", "stepping"}),
        "IDMM": frozenset({"stepping", "adaptFactor", "adaptTime"}),
        "EIDM": frozenset(
            {
                "delta",
                "stepping",
                "tPersDrive",
                "tpreview",
                "tPersEstimate",
                "treaction",
                "ccoolness",
                "sigmaleader",
                "sigmagap",
                "sigmaerror",
                "jerkmax",
                "epsilonacc",
                "taccmax",
                "Mflatness",
                "Mbegin",
                "maxvehpreview",
                "vehdynamics",
            }
        ),
        "BKerner": frozenset({"k", "phi"}),
        "Wiedemann": frozenset({"security", "estimation"}),
        "W99": frozenset({f"cc{i}" for i in range(1, 10)}),
        "ACC": _ACC_GAINS | {"speedControlGain"},
        "CACC": _ACC_GAINS
        | {
            "speedControlGainCACC",
            "gapClosingControlGainGap",
            "gapClosingControlGainGapDot",
            "gapControlGainGap",
            "gapControlGainGapDot",
            "collisionAvoidanceGainGap",
            "collisionAvoidanceGainGapDot",
            "tauCACCToACC",
            "speedControlMinGap",
        },
        "CC": frozenset(
            {
                "lanesCount",
                "ccDecel",
                "ccAccel",
                "constSpacing",
                "c1",
                "kp",
                "lambda",
                "omegaN",
                "xi",
                "tauEngine",
                "ploegKp",
                "ploegKd",
                "ploegH",
                "flatbedKa",
                "flatbedKv",
                "flatbedKp",
                "flatbedD",
                "flatbedH",
            }
        ),
    }
)

#: Parameters a model cannot run without (SUMO refuses the vType otherwise).
REQUIRED_PARAMS: Mapping[str, frozenset[str]] = MappingProxyType({"CC": frozenset({"lanesCount"})})

#: SUMO 1.28 models that are not offered as VUTs, with the reason.
UNSUPPORTED_MODELS: Mapping[str, str] = MappingProxyType(
    {"Rail": "a train model (needs a trainType and a rail vehicle class), not a road vehicle"}
)

#: vType attributes a controller-driven VUT may set: its body. Its motion comes from the
#: controller, so car-following parameters would be silently ignored and are refused.
CONTROLLED_BODY_PARAMS: frozenset[str] = frozenset({"length", "width", "height", "minGap"})


def _suggest(name: str, allowed: set[str] | frozenset[str]) -> str:
    close = difflib.get_close_matches(name, sorted(allowed), n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""


def _check_number(key: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ConfigError(f"{key} must be a number, got {value!r}")
    if not math.isfinite(value):
        raise ConfigError(f"{key} must be finite, got {value!r}")
    return float(value)


def check_param(key: str, name: str, value: Any) -> None:
    """Raise :class:`ConfigError` if ``value`` is not allowed for parameter ``name``.

    Args:
        key: Dotted field name for the message (e.g. ``env.vuts.x.params.sigma``).
        name: The SUMO attribute name, a key of :data:`PARAM_SPECS`.
        value: The value to check.
    """
    number = _check_number(key, value)
    spec = PARAM_SPECS[name]
    why = spec.violation(number)
    if why is not None:
        raise ConfigError(
            f"{key} {why}, got {value!r}; allowed: {spec.interval()} {spec.unit} "
            f"({spec.meaning}; range from {spec.source})"
        )


# ------------------------------------------------------------------------------ controllers


@dataclass(frozen=True)
class ControllerSpec:
    """A user's controller as the VUT: what to import, its parameters, its declared limits.

    The object named by ``target`` is called with ``params`` as keyword arguments and must
    return an object with an ``acceleration(state) -> float`` method (and optionally
    ``reset()``), see :class:`sumo_ayss.controllers.Controller`. The testbed bounds every
    command to ``[-max_decel_mps2, max_accel_mps2]`` and the speed to
    ``[0, max_speed_mps]``.

    YAML (a VUT entry of ``env.vuts``)::

        acc_tg2:
          description: constant time-gap ACC, T = 2 s
          params: {length: 5.0}            # SUMO body only: length, width, height, minGap
          controller:
            target: examples.acc_controller:TimeGapACC
            params: {time_gap_s: 2.0}
            max_accel_mps2: 3.0
            max_decel_mps2: 6.0

    Attributes:
        target: ``"package.module:attr"`` (imported with :mod:`importlib`; the module must be
            importable, e.g. from the working directory or an installed package) or
            ``"path/to/file.py:attr"`` (a file, relative to the working directory).
            ``attr`` may be dotted (``module:Class.factory``).
        max_accel_mps2: Largest acceleration the vehicle can realise [m/s²], > 0.
        max_decel_mps2: Largest deceleration the vehicle can realise [m/s²], a positive
            number (commands below ``-max_decel_mps2`` are clipped to it).
        params: Keyword arguments of the target (JSON/YAML values).
        max_speed_mps: Top speed of the vehicle [m/s], > 0.
        sensor_range_m: The leader is seen up to this bumper-to-bumper gap [m], > 0.
    """

    target: str
    max_accel_mps2: float
    max_decel_mps2: float
    params: Mapping[str, Any] = field(default_factory=dict)
    max_speed_mps: float = 40.0
    sensor_range_m: float = 250.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "params", MappingProxyType(dict(self.params)))

    def validate(self, where: str) -> None:
        """Raise :class:`ConfigError` naming ``where`` if the limits or the target are bad.

        Imports the target and builds one controller from ``params`` (so a wrong parameter
        name fails here, not in the middle of a training run).
        """
        if not isinstance(self.target, str) or ":" not in self.target:
            raise ConfigError(
                f"{where}.target must be 'package.module:attr' or 'file.py:attr', "
                f"got {self.target!r}"
            )
        for name in ("max_accel_mps2", "max_decel_mps2", "max_speed_mps", "sensor_range_m"):
            value = _check_number(f"{where}.{name}", getattr(self, name))
            if value <= 0:
                raise ConfigError(f"{where}.{name} must be > 0, got {value!r}")
        if _CONTROLLER_IMPORTS.get():  # untrusted (a run folder): built only when needed
            self.build(where)

    def resolve(self, where: str = "controller") -> Any:
        """The object ``target`` names (a class or factory), imported.

        Raises:
            ConfigError: The target cannot be imported, or imports are not allowed here
                (inside ``controller_imports(False)``: a run folder opened untrusted).
        """
        if not _CONTROLLER_IMPORTS.get():
            raise ConfigError(
                f"{where}.target {self.target!r}: this VUT is a user controller, and importing "
                "it runs code named by the run folder; pass --trust-controller if you trust "
                "the folder (see 'Trust model' in the README)"
            )
        module_part, _, attr_part = self.target.rpartition(":")
        try:
            module = _import(module_part)
        except Exception as e:  # any error while importing user code
            raise ConfigError(
                f"{where}.target {self.target!r}: cannot import {module_part!r} "
                f"({type(e).__name__}: {e})"
            ) from e
        obj: Any = module
        for part in attr_part.split("."):
            if not hasattr(obj, part):
                raise ConfigError(
                    f"{where}.target {self.target!r}: {module_part!r} has no attribute "
                    f"{attr_part!r}"
                )
            obj = getattr(obj, part)
        if not callable(obj):
            raise ConfigError(f"{where}.target {self.target!r} is not callable")
        return obj

    def build(self, where: str = "controller") -> Any:
        """A new controller instance: ``target(**params)``, checked for ``acceleration``."""
        factory = self.resolve(where)
        try:
            controller = factory(**dict(self.params))
        except Exception as e:  # user code: report whatever it raised, with the field
            raise ConfigError(
                f"{where}.params {dict(self.params)!r} rejected by {self.target!r} "
                f"({type(e).__name__}: {e})"
            ) from e
        if not callable(getattr(controller, "acceleration", None)):
            raise ConfigError(
                f"{where}.target {self.target!r} built {type(controller).__name__}, which has "
                "no acceleration(state) method (see sumo_ayss.controllers.Controller)"
            )
        reset = getattr(controller, "reset", None)
        if reset is not None and not callable(reset):
            raise ConfigError(f"{where}: {type(controller).__name__}.reset is not callable")
        return controller

    def to_dict(self) -> dict[str, Any]:
        """Plain YAML-safe form (the inverse of :meth:`from_mapping`)."""
        return {
            "target": self.target,
            "params": dict(self.params),
            "max_accel_mps2": self.max_accel_mps2,
            "max_decel_mps2": self.max_decel_mps2,
            "max_speed_mps": self.max_speed_mps,
            "sensor_range_m": self.sensor_range_m,
        }

    @classmethod
    def from_mapping(cls, value: Any, where: str) -> ControllerSpec:
        """Build from a YAML mapping (keys as in :meth:`to_dict`; ``params`` optional)."""
        if not isinstance(value, Mapping):
            raise ConfigError(
                f"{where} must be a mapping with target, max_accel_mps2, max_decel_mps2 "
                f"(and optionally params, max_speed_mps, sensor_range_m), got {value!r}"
            )
        allowed = ["target", "params", "max_accel_mps2", "max_decel_mps2", "max_speed_mps"]
        allowed.append("sensor_range_m")
        for key in value:
            if key not in allowed:
                raise ConfigError(
                    f"{where}: unknown key {key!r}{_suggest(str(key), set(allowed))}; "
                    f"allowed: {sorted(allowed)}"
                )
        for key in ("target", "max_accel_mps2", "max_decel_mps2"):
            if key not in value:
                raise ConfigError(
                    f"{where}.{key} is required (a controller VUT declares what it is and "
                    "its acceleration limits)"
                )
        params = value.get("params", {}) or {}
        if not isinstance(params, Mapping):
            raise ConfigError(f"{where}.params must be a mapping, got {params!r}")
        kwargs = {k: value[k] for k in ("max_speed_mps", "sensor_range_m") if k in value}
        spec = cls(
            target=value["target"],
            max_accel_mps2=value["max_accel_mps2"],
            max_decel_mps2=value["max_decel_mps2"],
            params={str(k): v for k, v in params.items()},
            **kwargs,
        )
        spec.validate(where)
        return spec


#: Whether user controllers may be imported now (see :func:`controller_imports`).
_CONTROLLER_IMPORTS: contextvars.ContextVar[bool] = contextvars.ContextVar(
    "sumo_ayss_controller_imports", default=True
)


@contextlib.contextmanager
def controller_imports(allowed: bool) -> Iterator[None]:
    """Allow or forbid importing user controllers inside the ``with`` block.

    Configs a user writes import their controllers (to fail early on a bad target). A run
    folder's ``config.yaml`` is opened with ``allowed=False`` unless the user passed
    ``--trust-controller``: its controller targets are checked for form but not imported,
    and building one (an env whose VUT it drives) raises a :class:`ConfigError` naming the flag.
    """
    token = _CONTROLLER_IMPORTS.set(bool(allowed))
    try:
        yield
    finally:
        _CONTROLLER_IMPORTS.reset(token)


def _import(module_part: str) -> Any:
    """Import ``pkg.module``, or load ``path/to/file.py`` (relative to the working dir)."""
    if module_part.endswith(".py"):
        path = Path(module_part).expanduser().resolve()
        name = "sumo_ayss_user_" + hashlib.sha1(str(path).encode()).hexdigest()[:16]
        if name in sys.modules:
            return sys.modules[name]
        spec = importlib.util.spec_from_file_location(name, path)
        if spec is None or spec.loader is None:
            raise ImportError(f"no Python file at {path}")
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        try:
            spec.loader.exec_module(module)
        except BaseException:
            del sys.modules[name]
            raise
        return module
    return importlib.import_module(module_part)


# ------------------------------------------------------------------------------ vehicle types


@dataclass(frozen=True)
class VehicleType:
    """A SUMO vehicle type: car-following model and its parameters, or a user controller.

    Attributes:
        model: SUMO ``carFollowModel`` name, one of :data:`MODEL_PARAMS`. Irrelevant when
            ``controller`` is set (the controller drives; SUMO's own checks are off).
        params: vType attributes in SUMO's own names and units (``minGap`` in m, ``accel``
            in m/s², ``tau`` in s, ...). Anything not given keeps SUMO's default. With a
            controller only the body (:data:`CONTROLLED_BODY_PARAMS`) may be given.
        description: free text shown in reports (e.g. the paper's spacing s0).
        controller: a user's controller that drives this vehicle instead of SUMO's model,
            or ``None`` (SUMO's ``model`` drives).
    """

    model: str = "IDM"
    params: Mapping[str, float] = field(default_factory=dict)
    description: str = ""
    controller: ControllerSpec | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "params", MappingProxyType(dict(self.params)))

    def validate(self, where: str) -> None:
        """Raise :class:`ConfigError` naming ``where`` if the model or a parameter is bad.

        Messages name the dotted field, the allowed values or range with its unit, and a
        close match for a misspelt name.
        """
        if self.model not in MODEL_PARAMS:
            extra = (
                f" ({self.model} is {UNSUPPORTED_MODELS[self.model]})"
                if self.model in UNSUPPORTED_MODELS
                else _suggest(self.model, set(MODEL_PARAMS))
            )
            raise ConfigError(
                f"{where}.model must be one of {sorted(MODEL_PARAMS)}, got {self.model!r}{extra}"
            )
        allowed = COMMON_PARAMS | MODEL_PARAMS[self.model]
        for name, value in self.params.items():
            key = f"{where}.params.{name}"
            if name not in allowed:
                raise ConfigError(
                    f"{key} is not a parameter of SUMO model {self.model}"
                    f"{_suggest(name, allowed)}; allowed: {sorted(allowed)}"
                )
            check_param(key, name, value)
        decel = self.params.get("decel")
        emergency = self.params.get("emergencyDecel")
        if decel is not None and emergency is not None and emergency < decel:
            raise ConfigError(
                f"{where}.params.emergencyDecel must be >= decel ({decel}), got {emergency}"
            )
        if self.controller is None:
            for name in sorted(REQUIRED_PARAMS.get(self.model, frozenset())):
                if name not in self.params:
                    spec = PARAM_SPECS[name]
                    raise ConfigError(
                        f"{where}.params.{name} is required by SUMO model {self.model} "
                        f"({spec.meaning}; allowed: {spec.interval()})"
                    )
            return
        if not isinstance(self.controller, ControllerSpec):
            raise ConfigError(
                f"{where}.controller must be a ControllerSpec, got {self.controller!r}"
            )
        ignored = sorted(set(self.params) - CONTROLLED_BODY_PARAMS)
        if ignored:
            raise ConfigError(
                f"{where}.params {ignored} would be ignored: a controller VUT is driven by "
                f"its controller; only its body may be set ({sorted(CONTROLLED_BODY_PARAMS)}), "
                "its limits go into controller.max_accel_mps2 / max_decel_mps2"
            )
        self.controller.validate(f"{where}.controller")

    @property
    def length_m(self) -> float:
        """Vehicle length [m] (SUMO's passenger default 5 m when not given)."""
        return float(self.params.get("length", 5.0))

    def to_xml(self, type_id: str) -> str:
        """One ``<vType>`` element; parameters sorted for a stable file.

        A controller VUT gets SUMO's body only; its ``carFollowModel`` is written but never
        acts (the testbed commands its speed with SUMO's checks off).
        """
        attrs = " ".join(
            f"{name}={quoteattr(_fmt(value))}" for name, value in sorted(self.params.items())
        )
        sep = " " if attrs else ""
        return f'<vType id={quoteattr(type_id)} carFollowModel="{self.model}"{sep}{attrs}/>'

    def to_dict(self) -> dict[str, Any]:
        """Plain YAML-safe form; ``controller`` only when set (old run files stay valid)."""
        out: dict[str, Any] = {
            "model": self.model,
            "params": dict(self.params),
            "description": self.description,
        }
        if self.controller is not None:
            out["controller"] = self.controller.to_dict()
        return out

    @classmethod
    def from_mapping(cls, value: Any, where: str) -> VehicleType:
        """Build and validate a vehicle type from a YAML mapping.

        Keys: ``model`` (default ``IDM``), ``params`` (SUMO vType attributes),
        ``description``, ``controller`` (see :class:`ControllerSpec`). A
        :class:`VehicleType` is returned as is.
        """
        if isinstance(value, VehicleType):
            return value
        if not isinstance(value, Mapping):
            raise ConfigError(f"{where} must be a mapping with model and params, got {value!r}")
        allowed = ["model", "params", "description", "controller"]
        for key in value:
            if key not in allowed:
                raise ConfigError(
                    f"{where}: unknown key {key!r}{_suggest(str(key), set(allowed))}; "
                    f"allowed: {sorted(allowed)}"
                )
        params = value.get("params", {}) or {}
        if not isinstance(params, Mapping):
            raise ConfigError(f"{where}.params must be a mapping, got {params!r}")
        controller = value.get("controller")
        vt = cls(
            model=str(value.get("model", "IDM")),
            params={str(k): v for k, v in params.items()},
            description=str(value.get("description", "")),
            controller=(
                None
                if controller is None
                else ControllerSpec.from_mapping(controller, f"{where}.controller")
            ),
        )
        vt.validate(where)
        return vt


def _fmt(value: float) -> str:
    return repr(float(value)) if not float(value).is_integer() else str(int(value))


def _paper_idm(min_gap_m: float, spacing_m: float) -> VehicleType:
    # highway-env measures s0 centre to centre (s0 = minGap + one 5 m length); SUMO's minGap
    # is bumper to bumper, hence minGap = s0 - 5 m. All other values: highway-env defaults.
    return VehicleType(
        model="IDM",
        params={
            "accel": 3.0,
            "decel": 5.0,
            "emergencyDecel": 6.0,
            "tau": 1.5,
            "delta": 4.0,
            "minGap": min_gap_m,
            "length": 5.0,
            "speedDev": 0.0,
            "maxSpeed": 40.0,
        },
        description=f"paper IDM, spacing s0 = {spacing_m:g} m (SUMO minGap = {min_gap_m:g} m)",
    )


def _hwenv_idm(distance_wanted_m: float) -> VehicleType:
    # highway-env's own IDMVehicle law (sumo_ayss.hwenv_laws), not SUMO's IDM: centre-to-
    # centre distance, no zero clamp in the desired gap, +-6 m/s^2 clip, v0 = speed at the
    # episode start (clipped to 30 m/s), 15 Hz Euler. Body: highway-env's 5 m x 2 m.
    return VehicleType(
        model="IDM",
        params={"length": 5.0, "width": 2.0, "minGap": 0.0},
        description=(
            f"highway-env IDMVehicle, DISTANCE_WANTED = {distance_wanted_m:g} m "
            "(centre to centre; the paper's s0)"
        ),
        controller=ControllerSpec(
            target="sumo_ayss.hwenv_laws:HighwayEnvIDM",
            params={"distance_wanted_m": distance_wanted_m},
            max_accel_mps2=6.0,
            max_decel_mps2=6.0,
            max_speed_mps=40.0,
        ),
    )


#: The paper's two VUTs (Table I): pi1 (s0 = 10 m) and pi2 (s0 = 20 m), as SUMO's IDM
#: (``pi1``/``pi2``, s0 converted to minGap) and as highway-env's own IDMVehicle law
#: (``hwenv_pi1``/``hwenv_pi2``, DISTANCE_WANTED 10 / 20 m; the paper-fidelity mode).
BUILTIN_VUTS: Mapping[str, VehicleType] = MappingProxyType(
    {
        "pi1": _paper_idm(5.0, 10.0),
        "pi2": _paper_idm(15.0, 20.0),
        "hwenv_pi1": _hwenv_idm(10.0),
        "hwenv_pi2": _hwenv_idm(20.0),
    }
)

#: The POV: speed and lane are commanded by our actuator, SUMO's own checks are off, so the
#: model only matters for length/width. maxSpeed 40 m/s = the upper end of the VUT ODD.
POV_TYPE = VehicleType(
    model="Krauss",
    params={
        "length": 5.0,
        "minGap": 0.0,
        "accel": 6.0,
        "decel": 6.0,
        "emergencyDecel": 6.0,
        "maxSpeed": 40.0,
        "speedDev": 0.0,
        "sigma": 0.0,
    },
    description="principal other vehicle, driven by the RL policy through our actuator",
)


def vtypes_xml(types: Mapping[str, VehicleType]) -> str:
    """An ``<additional>`` document holding one ``<vType>`` per entry of ``types``."""
    lines = ["<?xml version='1.0' encoding='UTF-8'?>", "<additional>"]
    lines += [f"    {vt.to_xml(type_id)}" for type_id, vt in types.items()]
    lines.append("</additional>")
    return "\n".join(lines) + "\n"
