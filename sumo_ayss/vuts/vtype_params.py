"""SUMO vehicle-type parameters: their units, meanings and allowed ranges, and which
car-following model reads which (the data behind :mod:`sumo_ayss.vuts.catalog`'s validation).

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

import math
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any, Literal

from sumo_ayss.util.errors import ConfigError

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
        lo = "-inf" if self.low is None else fmt_number(self.low)
        hi = "inf" if self.high is None else fmt_number(self.high)
        left = "(" if self.low is None or self.low_open else "["
        right = ")" if self.high is None or self.high_open else "]"
        kind = "integers in " if self.integer else ""
        return f"{kind}{left}{lo}, {hi}{right}"

    def condition(self) -> str:
        """Short condition for messages: ``> 0``, ``>= 0``, ``in [0, 1]``..."""
        if self.low is not None and self.high is None:
            return f"{'>' if self.low_open else '>='} {fmt_number(self.low)}"
        if self.high is not None and self.low is None:
            return f"{'<' if self.high_open else '<='} {fmt_number(self.high)}"
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

_LENGTH = (
    "vehicle length; ours: <= 30 m, above any truck with trailers on European roads "
    "(18.75 m): a longer body is a unit slip"
)
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
        "length": _p("m", _LENGTH, **_POS, high=30.0, source="ours"),  # SUMO: > 0 only
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

#: Noise parameters: a vehicle draws random numbers while one is > 0, and SUMO's default
#: when it is not given is > 0 (Krauss family, SmartSK, Daniel1, PWagner2009: sigma 0.5;
#: EIDM: its three sigmas). ``speedDev`` (every model; default 0.1) draws the vehicle's
#: speed factor.
NOISE_PARAMS: frozenset[str] = frozenset({"sigma", "sigmaerror", "sigmagap", "sigmaleader"})

#: Models whose trajectories depend on SUMO's ``--seed`` even with every noise parameter and
#: speedDev at 0 (measured on SUMO 1.28 with the testbed's car-following env: the same
#: scenarios and POV actions on seeds 1 and 2 gave other episodes;
#: tests/test_vut_equivalence.py keeps this list honest).
ALWAYS_RANDOM_MODELS: frozenset[str] = frozenset({"BKerner", "CC", "PWagner2009", "W99"})


def random_draws(model: str, params: Mapping[str, float]) -> tuple[str, ...]:
    """Why a SUMO vType draws random numbers, one phrase per reason (empty: it draws none).

    Such a VUT is the same vehicle on every path of the testbed, but SUMO draws its numbers
    from streams shared by all vehicles of a simulation: the single env and N pairs in one
    simulation draw different numbers, so their episodes agree in distribution, not one for
    one. The outcome stage and cross-play drive the same path on the same SUMO seed and
    agree exactly.
    """
    reasons = []
    dev = params.get("speedDev")
    if dev is None or dev > 0:
        shown = "SUMO's default 0.1" if dev is None else f"{dev:g}"
        reasons.append(f"speedDev {shown} (a random speed factor per vehicle)")
    for name in sorted(NOISE_PARAMS & MODEL_PARAMS.get(model, frozenset())):
        value = params.get(name)
        if value is None or value > 0:
            shown = "SUMO's default > 0" if value is None else f"{value:g}"
            reasons.append(f"{name} {shown} (driver noise)")
    if model in ALWAYS_RANDOM_MODELS:
        reasons.append(f"model {model} (draws random numbers whatever its parameters)")
    return tuple(reasons)


#: Parameters a model cannot run without (SUMO refuses the vType otherwise).
REQUIRED_PARAMS: Mapping[str, frozenset[str]] = MappingProxyType({"CC": frozenset({"lanesCount"})})

#: SUMO 1.28 models that are not offered as VUTs, with the reason.
UNSUPPORTED_MODELS: Mapping[str, str] = MappingProxyType(
    {"Rail": "a train model (needs a trainType and a rail vehicle class), not a road vehicle"}
)

#: vType attributes a controller-driven VUT may set: its body. Its motion comes from the
#: controller, so car-following parameters would be silently ignored and are refused.
CONTROLLED_BODY_PARAMS: frozenset[str] = frozenset({"length", "width", "height", "minGap"})


def as_number(key: str, value: Any) -> float:
    """``value`` as a float; a ConfigError naming ``key`` unless it is a finite number."""
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
    number = as_number(key, value)
    spec = PARAM_SPECS[name]
    why = spec.violation(number)
    if why is not None:
        raise ConfigError(
            f"{key} {why}, got {value!r}; allowed: {spec.interval()} {spec.unit} "
            f"({spec.meaning}; range from {spec.source})"
        )


def fmt_number(value: float) -> str:
    """``5`` for 5.0, ``0.25`` for 0.25: the shortest exact text of a parameter value."""
    return repr(float(value)) if not float(value).is_integer() else str(int(value))
