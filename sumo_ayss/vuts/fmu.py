"""An FMI co-simulation FMU executed as a VUT controller, through ``fmpy``.

:class:`FmuController` answers ``acceleration(state)`` like a Python controller, so the
testbed executes it exactly as one (:class:`~sumo_ayss.vuts.controllers.ControlledVut`:
bounds, integration, SUMO speed mode 0, the per-call deadline). Per SUMO step::

    set the mapped inputs from the state read after SUMO step t      (fmiSet*)
    doStep(t_fmu, dt)                                                 (fmi2DoStep/fmi3DoStep)
    read the command output                                           (fmiGet*)
    -> the command acts during SUMO step t + 1

**Time.** The FMU's time starts at 0 at every episode start: ``t_fmu = k · dt`` before the
``k``-th call of the episode (``k = 0`` at the initial condition), whatever SUMO's clock says
(one SUMO simulation runs many episodes). The communication step is the SUMO step
(``sim.step_length_s``). The output after ``doStep(t_fmu, dt)`` is the FMU's value at
``t_fmu + dt`` computed from the inputs held over ``[t_fmu, t_fmu + dt]``; the testbed
applies it over the SUMO step that spans the same interval. For an FMU whose output is an
algebraic function of its inputs this is what a Python controller with the same law returns
(the tests check identical episodes); an FMU with internal states integrates them over the
step it commands.

**Reset per episode** (``fmu.reset``): ``reinstantiate`` frees the instance and instantiates
a new one from the loaded library (exact by construction); ``reset`` calls
``fmi2Reset``/``fmi3Reset`` (exact when the FMU implements reset as the standard says). Both
then set the ``parameters`` and initialize at time 0.

**Errors** (one line each, naming the FMU and the variable): a path that is not a zip
archive; an unreadable ``modelDescription.xml``; an FMI version other than 2.0/3.0; an FMU
without co-simulation (model exchange only); no binary for this platform; a mapped variable
that does not exist, has the wrong causality or a type its signal cannot feed; an input
left unmapped; a ``doStep`` that fails or asks to terminate; a NaN or infinite output.
"""

from __future__ import annotations

import atexit
import contextlib
import ctypes
import math
import shutil
import tempfile
import weakref
import zipfile
from pathlib import Path
from typing import Any

from sumo_ayss.util.errors import ConfigError, ControllerError
from sumo_ayss.vuts.fmu_spec import FmuSpec
from sumo_ayss.vuts.signals import SIGNALS, SignalKind

__all__ = ["FmuController"]

#: FMU variable types per FMI major version: the fmpy setter/getter suffix, the ctypes
#: element type, and which signal kinds may feed it.
_TYPES: dict[int, dict[str, tuple[str, Any, frozenset[SignalKind]]]] = {
    2: {
        "Real": ("Real", ctypes.c_double, frozenset({"real", "int", "bool"})),
        "Integer": ("Integer", ctypes.c_int, frozenset({"int", "bool"})),
        "Boolean": ("Boolean", ctypes.c_int, frozenset({"bool"})),
    },
    3: {
        "Float64": ("Float64", ctypes.c_double, frozenset({"real", "int", "bool"})),
        "Float32": ("Float32", ctypes.c_float, frozenset({"real", "int", "bool"})),
        "Int32": ("Int32", ctypes.c_int32, frozenset({"int", "bool"})),
        "Int64": ("Int64", ctypes.c_int64, frozenset({"int", "bool"})),
        "Boolean": ("Boolean", ctypes.c_bool, frozenset({"bool"})),
    },
}
_REAL_TYPES = frozenset({"Real", "Float64", "Float32"})

# Each FMU file is read and extracted once per Python process, by (path, size, mtime): the
# pairs of a vectorised env (up to 256) each hold an instance of the same FMU, and loading
# one library path again only adds a reference to it (one copy of its code and data
# segment; instances keep their state apart as the standard requires).
#: Model descriptions read so far.
_DESCRIPTIONS: dict[tuple[str, int, int], Any] = {}
#: Folders the FMUs are extracted to (removed at exit).
_EXTRACTED: dict[tuple[str, int, int], Path] = {}


def _fail(where: str, label: str, message: str) -> ConfigError:
    return ConfigError(f"{where}: {label} {message}")


def _binary_name(version: int, model_identifier: str) -> str:
    """The platform binary an FMU of ``version`` must hold for this machine."""
    import fmpy

    folder = fmpy.platform if version == 2 else fmpy.platform_tuple
    return f"binaries/{folder}/{model_identifier}{fmpy.sharedLibraryExtension}"


class _Group:
    """Variables of one FMI type set (or read) together, with preallocated ctypes arrays."""

    def __init__(self, suffix: str, ctype: Any, refs: list[int]) -> None:
        self.suffix = suffix
        self.n = len(refs)
        self.refs = (ctypes.c_uint32 * self.n)(*refs)
        self.values = (ctype * self.n)()


class FmuController:
    """An FMU as a controller (see the module docstring for the semantics).

    Args:
        spec: The FMU's configuration.
        where: The config field, for errors (``env.vuts.<name>.fmu``).

    Raises:
        ConfigError: The FMU does not fit the configuration (checked before any step).
    """

    def __init__(self, spec: FmuSpec, where: str = "fmu") -> None:
        from fmpy import read_model_description

        self.spec = spec
        self.where = where
        self.label = spec.label
        path = Path(spec.path)
        if not path.is_file():
            raise ConfigError(f"{where}.path: no FMU file at {path}")
        if not zipfile.is_zipfile(path):
            raise _fail(where, self.label, "is not an FMU: an FMU is a zip archive, this is not")
        stat = path.stat()
        key = (str(path.resolve()), stat.st_size, stat.st_mtime_ns)
        md = _DESCRIPTIONS.get(key)
        if md is None:
            try:
                md = read_model_description(str(path))
            except Exception as e:  # fmpy raises plain Exceptions for unreadable descriptions
                msg = " ".join(str(e).split())[:300] or type(e).__name__
                raise _fail(
                    where, self.label, f"has no readable modelDescription.xml ({msg})"
                ) from e
            _DESCRIPTIONS[key] = md
        self._key = key
        self.fmi_version = md.fmiMajorVersion if md.fmiVersion else 0
        if self.fmi_version not in _TYPES:
            raise _fail(where, self.label, f"is FMI {md.fmiVersion}; supported: FMI 2.0 and 3.0")
        if md.coSimulation is None:
            kinds = [k for k in ("modelExchange", "scheduledExecution") if getattr(md, k, None)]
            raise _fail(
                where,
                self.label,
                f"has no co-simulation interface (only {kinds}); the testbed steps an FMU by "
                "co-simulation (FMI 2.0/3.0 CoSimulation)",
            )
        model_id = md.coSimulation.modelIdentifier
        binary = _binary_name(self.fmi_version, model_id)
        with zipfile.ZipFile(path) as zf:
            names = zf.namelist()
        if binary not in names:
            have = sorted(
                {n.split("/")[1] for n in names if n.startswith("binaries/") and "/" in n[9:]}
            )
            raise _fail(
                where,
                self.label,
                f"has no binary for this platform ({binary}); it has binaries for {have}",
            )
        self._variables = {v.name: v for v in md.modelVariables}
        self._inputs, self._input_signals = self._map_inputs()
        self._output_kind, out_name = spec.command
        self._output_name = out_name
        out = self._variable(out_name, "outputs", ("output",))
        if out.type not in _REAL_TYPES:
            raise _fail(
                where,
                self.label,
                f"output {out_name!r} is {out.type}; the command must be a real number "
                f"({sorted(_REAL_TYPES & set(_TYPES[self.fmi_version]))})",
            )
        self._output = _Group(*_TYPES[self.fmi_version][out.type][:2], [out.valueReference])
        self._parameters = self._map_parameters()

        self._path = path
        self._md = md
        self._k = 0  # calls since the episode start
        self._last_dt = 0.0
        self._fmu: Any = None
        self._open()
        self._fresh = True  # the first episode uses the instance built here

    def _open(self) -> None:
        """Extract the FMU, load its library, instantiate and initialize it."""
        import fmpy

        md = self._md
        folder = _EXTRACTED.get(self._key)
        if folder is None or not folder.is_dir():
            folder = Path(tempfile.mkdtemp(prefix="sumo_ayss_fmu_"))
            fmpy.extract(str(self._path), str(folder))
            _EXTRACTED[self._key] = folder
        from fmpy.fmi2 import FMU2Slave
        from fmpy.fmi3 import FMU3Slave

        cls: Any = FMU2Slave if self.fmi_version == 2 else FMU3Slave
        guid = md.guid if self.fmi_version == 2 else md.instantiationToken
        self._fmu = cls(
            guid=guid,
            unzipDirectory=str(folder),
            modelIdentifier=md.coSimulation.modelIdentifier,
            instanceName="vut",
        )
        self._live = [False]  # an instance exists (shared with the finalizer)
        self._finalizer = weakref.finalize(self, _release, self._fmu, self._live)
        self._instantiate()
        self._initialize()
        self._fresh = False

    # ------------------------------------------------------------------ mapping

    def _variable(self, name: str, field: str, causalities: tuple[str, ...]) -> Any:
        var = self._variables.get(name)
        if var is None:
            wanted = sorted(n for n, v in self._variables.items() if v.causality in causalities)
            raise _fail(
                f"{self.where}.{field}",
                self.label,
                f"has no variable {name!r}; its {'/'.join(causalities)} variables: {wanted}",
            )
        if var.causality not in causalities:
            raise _fail(
                f"{self.where}.{field}",
                self.label,
                f"variable {name!r} has causality {var.causality!r}, not "
                f"{' or '.join(map(repr, causalities))}",
            )
        return var

    def _map_inputs(self) -> tuple[list[_Group], list[list[Any]]]:
        by_type: dict[str, list[tuple[int, Any]]] = {}
        types = _TYPES[self.fmi_version]
        for name, signal_name in self.spec.inputs.items():
            var = self._variable(name, f"inputs.{name}", ("input",))
            signal = SIGNALS[signal_name]
            if var.type not in types or signal.kind not in types[var.type][2]:
                fits = sorted(t for t, (_, _, kinds) in types.items() if signal.kind in kinds)
                raise _fail(
                    f"{self.where}.inputs.{name}",
                    self.label,
                    f"input {name!r} is {var.type}; signal {signal_name!r} ({signal.kind}) "
                    f"feeds {fits}",
                )
            by_type.setdefault(var.type, []).append((var.valueReference, signal.read))
        unmapped = sorted(
            n
            for n, v in self._variables.items()
            if v.causality == "input"
            and n not in self.spec.inputs
            and n not in self.spec.parameters
        )
        if unmapped:
            raise _fail(
                f"{self.where}.inputs",
                self.label,
                f"inputs {unmapped} are not mapped: map each to a signal under inputs, or give "
                "it a fixed value under parameters",
            )
        groups = [_Group(*types[t][:2], [r for r, _ in pairs]) for t, pairs in by_type.items()]
        return groups, [[read for _, read in pairs] for pairs in by_type.values()]

    def _map_parameters(self) -> list[tuple[str, list[int], list[Any]]]:
        out: dict[str, tuple[list[int], list[Any]]] = {}
        for name, value in self.spec.parameters.items():
            field = f"parameters.{name}"
            var = self._variable(name, field, ("parameter", "input"))
            if var.variability == "constant":
                raise _fail(f"{self.where}.{field}", self.label, f"variable {name!r} is constant")
            kind = var.type
            if kind in _REAL_TYPES:
                ok = isinstance(value, int | float) and not isinstance(value, bool)
                value = float(value) if ok else value
            elif kind == "Boolean":
                ok = isinstance(value, bool)
            elif kind == "String":
                ok = isinstance(value, str)
            else:  # integer types and enumerations
                ok = isinstance(value, int) and not isinstance(value, bool)
            if not ok:
                raise _fail(
                    f"{self.where}.{field}",
                    self.label,
                    f"variable {name!r} is {kind}, got {value!r}",
                )
            suffix = "Real" if (kind == "Real" and self.fmi_version == 2) else kind
            if kind == "Enumeration":
                suffix = "Integer" if self.fmi_version == 2 else "Int64"
            refs, values = out.setdefault(suffix, ([], []))
            refs.append(var.valueReference)
            values.append(value)
        return [(suffix, refs, values) for suffix, (refs, values) in out.items()]

    # ------------------------------------------------------------------ lifecycle

    def _call(self, what: str, fn: Any, *args: Any) -> Any:
        try:
            return fn(*args)
        except Exception as e:  # fmpy's FMICallException or a failed instantiation
            raise ControllerError(
                f"{self.label}: {what} failed at FMU time {self._k * self._dt():g} s ({e})"
            ) from e

    def _dt(self) -> float:
        return self._last_dt

    def _instantiate(self) -> None:
        self._call("instantiate", self._fmu.instantiate)
        self._live[0] = True
        self._bind()

    def _initialize(self) -> None:
        fmu = self._fmu
        if self.fmi_version == 2:
            self._call("setupExperiment", fmu.setupExperiment, None, 0.0)
        for suffix, refs, values in self._parameters:
            self._call(f"set{suffix} of parameters", getattr(fmu, f"set{suffix}"), refs, values)
        if self.fmi_version == 2:
            self._call("enterInitializationMode", fmu.enterInitializationMode)
        else:
            self._call("enterInitializationMode", fmu.enterInitializationMode, None, 0.0)
        self._call("exitInitializationMode", fmu.exitInitializationMode)
        self._k = 0

    def reset(self) -> None:
        """Start an episode: a fresh (``reinstantiate``) or reset (``reset``) instance,
        parameters set, initialized at FMU time 0. A closed FMU is opened again."""
        if self._fmu is None:
            self._open()
            return
        if self._fresh:
            self._fresh = False
            self._k = 0
            return
        fmu = self._fmu
        if self.spec.reset == "reset":
            self._call("reset", fmu.reset)
        else:
            free = fmu.fmi2FreeInstance if self.fmi_version == 2 else fmu.fmi3FreeInstance
            free(fmu.component)
            self._live[0] = False
            self._instantiate()
        self._initialize()

    def _bind(self) -> None:
        """The raw C functions of this instance with their fixed arguments, bound once (the
        per-step path makes no name lookups and no fmpy wrapper calls)."""
        fmu = self._fmu
        fns = fmu._functions
        prefix = f"fmi{self.fmi_version}"
        tail = self.fmi_version == 3  # FMI 3 passes the number of values too
        self._set_calls = [
            (
                f"{prefix}Set{g.suffix}",
                fns[f"{prefix}Set{g.suffix}"],
                (fmu.component, g.refs, g.n, g.values, *((g.n,) if tail else ())),
                g.values,
                reads,
            )
            for g, reads in zip(self._inputs, self._input_signals, strict=True)
        ]
        out = self._output
        self._get_call = (
            f"{prefix}Get{out.suffix}",
            fns[f"{prefix}Get{out.suffix}"],
            (fmu.component, out.refs, 1, out.values, *((1,) if tail else ())),
        )
        self._do_step = fns[f"{prefix}DoStep"]
        if tail:
            self._step_flags = tuple(ctypes.c_bool() for _ in range(3))
            self._step_time = ctypes.c_double()
            self._step_tail: tuple[Any, ...] = (
                True,
                *(ctypes.byref(f) for f in self._step_flags),
                ctypes.byref(self._step_time),
            )
        else:
            self._step_tail = (1,)

    def _status(self, what: str, status: int) -> None:
        if status > 1:  # fmiOK 0, fmiWarning 1; then discard, error, fatal (, pending)
            label = ["ok", "warning", "discard", "error", "fatal", "pending"][min(status, 5)]
            raise ControllerError(
                f"{self.label}: {what} failed with status {status} ({label}) at FMU time "
                f"{self._k * self._last_dt:g} s"
            )

    def acceleration(self, state: Any) -> float:
        """The FMU's command for the coming step [m/s²] (a commanded speed converted)."""
        if self._fmu is None:
            raise ControllerError(f"{self.label}: asked for a command after close()")
        for what, fn, args, values, reads in self._set_calls:
            for i, read in enumerate(reads):
                values[i] = read(state)
            self._status(what, fn(*args))
        dt = float(state.dt_s)
        self._last_dt = dt
        t = self._k * dt
        component = self._fmu.component
        self._status(
            f"fmi{self.fmi_version}DoStep", self._do_step(component, t, dt, *self._step_tail)
        )
        if self.fmi_version == 3 and self._step_flags[1].value:
            raise ControllerError(
                f"{self.label}: fmi3DoStep asked to terminate at FMU time {t:g} s"
            )
        what, fn, args = self._get_call
        self._status(what, fn(*args))
        self._k += 1
        value = float(self._output.values[0])
        if not math.isfinite(value):
            raise ControllerError(
                f"{self.label}: output {self._output_name!r} is {value} after the step at FMU "
                f"time {t:g} s (state {state})"
            )
        if self._output_kind == "speed_mps":
            accel_mps2: float = (value - state.speed_mps) / dt
            return accel_mps2
        return value

    def close(self) -> None:
        """Terminate and free the instance, release the library (safe to call twice; the
        next :meth:`reset` opens it again)."""
        if self._fmu is not None:
            self._finalizer()
            self._fmu = None


def _release(fmu: Any, live: list[bool]) -> None:
    """Free an FMU instance and release its library (also at garbage collection)."""
    if live[0]:
        live[0] = False
        with contextlib.suppress(Exception):  # a failed instance may refuse to terminate
            fmu.terminate()
        fmu.freeInstance()


@atexit.register
def _remove_extracted() -> None:
    for folder in _EXTRACTED.values():
        shutil.rmtree(folder, ignore_errors=True)
