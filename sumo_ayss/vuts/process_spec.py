"""An external process as the VUT: its configuration record (no process is started here).

YAML (a VUT entry of ``env.vuts``)::

    acc_proc:
      description: the time-gap ACC behind the line protocol, in another process
      process:
        command: [python, examples/process_vut.py, --time-gap, "2.0"]
        cwd: .                             # the process's folder, relative to the YAML file
        signals: [speed_mps, gap_m, rel_speed_mps, has_leader]   # sent every step, in order
        max_accel_mps2: 3.0
        max_decel_mps2: 6.0
        call_deadline_s: 1.0               # no answer within this: a clear error

The line protocol and its errors are :mod:`sumo_ayss.vuts.process`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

from sumo_ayss.util.errors import ConfigError
from sumo_ayss.util.validation import check_keys
from sumo_ayss.vuts.controller_spec import ControllerSpec, check_imports_allowed
from sumo_ayss.vuts.signals import DEFAULT_SIGNALS, check_signal
from sumo_ayss.vuts.vtype_params import as_number

__all__ = ["ProcessSpec"]


@dataclass(frozen=True)
class ProcessSpec(ControllerSpec):
    """A separate process that answers one request per SUMO step (the line protocol of
    :mod:`sumo_ayss.vuts.process`). Limits and deadline: :class:`ControllerSpec`'s.

    Attributes:
        command: The program and its arguments (no shell).
        cwd: The folder it runs in (absolute once read from YAML; default: the YAML's).
        signals: The signals sent every step, in this order
            (:data:`~sumo_ayss.vuts.signals.SIGNALS`; default: the controller input's).
        start_timeout_s: How long the process may take to answer the handshake [s], > 0.
    """

    yaml_key: ClassVar[str] = "process"

    target: str = field(default="", init=False)
    command: tuple[str, ...] = field(default=(), kw_only=True)
    cwd: str = field(default="", kw_only=True)
    signals: tuple[str, ...] = field(default=DEFAULT_SIGNALS, kw_only=True)
    start_timeout_s: float = field(default=10.0, kw_only=True)

    def __post_init__(self) -> None:
        super().__post_init__()
        object.__setattr__(self, "command", tuple(self.command))
        object.__setattr__(self, "signals", tuple(self.signals))
        object.__setattr__(self, "target", "process:" + " ".join(map(str, self.command)))

    @property
    def label(self) -> str:
        """``process 'prog args'``: how errors name this VUT."""
        return f"process {' '.join(map(str, self.command))!r}"

    def validate(self, where: str) -> None:
        """Raise :class:`ConfigError` naming the field if the form is bad."""
        if not self.command or not all(isinstance(a, str) and a for a in self.command):
            raise ConfigError(
                f"{where}.command must be a non-empty list of strings (program, arguments), "
                f"got {list(self.command)!r}"
            )
        self.check_limits(where)
        if as_number(f"{where}.start_timeout_s", self.start_timeout_s) <= 0:
            raise ConfigError(f"{where}.start_timeout_s must be > 0, got {self.start_timeout_s!r}")
        if not self.signals:
            raise ConfigError(f"{where}.signals must name at least one signal")
        for i, name in enumerate(self.signals):
            check_signal(f"{where}.signals[{i}]", name)
        if len(set(self.signals)) != len(self.signals):
            raise ConfigError(f"{where}.signals names a signal twice: {list(self.signals)}")

    def anchored(self, base_dir: Path) -> ProcessSpec:
        """``cwd`` made absolute against ``base_dir`` (the YAML file's folder; its default)."""
        cwd = Path(self.cwd).expanduser() if self.cwd else Path(".")
        if cwd.is_absolute():
            return self
        return dataclasses.replace(self, cwd=str((base_dir / cwd).resolve()))

    def build(self, where: str = "process") -> Any:
        """Start the process and shake hands (:class:`~sumo_ayss.vuts.process.ProcessController`).

        Raises:
            ConfigError: Starting user code is not allowed here, the program cannot be
                started, or it does not answer the handshake in ``start_timeout_s``.
        """
        check_imports_allowed(
            f"{where}.command {list(self.command)!r}", "a process, and starting it"
        )
        from sumo_ayss.vuts.process import ProcessController

        return ProcessController(self, where)

    def to_dict(self) -> dict[str, Any]:
        """Plain YAML-safe form (the inverse of :meth:`from_mapping`)."""
        return {
            "command": list(self.command),
            "cwd": self.cwd,
            "signals": list(self.signals),
            "start_timeout_s": self.start_timeout_s,
            "max_accel_mps2": self.max_accel_mps2,
            "max_decel_mps2": self.max_decel_mps2,
            "max_speed_mps": self.max_speed_mps,
            "sensor_range_m": self.sensor_range_m,
            **self._deadline_dict(),
        }

    @classmethod
    def from_mapping(cls, value: Any, where: str) -> ProcessSpec:
        """Build and validate from a YAML mapping (keys as in :meth:`to_dict`)."""
        keys = (
            "command",
            "cwd",
            "signals",
            "start_timeout_s",
            "max_accel_mps2",
            "max_decel_mps2",
            "max_speed_mps",
            "sensor_range_m",
            "call_deadline_s",
        )
        if not isinstance(value, Mapping):
            raise ConfigError(
                f"{where} must be a mapping with command, max_accel_mps2, max_decel_mps2, "
                f"got {value!r}"
            )
        check_keys(where, value, keys)
        for key in ("command", "max_accel_mps2", "max_decel_mps2"):
            if key not in value:
                raise ConfigError(
                    f"{where}.{key} is required (a process VUT names its program and its "
                    "acceleration limits)"
                )
        kwargs = {k: value[k] for k in keys if k in value}
        for key in ("command", "signals"):
            if key in kwargs and not isinstance(kwargs[key], list | tuple):
                raise ConfigError(f"{where}.{key} must be a list, got {kwargs[key]!r}")
        if "cwd" in kwargs:
            kwargs["cwd"] = str(kwargs["cwd"])
        spec = cls(**kwargs)
        spec.validate(where)
        return spec
