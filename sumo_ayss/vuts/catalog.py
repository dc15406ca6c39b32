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

import contextlib
import contextvars
import hashlib
import importlib
import importlib.util
import inspect
import sys
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any
from xml.sax.saxutils import quoteattr

from sumo_ayss.util.errors import ConfigError
from sumo_ayss.util.frozen import FrozenMap
from sumo_ayss.util.validation import check_keys, suggest
from sumo_ayss.vuts.vtype_params import (
    COMMON_PARAMS,
    CONTROLLED_BODY_PARAMS,
    MODEL_PARAMS,
    PARAM_SPECS,
    REQUIRED_PARAMS,
    UNSUPPORTED_MODELS,
    as_number,
    check_param,
    fmt_number,
    random_draws,
)

# ------------------------------------------------------------------------------ controllers


@dataclass(frozen=True)
class ControllerSpec:
    """A user's controller as the VUT: what to import, its parameters, its declared limits.

    The object named by ``target`` is called with ``params`` as keyword arguments and must
    return an object with an ``acceleration(state) -> float`` method (and optionally
    ``reset()``), see :class:`sumo_ayss.vuts.controllers.Controller`. The testbed bounds every
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
            ``"path/to/file.py:attr"`` (a file; relative to the YAML file that names it).
            ``attr`` may be dotted (``module:Outer.Inner``); it must name a class with an
            ``acceleration(state)`` method, checked before the class is instantiated.
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
        object.__setattr__(self, "params", FrozenMap(dict(self.params)))

    def validate(self, where: str) -> None:
        """Raise :class:`ConfigError` naming ``where`` if the limits or the target's form
        are bad.

        Reading a config runs no user code: the target is imported, and the controller
        built from ``params``, when an env that drives this VUT is built (:meth:`build`,
        at the start of a run, so a wrong target or parameter still fails before training).
        """
        if not isinstance(self.target, str) or ":" not in self.target:
            raise ConfigError(
                f"{where}.target must be 'package.module:attr' or 'file.py:attr', "
                f"got {self.target!r}"
            )
        for name in ("max_accel_mps2", "max_decel_mps2", "max_speed_mps", "sensor_range_m"):
            value = as_number(f"{where}.{name}", getattr(self, name))
            if value <= 0:
                raise ConfigError(f"{where}.{name} must be > 0, got {value!r}")
        if not isinstance(self.params, Mapping):
            raise ConfigError(f"{where}.params must be a mapping, got {self.params!r}")

    def resolve(self, where: str = "controller") -> type:
        """The class ``target`` names, imported; nothing of it is called.

        Raises:
            ConfigError: The target cannot be imported, imports are not allowed here
                (``controller_imports(False)``: a run folder opened untrusted), or it is not
                a class with a callable ``acceleration`` (``subprocess:getoutput`` is not).
        """
        if not _CONTROLLER_IMPORTS.get() and not self.target.startswith("sumo_ayss."):
            raise ConfigError(
                f"{where}.target {self.target!r}: this VUT is a user controller, and importing "
                "it runs code named by the run folder; pass --trust-controller if you trust "
                "the folder (see 'Trust model' in the README; sumo_ayss.* is always allowed)"
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
        method = inspect.getattr_static(obj, "acceleration", None)  # runs no descriptor
        if isinstance(method, staticmethod | classmethod):
            method = method.__func__
        if not inspect.isclass(obj) or not callable(method):
            kind = "function" if inspect.isroutine(obj) else type(obj).__name__
            what = (
                f"the class {obj.__name__}, which has no"
                if inspect.isclass(obj)
                else f"a {kind}, not a class with an"
            )
            raise ConfigError(
                f"{where}.target {self.target!r} is {what} acceleration(state) method (see "
                "sumo_ayss.vuts.controllers.Controller)"
            )
        return obj

    def build(self, where: str = "controller") -> Any:
        """A new controller instance: ``target(**params)``; the target is checked to be a
        class with ``acceleration`` first (:meth:`resolve`), the instance after."""
        cls = self.resolve(where)
        try:
            controller = cls(**dict(self.params))
        except Exception as e:  # user code: report whatever it raised, with the field
            raise ConfigError(
                f"{where}.params {dict(self.params)!r} rejected by {self.target!r} "
                f"({type(e).__name__}: {e})"
            ) from e
        if not callable(getattr(controller, "acceleration", None)):
            raise ConfigError(
                f"{where}.target {self.target!r} built {type(controller).__name__}, which has "
                "no acceleration(state) method (see sumo_ayss.vuts.controllers.Controller)"
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
        check_keys(
            where,
            value,
            (
                "target",
                "params",
                "max_accel_mps2",
                "max_decel_mps2",
                "max_speed_mps",
                "sensor_range_m",
            ),
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

    Reading a config never imports a controller; building an env whose VUT it drives does
    (:meth:`ControllerSpec.build`). Configs a user passes (``train``, ``pipeline``) are
    trusted; a run folder's ``config.yaml`` is evaluated or replayed with ``allowed=False``
    unless the user passed ``--trust-controller``, and building such an env then raises a
    :class:`ConfigError` naming the flag.
    """
    token = _CONTROLLER_IMPORTS.set(bool(allowed))
    try:
        yield
    finally:
        _CONTROLLER_IMPORTS.reset(token)


def _import(module_part: str) -> Any:
    """Import ``pkg.module``, or load ``path/to/file.py`` (made absolute by the config)."""
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
        self.controller.validate(f"{where}.controller")

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
        check_keys(where, value, ("model", "params", "description", "controller"))
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
