"""An FMI co-simulation FMU as the VUT: its configuration record (no FMU is opened here).

YAML (a VUT entry of ``env.vuts``; every mapping reads ``destination: source``, like an
assignment)::

    acc_fmu:
      description: time-gap ACC exported as an FMU (FMI 2.0 co-simulation)
      fmu:
        path: fmus/acc.fmu                 # relative to the YAML file
        inputs:                            # FMU input variable: signal of the sensor view
          v_ego: speed_mps
          gap: gap_m
          v_rel: rel_speed_mps
          has_lead: has_leader
        outputs:                           # testbed command: FMU output variable
          acceleration_mps2: a_cmd         # or speed_mps: v_cmd (a commanded speed)
        parameters: {time_gap_s: 2.0}      # start values, set before initialization
        max_accel_mps2: 3.0
        max_decel_mps2: 6.0

The signals are :data:`sumo_ayss.vuts.signals.SIGNALS`. How the FMU is executed (its time,
its reset per episode, the errors) is :mod:`sumo_ayss.vuts.fmu`; the FMU file itself is opened
when an env that drives it is built, not when a config is read.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar, Literal

from sumo_ayss.util.errors import ConfigError
from sumo_ayss.util.frozen import FrozenMap
from sumo_ayss.util.validation import check_choice, check_keys
from sumo_ayss.vuts.controller_spec import ControllerSpec, check_imports_allowed
from sumo_ayss.vuts.signals import check_signal

__all__ = ["COMMAND_OUTPUTS", "RESET_MODES", "FmuSpec"]

#: What an FMU's output may command: an acceleration [m/s²] or a speed [m/s] for the step.
COMMAND_OUTPUTS = ("acceleration_mps2", "speed_mps")
#: How the FMU starts every episode: a fresh instance, or ``fmiReset`` + initialization.
RESET_MODES = ("reinstantiate", "reset")


@dataclass(frozen=True)
class FmuSpec(ControllerSpec):
    """An FMU (FMI 2.0 or 3.0 co-simulation) as the VUT, run through ``fmpy``.

    The declared limits (``max_accel_mps2``, ...) and the deadline are
    :class:`ControllerSpec`'s; ``target`` is derived (``fmu:<path>``) and ``params`` unused.

    Attributes:
        path: The ``.fmu`` file (absolute once read from YAML).
        inputs: FMU input variable -> signal name; every input of the FMU must be mapped
            here or given a value under ``parameters``.
        outputs: One entry: ``acceleration_mps2`` or ``speed_mps`` -> FMU output variable.
            A commanded speed ``v'`` becomes the acceleration ``(v' - v) / dt``.
        parameters: FMU variable -> start value (number, bool or string), set after
            instantiation and before initialization, every episode.
        reset: ``reinstantiate`` (free the instance and instantiate a new one) or ``reset``
            (``fmi2Reset``/``fmi3Reset``, then initialize again) at every episode start.
    """

    yaml_key: ClassVar[str] = "fmu"

    target: str = field(default="", init=False)
    path: str = field(default="", kw_only=True)
    inputs: Mapping[str, str] = field(default_factory=dict, kw_only=True)
    outputs: Mapping[str, str] = field(default_factory=dict, kw_only=True)
    parameters: Mapping[str, Any] = field(default_factory=dict, kw_only=True)
    reset: Literal["reinstantiate", "reset"] = field(default="reinstantiate", kw_only=True)

    def __post_init__(self) -> None:
        super().__post_init__()
        for name in ("inputs", "outputs", "parameters"):
            value = getattr(self, name)
            if isinstance(value, Mapping):
                object.__setattr__(self, name, FrozenMap(dict(value)))
        object.__setattr__(self, "target", f"fmu:{self.path}")

    @property
    def label(self) -> str:
        """``FMU 'name.fmu'``: how errors name this VUT."""
        return f"FMU {Path(str(self.path)).name!r}"

    @property
    def command(self) -> tuple[str, str]:
        """``(what the output commands, the FMU output variable)``."""
        ((kind, variable),) = self.outputs.items()
        return kind, variable

    def validate(self, where: str) -> None:
        """Raise :class:`ConfigError` naming the field if the form is bad (the FMU file is
        checked against it when it is opened, :class:`~sumo_ayss.vuts.fmu.FmuController`)."""
        if not isinstance(self.path, str) or not self.path:
            raise ConfigError(f"{where}.path must be the path of an .fmu file, got {self.path!r}")
        self.check_limits(where)
        check_choice(f"{where}.reset", self.reset, RESET_MODES)
        for name in ("inputs", "outputs", "parameters"):
            if not isinstance(getattr(self, name), Mapping):
                raise ConfigError(f"{where}.{name} must be a mapping, got {getattr(self, name)!r}")
        if not self.inputs:
            raise ConfigError(
                f"{where}.inputs must map at least one FMU input variable to a signal "
                "(e.g. {v_ego: speed_mps})"
            )
        for variable, signal in self.inputs.items():
            check_signal(f"{where}.inputs.{variable}", signal)
        if len(self.outputs) != 1 or next(iter(self.outputs)) not in COMMAND_OUTPUTS:
            raise ConfigError(
                f"{where}.outputs must have exactly one of {list(COMMAND_OUTPUTS)}, naming the "
                f"FMU output variable that commands it, got {dict(self.outputs)!r}"
            )
        _, variable = self.command
        if not isinstance(variable, str) or not variable:
            raise ConfigError(f"{where}.outputs: the FMU variable must be a name, got {variable!r}")
        for variable, value in self.parameters.items():
            if not isinstance(value, int | float | str):  # bool is an int
                raise ConfigError(
                    f"{where}.parameters.{variable} must be a number, true/false or a string, "
                    f"got {value!r}"
                )
        both = sorted(set(self.inputs) & set(self.parameters))
        if both:
            raise ConfigError(
                f"{where}: {both} are both mapped to a signal (inputs) and given a value "
                "(parameters); give each FMU variable one source"
            )

    def anchored(self, base_dir: Path) -> FmuSpec:
        """The FMU path made absolute against ``base_dir`` (the YAML file's folder)."""
        path = Path(self.path).expanduser()
        if path.is_absolute():
            return self
        return dataclasses.replace(self, path=str((base_dir / path).resolve()))

    def build(self, where: str = "fmu") -> Any:
        """Open the FMU, check its variables against the mapping, instantiate it.

        Raises:
            ConfigError: Loading user code is not allowed here, or the FMU does not fit
                (see :class:`~sumo_ayss.vuts.fmu.FmuController`).
        """
        check_imports_allowed(f"{where}.path {self.path!r}", "an FMU, and loading it")
        from sumo_ayss.vuts.fmu import FmuController  # fmpy only when an FMU is driven

        return FmuController(self, where)

    def to_dict(self) -> dict[str, Any]:
        """Plain YAML-safe form (the inverse of :meth:`from_mapping`)."""
        return {
            "path": self.path,
            "inputs": dict(self.inputs),
            "outputs": dict(self.outputs),
            "parameters": dict(self.parameters),
            "reset": self.reset,
            "max_accel_mps2": self.max_accel_mps2,
            "max_decel_mps2": self.max_decel_mps2,
            "max_speed_mps": self.max_speed_mps,
            "sensor_range_m": self.sensor_range_m,
            **self._deadline_dict(),
        }

    @classmethod
    def from_mapping(cls, value: Any, where: str) -> FmuSpec:
        """Build and validate from a YAML mapping (keys as in :meth:`to_dict`)."""
        keys = (
            "path",
            "inputs",
            "outputs",
            "parameters",
            "reset",
            "max_accel_mps2",
            "max_decel_mps2",
            "max_speed_mps",
            "sensor_range_m",
            "call_deadline_s",
        )
        if not isinstance(value, Mapping):
            raise ConfigError(
                f"{where} must be a mapping with path, inputs, outputs, max_accel_mps2, "
                f"max_decel_mps2, got {value!r}"
            )
        check_keys(where, value, keys)
        for key in ("path", "inputs", "outputs", "max_accel_mps2", "max_decel_mps2"):
            if key not in value:
                raise ConfigError(
                    f"{where}.{key} is required (an FMU VUT names its file, its signals, its "
                    "command output and its acceleration limits)"
                )
        kwargs = {k: value[k] for k in keys if k in value}
        for key in ("inputs", "outputs", "parameters"):
            if key in kwargs and not isinstance(kwargs[key], Mapping):
                raise ConfigError(f"{where}.{key} must be a mapping, got {kwargs[key]!r}")
            if key in kwargs:
                kwargs[key] = {str(k): v for k, v in kwargs[key].items()}
        if isinstance(kwargs["path"], Path):
            kwargs["path"] = str(kwargs["path"])
        spec = cls(**kwargs)
        spec.validate(where)
        return spec
