"""Mapping -> frozen dataclass, and back: how YAML (and a run folder's ``config.yaml``)
becomes a configuration record.

:func:`build` merges a mapping over a section's defaults (or over a given record), converts
each value to its field's type and rejects unknown keys with a suggestion; the section's own
``__post_init__`` then checks the values. Relative paths resolve against ``base_dir`` (the
YAML file's folder). :func:`to_dict` is the inverse (YAML-safe plain data).
"""

from __future__ import annotations

import dataclasses
import math
import types
import typing
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal, TypeVar

from sumo_ayss.config.env import OMIT_DEFAULT, EnvConfig
from sumo_ayss.util.errors import ConfigError
from sumo_ayss.util.validation import check_choice, unknown_key
from sumo_ayss.vuts.catalog import DRIVER_KEYS, ControllerSpec, VehicleType
from sumo_ayss.vuts.controller_spec import DEFAULT_CALL_DEADLINE_S


def _anchor_controller(spec: ControllerSpec, base_dir: Path) -> ControllerSpec:
    """The spec's paths (a ``file.py`` target, an FMU, a process's folder) made absolute
    against ``base_dir`` (the YAML file's folder), like every other path of a configuration."""
    return spec.anchored(base_dir)


def _names_black_box(value: Mapping[Any, Any]) -> bool:
    """Whether a VUT entry is driven by an FMU or a process (a driver key other than
    ``controller``, :data:`~sumo_ayss.vuts.catalog.DRIVER_KEYS`)."""
    return any(value.get(key) is not None for key in DRIVER_KEYS if key != "controller")


def _convert(tp: Any, value: Any, where: str, base_dir: Path, default: Any) -> Any:
    origin = typing.get_origin(tp)
    args = typing.get_args(tp)
    if tp is ControllerSpec:  # free-form params: parsed and validated by the catalog
        if isinstance(value, ControllerSpec):
            return value
        return _anchor_controller(ControllerSpec.from_mapping(value, where), base_dir)
    if tp is VehicleType and isinstance(value, Mapping) and _names_black_box(value):
        # An FMU or a process VUT: read whole by the catalog (its record is not a field of
        # VehicleType's own, so the field-by-field build below would not know the key).
        vt = VehicleType.from_mapping(value, where)
        if vt.controller is None:
            return vt
        return dataclasses.replace(vt, controller=_anchor_controller(vt.controller, base_dir))
    if dataclasses.is_dataclass(tp) and isinstance(tp, type):
        if isinstance(value, tp):
            return value
        return build(tp, value, where, base_dir, default)
    if origin in (types.UnionType, typing.Union):
        if value is None and type(None) in args:
            return None
        non_none = [a for a in args if a is not type(None)]
        return _convert(non_none[0], value, where, base_dir, default)
    if origin is Literal:
        check_choice(where, value, args)
        return value
    if tp is Path:
        if not isinstance(value, str | Path):
            raise ConfigError(f"{where} must be a path string, got {value!r}")
        path = Path(value).expanduser()
        return path if path.is_absolute() else (base_dir / path).resolve()
    if tp is bool:
        if not isinstance(value, bool):
            raise ConfigError(f"{where} must be true or false, got {value!r}")
        return value
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ConfigError(f"{where} must be an integer, got {value!r}")
        return value
    if tp is float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ConfigError(f"{where} must be a number, got {value!r}")
        if not math.isfinite(value):  # YAML's .inf / .nan: no field of ours takes them
            raise ConfigError(f"{where} must be a finite number, got {value!r}")
        return float(value)
    if tp is str:
        if not isinstance(value, str):
            raise ConfigError(f"{where} must be a string, got {value!r}")
        return value
    if origin is tuple:
        if not isinstance(value, list | tuple):
            raise ConfigError(f"{where} must be a list, got {value!r}")
        item_types = [args[0]] * len(value) if (len(args) == 2 and args[1] is Ellipsis) else args
        if len(item_types) != len(value):
            raise ConfigError(f"{where} must have {len(item_types)} items, got {list(value)}")
        return tuple(
            _convert(t, v, f"{where}[{i}]", base_dir, None)
            for i, (t, v) in enumerate(zip(item_types, value, strict=True))
        )
    if origin in (Mapping, dict) or tp is dict:
        if not isinstance(value, Mapping):
            raise ConfigError(f"{where} must be a mapping, got {value!r}")
        # A catalog of VUTs extends the built-ins; any other mapping (e.g. the pipeline's
        # ``experiments``) replaces its default whole, so ``{}`` never falls back silently.
        catalog = bool(args) and args[1] is VehicleType
        merged = dict(default or {}) if catalog else {}
        for k, v in value.items():
            if catalog and v is None:  # would silently keep the built-in (or the default)
                raise ConfigError(
                    f"{where}.{k} is null: give a vehicle type (a mapping with model, params, "
                    "description, controller) or leave the entry out"
                )
            merged[str(k)] = _convert(args[1], v, f"{where}.{k}", base_dir, merged.get(str(k)))
        return merged
    raise ConfigError(f"{where}: unsupported type {tp!r}")  # pragma: no cover


if TYPE_CHECKING:
    from _typeshed import DataclassInstance

_T = TypeVar("_T", bound="DataclassInstance")


def build(cls: type[_T], data: Any, where: str, base_dir: Path, default: _T | None = None) -> _T:
    """Build dataclass ``cls`` from a mapping, over ``default`` (or the class defaults).

    Errors name the dotted field under ``where``: a section whose checks name its usual
    place (``SECTION``, e.g. ``ayss``) gets ``where`` instead when it sits elsewhere
    (``evaluate.ayss``).
    """
    if data is None:
        data = {}
    if not isinstance(data, Mapping):
        raise ConfigError(f"{where or 'config'} must be a mapping, got {data!r}")
    hints = typing.get_type_hints(cls)
    names = [f.name for f in dataclasses.fields(cls)]
    base = default if default is not None else None
    kwargs: dict[str, Any] = {}
    for key, value in data.items():
        if key not in names:
            raise unknown_key(where or "config", str(key), names)
        sub_default = getattr(base, key) if base is not None else _field_default(cls, key)
        child = f"{where}.{key}" if where else str(key)
        kwargs[key] = _convert(hints[key], value, child, base_dir, sub_default)
    try:
        return dataclasses.replace(base, **kwargs) if base is not None else cls(**kwargs)
    except ConfigError as e:
        section = getattr(cls, "SECTION", "")
        message = str(e)
        if section and where and where != section and message.startswith(section + "."):
            raise ConfigError(where + message[len(section) :]) from e
        raise


def _field_default(cls: type, name: str) -> Any:
    f = next(f for f in dataclasses.fields(cls) if f.name == name)
    if f.default is not dataclasses.MISSING:
        return f.default
    if f.default_factory is not dataclasses.MISSING:
        return f.default_factory()
    return None


def to_dict(obj: Any) -> Any:
    """Plain YAML-safe form of a config (the exact resolved config a run used)."""
    if isinstance(obj, VehicleType) and obj.controller is not None:
        return _controlled_vut_dict(obj)
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {
            f.name: to_dict(getattr(obj, f.name))
            for f in dataclasses.fields(obj)
            if not (f.metadata.get(OMIT_DEFAULT) and getattr(obj, f.name) == f.default)
        }
    if isinstance(obj, Mapping):
        return {str(k): to_dict(v) for k, v in obj.items()}
    if isinstance(obj, tuple | list):
        return [to_dict(v) for v in obj]
    if isinstance(obj, Path):
        return str(obj)
    return obj


def _controlled_vut_dict(vt: VehicleType) -> dict[str, Any]:
    """A VUT driven by a controller, an FMU or a process, under its own key (``controller``,
    ``fmu``, ``process``). A Python controller keeps the form it always had (every field;
    ``call_deadline_s`` only when it is not the default), so existing run files read the same."""
    spec = vt.controller
    assert spec is not None
    out = {f.name: to_dict(getattr(vt, f.name)) for f in dataclasses.fields(vt)}
    del out["controller"]
    if type(spec) is ControllerSpec:
        fields = {f.name: to_dict(getattr(spec, f.name)) for f in dataclasses.fields(spec)}
        if spec.call_deadline_s == DEFAULT_CALL_DEADLINE_S:
            del fields["call_deadline_s"]
        out["controller"] = fields
    else:
        out[spec.yaml_key] = spec.to_dict()
    return out


def env_config_from_mapping(data: Mapping[str, Any], base_dir: Path | None = None) -> EnvConfig:
    """Build an :class:`EnvConfig` from the contents of an ``env:`` section."""
    return build(EnvConfig, data, "env", base_dir or Path.cwd())
