"""Vehicle types: the VUT catalog, the POV type, their validation and their SUMO XML form.

A vehicle type is a SUMO car-following model plus its parameters. Validation happens here,
in Python, before any SUMO simulation starts, so that a typo gives an error that names the
field and the allowed values instead of a libsumo traceback.

Units follow SUMO: lengths in m, speeds in m/s, accelerations in m/s², times in s.
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from xml.sax.saxutils import quoteattr

from sumo_ayss.errors import ConfigError

#: Attributes every SUMO car-following model accepts (vType attributes).
COMMON_PARAMS: frozenset[str] = frozenset(
    {
        "accel",  # [m/s²] maximum acceleration
        "decel",  # [m/s²] comfortable deceleration (positive number)
        "emergencyDecel",  # [m/s²] physical braking limit (positive number)
        "apparentDecel",  # [m/s²] deceleration the followers assume
        "startupDelay",  # [s]
        "tau",  # [s] desired time headway
        "minGap",  # [m] standstill gap, bumper to bumper
        "length",  # [m]
        "width",  # [m]
        "maxSpeed",  # [m/s]
        "speedFactor",  # [-] multiplier on the lane speed limit
        "speedDev",  # [-] deviation of speedFactor
        "actionStepLength",  # [s]
        "sigma",  # [-] driver imperfection (models that use it)
    }
)

#: Model-specific parameters, by SUMO ``carFollowModel`` name (SUMO 1.28 vType docs).
MODEL_PARAMS: Mapping[str, frozenset[str]] = MappingProxyType(
    {
        "Krauss": frozenset({"sigmaStep"}),
        "KraussOrig1": frozenset({"sigmaStep"}),
        "KraussPS": frozenset({"sigmaStep"}),
        "KraussX": frozenset({"sigmaStep", "tmp1", "tmp2"}),
        "SKOrig": frozenset(),
        "IDM": frozenset({"delta", "stepping"}),
        "IIDM": frozenset({"delta", "stepping"}),
        "IDMM": frozenset({"delta", "stepping", "adaptFactor", "adaptTime"}),
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
        "ACC": frozenset(
            {
                "speedControlGainSpeed",
                "gapControlGainSpeed",
                "gapControlGainSpace",
                "collisionAvoidanceGainSpeed",
                "collisionAvoidanceGainSpace",
                "speedControlMinGap",
                "applyDriverstate",
            }
        ),
        "CACC": frozenset(
            {
                "speedControlGainCACC",
                "gapClosingControlGainGap",
                "gapClosingControlGainGapDot",
                "gapControlGainGap",
                "gapControlGainGapDot",
                "collisionAvoidanceGainGap",
                "collisionAvoidanceGainGapDot",
                "tauCACCToACC",
                "speedControlGainSpeed",
                "gapControlGainSpeed",
                "gapControlGainSpace",
                "collisionAvoidanceGainSpeed",
                "collisionAvoidanceGainSpace",
                "speedControlMinGap",
                "applyDriverstate",
            }
        ),
        "W99": frozenset({f"cc{i}" for i in range(1, 10)}),
        "Wiedemann": frozenset({"security", "estimation"}),
        "BKerner": frozenset({"k", "phi"}),
        "SmartSK": frozenset({f"tmp{i}" for i in range(1, 6)}),
        "Daniel1": frozenset({f"tmp{i}" for i in range(1, 6)}),
        "PWagner2009": frozenset({"taulast", "apProb"}),
    }
)

#: Lower bounds (inclusive unless marked strict) of the common numeric parameters.
_POSITIVE = frozenset({"accel", "decel", "emergencyDecel", "apparentDecel", "tau", "length"})
_NON_NEGATIVE = frozenset(
    {"minGap", "speedDev", "startupDelay", "sigma", "maxSpeed", "speedFactor", "width"}
)


def _suggest(name: str, allowed: set[str] | frozenset[str]) -> str:
    close = difflib.get_close_matches(name, sorted(allowed), n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""


@dataclass(frozen=True)
class VehicleType:
    """A SUMO vehicle type: car-following model and its parameters.

    Attributes:
        model: SUMO ``carFollowModel`` name, one of :data:`MODEL_PARAMS`.
        params: vType attributes in SUMO's own names and units (``minGap`` in m, ``accel``
            in m/s², ``tau`` in s, ...). Anything not given keeps SUMO's default.
        description: free text shown in reports (e.g. the paper's spacing s0).
    """

    model: str = "IDM"
    params: Mapping[str, float] = field(default_factory=dict)
    description: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "params", MappingProxyType(dict(self.params)))

    def validate(self, where: str) -> None:
        """Raise :class:`ConfigError` naming ``where`` if the model or a parameter is bad."""
        if self.model not in MODEL_PARAMS:
            raise ConfigError(
                f"{where}.model must be one of {sorted(MODEL_PARAMS)}, got {self.model!r}"
                f"{_suggest(self.model, set(MODEL_PARAMS))}"
            )
        allowed = COMMON_PARAMS | MODEL_PARAMS[self.model]
        for name, value in self.params.items():
            key = f"{where}.params.{name}"
            if name not in allowed:
                raise ConfigError(
                    f"{key} is not a parameter of SUMO model {self.model}"
                    f"{_suggest(name, allowed)}; allowed: {sorted(allowed)}"
                )
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise ConfigError(f"{key} must be a number, got {value!r}")
            if not math.isfinite(value):
                raise ConfigError(f"{key} must be finite, got {value!r}")
            if name in _POSITIVE and value <= 0:
                raise ConfigError(f"{key} must be > 0, got {value!r}")
            if name in _NON_NEGATIVE and value < 0:
                raise ConfigError(f"{key} must be >= 0, got {value!r}")
        decel = self.params.get("decel")
        emergency = self.params.get("emergencyDecel")
        if decel is not None and emergency is not None and emergency < decel:
            raise ConfigError(
                f"{where}.params.emergencyDecel must be >= decel ({decel}), got {emergency}"
            )

    @property
    def length_m(self) -> float:
        """Vehicle length [m] (SUMO's passenger default 5 m when not given)."""
        return float(self.params.get("length", 5.0))

    def to_xml(self, type_id: str) -> str:
        """One ``<vType>`` element; parameters sorted for a stable file."""
        attrs = " ".join(
            f"{name}={quoteattr(_fmt(value))}" for name, value in sorted(self.params.items())
        )
        return f'<vType id={quoteattr(type_id)} carFollowModel="{self.model}" {attrs}/>'


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


#: The paper's two VUTs (Table I): pi1 (s0 = 10 m) and pi2 (s0 = 20 m).
BUILTIN_VUTS: Mapping[str, VehicleType] = MappingProxyType(
    {"pi1": _paper_idm(5.0, 10.0), "pi2": _paper_idm(15.0, 20.0)}
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
