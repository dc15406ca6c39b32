"""Vehicle types: the VUT catalog, the POV type, their validation and their SUMO XML form.

A vehicle type is a SUMO car-following model plus its parameters, or a user's controller
(a Python object that returns an acceleration, see :mod:`sumo_ayss.vuts.controllers`) driving a
SUMO vehicle body. Validation happens here, in Python, before any SUMO simulation starts,
so that a typo or an out-of-range value gives an error that names the field, the allowed
values and their unit instead of a libsumo traceback (or, worse, SUMO silently ignoring the
attribute: SUMO drops a vType attribute the chosen model does not read without a word).
Which model reads which parameter, and their ranges: :mod:`sumo_ayss.vuts.vtype_params`.

A user controller is checked for form when a config is read; it is imported (its code run)
only when an env that drives it is built (:meth:`ControllerSpec.build`).

Units follow SUMO: lengths in m, speeds in m/s, accelerations in m/s², times in s.
Decelerations (``decel``, ``emergencyDecel``, ``apparentDecel``) are positive numbers.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any
from xml.sax.saxutils import quoteattr

from sumo_ayss.util.errors import ConfigError
from sumo_ayss.util.frozen import FrozenMap
from sumo_ayss.util.validation import check_keys, suggest
from sumo_ayss.vuts.controller_spec import ControllerSpec as ControllerSpec
from sumo_ayss.vuts.controller_spec import controller_imports as controller_imports
from sumo_ayss.vuts.fmu_spec import FmuSpec
from sumo_ayss.vuts.process_spec import ProcessSpec
from sumo_ayss.vuts.vtype_params import (
    COMMON_PARAMS,
    CONTROLLED_BODY_PARAMS,
    MODEL_PARAMS,
    PARAM_SPECS,
    REQUIRED_PARAMS,
    UNSUPPORTED_MODELS,
    check_param,
    fmt_number,
    random_draws,
)

#: The keys of a VUT entry that name what drives it instead of a SUMO model, and the record
#: each is read into: a Python class, an FMI co-simulation FMU, an external process.
DRIVER_KEYS: Mapping[str, type[ControllerSpec]] = FrozenMap(
    {"controller": ControllerSpec, "fmu": FmuSpec, "process": ProcessSpec}
)


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
            or ``None`` (SUMO's ``model`` drives). An FMU (:class:`FmuSpec`, YAML key
            ``fmu``) and an external process (:class:`ProcessSpec`, key ``process``) are
            controllers too: the same limits, the same execution.
    """

    model: str = "IDM"
    params: Mapping[str, float] = field(default_factory=dict)
    description: str = ""
    controller: ControllerSpec | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "params", FrozenMap(dict(self.params)))

    def validate(self, where: str) -> None:
        """Raise :class:`ConfigError` naming ``where`` if the model or a parameter is bad.

        Messages name the dotted field, the allowed values or range with its unit, and a
        close match for a misspelt name.
        """
        if self.model not in MODEL_PARAMS:
            extra = (
                f" ({self.model} is {UNSUPPORTED_MODELS[self.model]})"
                if self.model in UNSUPPORTED_MODELS
                else suggest(self.model, set(MODEL_PARAMS))
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
                    f"{suggest(name, allowed)}; allowed: {sorted(allowed)}"
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
        self.controller.validate(f"{where}.{self.controller.yaml_key}")

    def random_draws(self) -> tuple[str, ...]:
        """Why SUMO draws random numbers for this vehicle (empty: none; a controller VUT is
        the controller's business). See :func:`sumo_ayss.vuts.vtype_params.random_draws`."""
        if self.controller is not None:
            return ()
        return random_draws(self.model, self.params)

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
            f"{name}={quoteattr(fmt_number(value))}" for name, value in sorted(self.params.items())
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
            out[self.controller.yaml_key] = self.controller.to_dict()
        return out

    @classmethod
    def from_mapping(cls, value: Any, where: str) -> VehicleType:
        """Build and validate a vehicle type from a YAML mapping.

        Keys: ``model`` (default ``IDM``), ``params`` (SUMO vType attributes),
        ``description``, and at most one of ``controller`` (:class:`ControllerSpec`),
        ``fmu`` (:class:`FmuSpec`), ``process`` (:class:`ProcessSpec`). A
        :class:`VehicleType` is returned as is.
        """
        if isinstance(value, VehicleType):
            return value
        if not isinstance(value, Mapping):
            raise ConfigError(f"{where} must be a mapping with model and params, got {value!r}")
        check_keys(where, value, ("model", "params", "description", *DRIVER_KEYS))
        drivers = [key for key in DRIVER_KEYS if value.get(key) is not None]
        if len(drivers) > 1:
            raise ConfigError(
                f"{where} names {drivers}: a VUT is driven by one of {list(DRIVER_KEYS)}"
            )
        params = value.get("params", {}) or {}
        if not isinstance(params, Mapping):
            raise ConfigError(f"{where}.params must be a mapping, got {params!r}")
        key = drivers[0] if drivers else "controller"
        controller = value.get(key)
        vt = cls(
            model=str(value.get("model", "IDM")),
            params={str(k): v for k, v in params.items()},
            description=str(value.get("description", "")),
            controller=(
                None
                if controller is None
                else DRIVER_KEYS[key].from_mapping(controller, f"{where}.{key}")
            ),
        )
        vt.validate(where)
        return vt


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
    # highway-env's own IDMVehicle law (sumo_ayss.laws.hwenv), not SUMO's IDM: centre-to-
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
            target="highway_env_idm",
            params={"distance_wanted_m": distance_wanted_m},
            max_accel_mps2=6.0,
            max_decel_mps2=6.0,
            max_speed_mps=40.0,
        ),
    )


#: The paper's two VUTs (Table I): pi1 (s0 = 10 m) and pi2 (s0 = 20 m), as SUMO's IDM
#: (``pi1``/``pi2``, s0 converted to minGap) and as highway-env's own IDMVehicle law
#: (``hwenv_pi1``/``hwenv_pi2``, DISTANCE_WANTED 10 / 20 m; the paper-fidelity mode).
BUILTIN_VUTS: Mapping[str, VehicleType] = FrozenMap(
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


def stored_description(env: Mapping[str, Any], vut: str) -> str:
    """A VUT's description as a stored ``env`` section's catalog holds it (a run's
    ``config.yaml``): its ``description``, else its model with ``minGap`` and ``tau``; "" if
    the catalog has no such entry."""
    vuts = env.get("vuts")
    entry = vuts.get(vut) if isinstance(vuts, Mapping) else None
    if not isinstance(entry, Mapping):
        return ""
    if entry.get("description"):
        return str(entry["description"])
    params = entry.get("params") or {}
    shown = ", ".join(f"{k}={v}" for k, v in sorted(params.items()) if k in ("minGap", "tau"))
    return f"{entry.get('model', '?')}" + (f" ({shown})" if shown else "")
