"""A user's Python controller as the VUT: its configuration record and the trust gate.

:class:`ControllerSpec` names the class to import, its parameters and the vehicle's declared
limits; :func:`controller_imports` decides whether user code named by a configuration may be
run now. The FMU and external-process VUTs (:mod:`sumo_ayss.vuts.fmu_spec`,
:mod:`sumo_ayss.vuts.process_spec`) are specialisations of :class:`ControllerSpec`: the same
limits and the same execution (:class:`~sumo_ayss.vuts.controllers.ControlledVut`), another
way to build the object that answers ``acceleration(state)``.

Units: accelerations m/s² (decelerations positive numbers), speeds m/s, lengths m, times s.
"""

from __future__ import annotations

import contextlib
import contextvars
import dataclasses
import hashlib
import importlib
import importlib.util
import inspect
import sys
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

from sumo_ayss.util.errors import ConfigError
from sumo_ayss.util.frozen import FrozenMap
from sumo_ayss.util.registry import Registry
from sumo_ayss.util.validation import check_keys
from sumo_ayss.vuts.vtype_params import as_number

__all__ = [
    "CONTROLLERS",
    "DEFAULT_CALL_DEADLINE_S",
    "TARGET_ALIASES",
    "ControllerSpec",
    "check_imports_allowed",
    "controller_imports",
    "controller_imports_allowed",
    "identity_target",
    "registered_target",
]

#: The package's own controllers by registered name -> the class each names
#: (``"module:attr"``). A configuration (and so every run folder's ``config.yaml`` written
#: from now) names one of them by this name as its ``controller.target``, never by a module
#: path: a class may move without the stored configs changing.
CONTROLLERS: Registry[str] = Registry("controller")
for _name, _path in (
    ("highway_env_idm", "sumo_ayss.laws.hwenv:HighwayEnvIDM"),
    ("careful_driver", "sumo_ayss.vuts.reference:CarefulDriver"),
    ("fuzzy_safety_driver", "sumo_ayss.vuts.reference:FuzzySafetyDriver"),
    ("rss_driver", "sumo_ayss.vuts.reference:RssDriver"),
    ("full_braking", "sumo_ayss.vuts.reference:FullBraking"),
    ("over_braker", "sumo_ayss.vuts.overbraking:OverBraker"),
):
    CONTROLLERS.register(_name, _path)

#: Targets stored by run folders written before the registered names (module paths, one of
#: them, ``sumo_ayss.hwenv_laws``, no longer a module) -> the registered name they mean.
#: A :class:`ControllerSpec` read with one of them holds the registered name; the first path
#: of each name is also the form run identities and definition keys are computed over
#: (:func:`identity_target`), so records written before keep matching.
TARGET_ALIASES: Mapping[str, str] = FrozenMap(
    {
        "sumo_ayss.hwenv_laws:HighwayEnvIDM": "highway_env_idm",
        "sumo_ayss.laws.hwenv:HighwayEnvIDM": "highway_env_idm",
        "sumo_ayss.vuts.reference:CarefulDriver": "careful_driver",
        "sumo_ayss.vuts.reference:FuzzySafetyDriver": "fuzzy_safety_driver",
        "sumo_ayss.vuts.reference:RssDriver": "rss_driver",
        "sumo_ayss.vuts.reference:FullBraking": "full_braking",
        "sumo_ayss.vuts.overbraking:OverBraker": "over_braker",
    }
)

_KEYED_AS: dict[str, str] = {}  # registered name -> the first path it was stored as
for _path, _name in TARGET_ALIASES.items():
    _KEYED_AS.setdefault(_name, _path)


def registered_target(target: str) -> str:
    """A stored ``controller.target`` as a configuration names it now: an old module path
    of a registered controller (:data:`TARGET_ALIASES`) -> its registered name; anything
    else (a registered name, a user's ``module:attr`` or ``file.py:attr``) unchanged."""
    return TARGET_ALIASES.get(target, target) if isinstance(target, str) else target


def identity_target(target: str) -> str:
    """The form of ``target`` that run identities and VUT definition keys are computed over
    (:mod:`sumo_ayss.run_folder.identity`): a registered name that run folders stored as a
    module path before keeps that path's form, so their fingerprints, ``crossplay.json``'s
    ``vut_keys`` and ``adaptive.json`` still match; any other target as it is."""
    return _KEYED_AS.get(target, target)


#: Default per-call deadline of every VUT kind [s] (``call_deadline_s``): a VUT that takes
#: longer than this for one step stops the run with a :class:`ControllerError`.
DEFAULT_CALL_DEADLINE_S = 1.0


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
        target: A registered controller of the package (:data:`CONTROLLERS`, e.g.
            ``"highway_env_idm"``; an old module path of one, :data:`TARGET_ALIASES`, is read
            as its name), ``"package.module:attr"`` (imported with :mod:`importlib`; the
            module must be importable, e.g. from the working directory or an installed
            package) or ``"path/to/file.py:attr"`` (a file; relative to the YAML file that
            names it). ``attr`` may be dotted (``module:Outer.Inner``); it must name a class
            with an ``acceleration(state)`` method, checked before the class is instantiated.
        max_accel_mps2: Largest acceleration the vehicle can realise [m/s²], > 0.
        max_decel_mps2: Largest deceleration the vehicle can realise [m/s²], a positive
            number (commands below ``-max_decel_mps2`` are clipped to it).
        params: Keyword arguments of the target (JSON/YAML values).
        max_speed_mps: Top speed of the vehicle [m/s], > 0.
        sensor_range_m: The leader is seen up to this bumper-to-bumper gap [m], > 0.
        call_deadline_s: Longest wall time one call may take [s], > 0: a slower call stops
            the run with a :class:`~sumo_ayss.util.errors.ControllerError` (an in-process
            call is judged when it returns; an external process is not waited for longer).
            See :mod:`sumo_ayss.vuts.call_budget`.
    """

    #: The key of a VUT entry that holds this kind of VUT (``controller``, ``fmu``, ...).
    yaml_key: ClassVar[str] = "controller"

    target: str
    max_accel_mps2: float
    max_decel_mps2: float
    params: Mapping[str, Any] = field(default_factory=dict)
    max_speed_mps: float = 40.0
    sensor_range_m: float = 250.0
    call_deadline_s: float = DEFAULT_CALL_DEADLINE_S

    def __post_init__(self) -> None:
        object.__setattr__(self, "params", FrozenMap(dict(self.params)))
        object.__setattr__(self, "target", registered_target(self.target))

    @property
    def label(self) -> str:
        """How errors and logs name this VUT (the controller's target)."""
        return repr(self.target)

    def anchored(self, base_dir: Path) -> ControllerSpec:
        """A ``path/to/file.py:attr`` target made absolute against ``base_dir`` (the YAML
        file's folder), like every other path of a configuration; module targets unchanged."""
        module_part, _, attr = self.target.rpartition(":")
        if not module_part.endswith(".py"):
            return self
        path = Path(module_part).expanduser()
        if path.is_absolute():
            return self
        return dataclasses.replace(self, target=f"{(base_dir / path).resolve()}:{attr}")

    def check_limits(self, where: str) -> None:
        """Raise :class:`ConfigError` if a declared limit or the deadline is not > 0."""
        for name in (
            "max_accel_mps2",
            "max_decel_mps2",
            "max_speed_mps",
            "sensor_range_m",
            "call_deadline_s",
        ):
            value = as_number(f"{where}.{name}", getattr(self, name))
            if value <= 0:
                raise ConfigError(f"{where}.{name} must be > 0, got {value!r}")

    def validate(self, where: str) -> None:
        """Raise :class:`ConfigError` naming ``where`` if the limits or the target's form
        are bad.

        Reading a config runs no user code: the target is imported, and the controller
        built from ``params``, when an env that drives this VUT is built (:meth:`build`,
        at the start of a run, so a wrong target or parameter still fails before training).
        """
        registered = isinstance(self.target, str) and CONTROLLERS.find(self.target) is not None
        if not registered and (not isinstance(self.target, str) or ":" not in self.target):
            raise ConfigError(
                f"{where}.target must be a registered controller {list(CONTROLLERS.names())}, "
                f"'package.module:attr' or 'file.py:attr', got {self.target!r}"
            )
        self.check_limits(where)
        if not isinstance(self.params, Mapping):
            raise ConfigError(f"{where}.params must be a mapping, got {self.params!r}")

    def resolve(self, where: str = "controller") -> type:
        """The class ``target`` names, imported; nothing of it is called.

        Raises:
            ConfigError: The target cannot be imported, imports are not allowed here
                (``controller_imports(False)``: a run folder opened untrusted), or it is not
                a class with a callable ``acceleration`` (``subprocess:getoutput`` is not).
        """
        path = CONTROLLERS.find(self.target) or self.target  # a registered name: its class
        if not path.startswith("sumo_ayss."):  # the package's own is always allowed
            check_imports_allowed(
                f"{where}.target {self.target!r}",
                "a user controller, and importing it",
                " (the package's own, sumo_ayss.*, is always allowed)",
            )
        module_part, _, attr_part = path.rpartition(":")
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
            **self._deadline_dict(),
        }

    def _deadline_dict(self) -> dict[str, float]:
        # Written only when set: a run folder's config (and what is derived from it) stays
        # as it was for every VUT that keeps the default deadline.
        if self.call_deadline_s == DEFAULT_CALL_DEADLINE_S:
            return {}
        return {"call_deadline_s": self.call_deadline_s}

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
                "call_deadline_s",
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
        kwargs = {
            k: value[k]
            for k in ("max_speed_mps", "sensor_range_m", "call_deadline_s")
            if k in value
        }
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


def controller_imports_allowed() -> bool:
    """Whether user controllers may be imported now (:func:`controller_imports`): what a
    worker process is handed, so that it drives under the caller's trust."""
    return _CONTROLLER_IMPORTS.get()


def check_imports_allowed(where: str, what: str, note: str = "") -> None:
    """Raise :class:`ConfigError` unless user code may run now (:func:`controller_imports`).

    Args:
        where: The field and value to name (``env.vuts.x.controller.target 'm:C'``).
        what: What this VUT is and what building it does (``"an FMU, and loading it"``).
        note: Said after "run folder" (what is allowed anyway).
    """
    if not _CONTROLLER_IMPORTS.get():
        raise ConfigError(
            f"{where}: this VUT is {what} runs code named by the run folder{note}; pass "
            "--trust-controller if you trust the folder (see 'Trust model' in the README)"
        )


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
