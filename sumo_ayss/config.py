"""Typed, validated configuration: defaults in code, YAML holds overrides.

Every section is a frozen dataclass checked in ``__post_init__``; a bad value raises
:class:`~sumo_ayss.errors.ConfigError` naming the dotted field and the allowed values. YAML
files are merged over the defaults by :func:`load_config`; unknown keys are rejected with a
suggestion, relative paths resolve against the YAML file's folder.

Units: lengths m, speeds m/s, accelerations m/s², times s. Sign convention: accelerations
are positive forward, braking is negative (the POV actuator bounds are ``[-6, 6]`` m/s²).
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import types
import typing
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar, Literal

import yaml

from sumo_ayss.catalog import BUILTIN_VUTS, POV_TYPE, ControllerSpec, VehicleType
from sumo_ayss.errors import ConfigError

Case = Literal["car_following", "cut_in"]
ShapeKind = Literal["linear", "quadratic", "exponential"]

#: Repository root (holds networks/, configs/, routes/) when running from a checkout.
PROJECT_ROOT = Path(__file__).resolve().parent.parent


def _require(cond: bool, message: str) -> None:
    if not cond:
        raise ConfigError(message)


def _check_range(where: str, value: tuple[float, ...], low: float = -math.inf) -> None:
    _require(
        len(value) == 2 and all(math.isfinite(v) for v in value),
        f"{where} must be [min, max] with finite numbers, got {list(value)}",
    )
    _require(value[0] <= value[1], f"{where} must have min <= max, got {list(value)}")
    _require(value[0] >= low, f"{where} min must be >= {low}, got {value[0]}")


#: SUMO options that sumo_ayss sets itself (sim/session.py), and where to change them.
MANAGED_SUMO_OPTIONS: dict[str, str] = {
    "net-file": "env.network",
    "n": "env.network",
    "additional-files": "env.vuts / env.pov",
    "a": "env.vuts / env.pov",
    "step-length": "env.sim.step_length_s",
    "seed": "the run's seed",
    "collision.action": "always warn: a collision ends the episode",
    "collision.mingap-factor": "env.sim.collision_mingap_factor",
    "lanechange.duration": "env.sim.lanechange_duration_s",
    "begin": "always 0",
}


@dataclass(frozen=True)
class SimConfig:
    """How SUMO runs. Section ``env.sim``."""

    SECTION: ClassVar[str] = "env.sim"

    step_length_s: float = 0.2
    """SUMO step [s]; the policy acts every ``env.decision_period_s``."""
    lanechange_duration_s: float = 1.0
    """Duration of a POV lane change [s] (continuous lateral motion, ``--lanechange.duration``)."""
    lateral_resolution_m: float | None = None
    """SUMO's sublane model (``--lateral-resolution``) [m], or None (off). Needed by the
    highway-env POV in cut-in (free lateral positions); SUMO then ignores
    ``lanechange_duration_s`` (the two options exclude each other)."""
    collision_mingap_factor: float = 0.0
    """0: only physical overlap counts as a collision (SUMO's default flags a 0.3 m gap)."""
    extra_args: tuple[str, ...] = ()
    """Extra SUMO command-line arguments, appended verbatim."""

    def __post_init__(self) -> None:
        s = self.SECTION
        _require(self.step_length_s > 0, f"{s}.step_length_s must be > 0, got {self.step_length_s}")
        _require(
            self.lanechange_duration_s > 0,
            f"{s}.lanechange_duration_s must be > 0, got {self.lanechange_duration_s}",
        )
        _require(
            self.lateral_resolution_m is None or self.lateral_resolution_m > 0,
            f"{s}.lateral_resolution_m must be > 0 or null, got {self.lateral_resolution_m}",
        )
        _require(
            0 <= self.collision_mingap_factor <= 1,
            f"{s}.collision_mingap_factor must be in [0, 1], got {self.collision_mingap_factor}",
        )
        args = self.extra_args
        _require(
            not args or str(args[0]).startswith("-"),
            f"{s}.extra_args must start with a SUMO option ('--name'), got {list(args)}",
        )
        for arg in args:
            name = str(arg).lstrip("-").split("=", 1)[0]
            if str(arg).startswith("-") and name in MANAGED_SUMO_OPTIONS:
                raise ConfigError(
                    f"{s}.extra_args: {arg!r} is set by sumo_ayss itself "
                    f"({MANAGED_SUMO_OPTIONS[name]}); remove it"
                )


ActuatorMode = Literal["clipped", "highway_env"]


@dataclass(frozen=True)
class ActuatorConfig:
    """The POV's controller. Section ``env.actuator``.

    ``mode: clipped`` (default): ``a = clip((v_target - v) / time_constant_s, min, max)``,
    evaluated once per SUMO step; lane changes are SUMO's (constant lateral speed over
    ``env.sim.lanechange_duration_s``).

    ``mode: highway_env``: highway-env 1.8.2's ControlledVehicle (the paper's POV,
    :mod:`sumo_ayss.hwenv_laws`): ``a = (v_target - v) / time_constant_s`` **unclipped**,
    re-evaluated at each of ``substeps`` explicit-Euler sub-steps per SUMO step (3 per
    0.2 s = highway-env's 15 Hz), and its lane-centring steering loop on a kinematic
    bicycle for the cut-in (the lateral speed rises and decays smoothly, so Δv̄ depends
    on it as in highway-env). The POV's state is integrated in Python and put into SUMO
    exactly (``moveToXY``; cut-in needs SUMO's sublane model, ``env.sim.
    lateral_resolution_m``). ``accel_min_mps2``/``accel_max_mps2`` must keep their
    defaults there (highway-env does not clip); ``max_speed_mps`` is highway-env's
    ``MAX_SPEED`` soft cap.
    """

    SECTION: ClassVar[str] = "env.actuator"

    time_constant_s: float = 0.6
    """Speed-law time constant [s] (highway-env's ``TAU_ACC``)."""
    accel_min_mps2: float = -6.0
    accel_max_mps2: float = 6.0
    max_speed_mps: float = 40.0
    mode: ActuatorMode = "clipped"
    """``clipped`` (ours, default) or ``highway_env`` (highway-env's ControlledVehicle)."""
    substeps: int = 3
    """Euler sub-steps per SUMO step of highway-env's laws (POV in mode ``highway_env``,
    and any highway-env IDM VUT): 3 with a 0.2 s step = highway-env's 15 Hz."""
    tau_lateral_s: float = 0.6
    """highway-env ``TAU_LATERAL`` [s] (mode ``highway_env``)."""
    tau_heading_s: float = 0.2
    """highway-env ``TAU_HEADING`` [s] (mode ``highway_env``)."""
    lane_change_done_m: float = 0.1
    """Mode ``highway_env``: the POV counts as changing lanes (cut-in reward phase) until
    its centre is within this distance [m] of its target lane's centre line (highway-env's
    lateral loop approaches the centre line only asymptotically)."""

    def __post_init__(self) -> None:
        s = self.SECTION
        _require(
            self.time_constant_s > 0, f"{s}.time_constant_s must be > 0, got {self.time_constant_s}"
        )
        _require(
            self.accel_min_mps2 < 0 < self.accel_max_mps2,
            f"{s}.accel_min_mps2 must be < 0 < accel_max_mps2, got "
            f"[{self.accel_min_mps2}, {self.accel_max_mps2}]",
        )
        _require(self.max_speed_mps > 0, f"{s}.max_speed_mps must be > 0, got {self.max_speed_mps}")
        _require(
            self.mode in typing.get_args(ActuatorMode),
            f"{s}.mode must be one of {list(typing.get_args(ActuatorMode))}, got {self.mode!r}",
        )
        _require(
            isinstance(self.substeps, int) and self.substeps >= 1,
            f"{s}.substeps must be an integer >= 1, got {self.substeps!r}",
        )
        for name in ("tau_lateral_s", "tau_heading_s", "lane_change_done_m"):
            value = getattr(self, name)
            _require(value > 0, f"{s}.{name} must be > 0, got {value}")
        if self.mode == "highway_env":
            _require(
                (self.accel_min_mps2, self.accel_max_mps2) == (-6.0, 6.0),
                f"{s}.accel_min_mps2/accel_max_mps2 are not used in mode highway_env "
                "(highway-env's ControlledVehicle does not clip); remove them, got "
                f"[{self.accel_min_mps2}, {self.accel_max_mps2}]",
            )

    @property
    def highway_env(self) -> bool:
        """Whether the POV runs highway-env's ControlledVehicle."""
        return self.mode == "highway_env"


@dataclass(frozen=True)
class OddConfig:
    """Initial conditions are drawn uniformly from these ranges. Section ``env.odd``.

    Defaults: both speeds in [10, 30] m/s (30 m/s = the speed limit) and a bumper-to-bumper
    gap in [2, 25] m, so that most episodes start where the adversarial reward (zero beyond
    20 m) can be earned within the 5 s episode.
    """

    SECTION: ClassVar[str] = "env.odd"

    pov_speed_mps: tuple[float, float] = (10.0, 30.0)
    vut_speed_mps: tuple[float, float] = (10.0, 30.0)
    gap_m: tuple[float, float] = (2.0, 25.0)
    """Longitudinal gap POV rear bumper - VUT front bumper [m]."""

    def __post_init__(self) -> None:
        for name in ("pov_speed_mps", "vut_speed_mps", "gap_m"):
            value = tuple(float(v) for v in getattr(self, name))
            object.__setattr__(self, name, value)
            _check_range(f"{self.SECTION}.{name}", value, low=0.0)


@dataclass(frozen=True)
class RewardShape:
    """Adversarial reward R_A as a function of headway h [m], 0 <= R_A <= 1.

    ``R_A(peak_m) = 1``; for ``h >= zero_m`` it is 0; between the two it falls as
    ``1 - u`` (linear), ``(1 - u)²`` (quadratic) or ``exp(-3u)`` rescaled to reach 0 at
    ``u = 1`` (exponential), with ``u = (h - peak_m) / (zero_m - peak_m)``. Below the peak it
    rises linearly from ``value_at_contact`` at h = 0 to 1 at the peak. The paper shows these
    curves only as figures; the defaults are ours and are drawn in ``docs/reward_shapes.png``.
    """

    kind: ShapeKind = "linear"
    peak_m: float = 0.25
    zero_m: float = 20.0
    value_at_contact: float = 0.5

    def validate(self, where: str) -> None:
        _require(
            self.kind in typing.get_args(ShapeKind),
            f"{where}.kind must be one of {list(typing.get_args(ShapeKind))}, got {self.kind!r}",
        )
        _require(self.peak_m >= 0, f"{where}.peak_m must be >= 0, got {self.peak_m}")
        _require(
            self.zero_m > self.peak_m,
            f"{where}.zero_m must be > peak_m ({self.peak_m}), got {self.zero_m}",
        )
        _require(
            0 <= self.value_at_contact <= 1,
            f"{where}.value_at_contact must be in [0, 1], got {self.value_at_contact}",
        )


@dataclass(frozen=True)
class RewardConfig:
    """R = alpha_adversarial·R_A + alpha_collision·R_C with R_C = -1 on a collision, else 0.

    A collision therefore gets the minimum reward ``-alpha_collision`` (R_A is 0 then) and
    ends the episode. Section ``env.reward``.
    """

    SECTION: ClassVar[str] = "env.reward"

    alpha_adversarial: float = 1.0
    alpha_collision: float = 10.0
    same_lane: RewardShape = field(default_factory=RewardShape)
    """R_A while POV and VUT share a lane (car-following, and cut-in after the change)."""
    lane_change: RewardShape = field(
        default_factory=lambda: RewardShape(peak_m=1.0, zero_m=5.0, value_at_contact=0.5)
    )
    """R_A while the POV changes lanes (cut-in only)."""

    def __post_init__(self) -> None:
        s = self.SECTION
        _require(
            self.alpha_adversarial > 0,
            f"{s}.alpha_adversarial must be > 0, got {self.alpha_adversarial}",
        )
        _require(
            self.alpha_collision > 0, f"{s}.alpha_collision must be > 0, got {self.alpha_collision}"
        )
        self.same_lane.validate(f"{s}.same_lane")
        self.lane_change.validate(f"{s}.lane_change")

    @property
    def min_reward(self) -> float:
        """The reward of a collision step (the smallest reward there is)."""
        return -self.alpha_collision

    @property
    def max_reward(self) -> float:
        return self.alpha_adversarial


@dataclass(frozen=True)
class EnvConfig:
    """One testing environment: case, VUT, timing, ODD, reward, actuator and SUMO options."""

    SECTION: ClassVar[str] = "env"

    case: Case = "car_following"
    vut: str = "pi1"
    """Name of the VUT in ``vuts`` (built-ins: pi1, pi2)."""
    vuts: Mapping[str, VehicleType] = field(default_factory=lambda: dict(BUILTIN_VUTS))
    """VUT catalog: the built-ins plus any defined in YAML."""
    pov: VehicleType = POV_TYPE
    episode_s: float = 5.0
    decision_period_s: float = 0.2
    """Policy period [s] (5 Hz in the paper); a multiple of ``sim.step_length_s``."""
    network: Path | None = None
    """SUMO .net.xml; None = the built-in network of the case."""
    odd: OddConfig = field(default_factory=OddConfig)
    reward: RewardConfig = field(default_factory=RewardConfig)
    actuator: ActuatorConfig = field(default_factory=ActuatorConfig)
    sim: SimConfig = field(default_factory=SimConfig)

    def __post_init__(self) -> None:
        s = self.SECTION
        _require(
            self.case in typing.get_args(Case),
            f"{s}.case must be one of {list(typing.get_args(Case))}, got {self.case!r}",
        )
        object.__setattr__(self, "vuts", types.MappingProxyType(dict(self.vuts)))
        for name, vt in self.vuts.items():
            vt.validate(f"{s}.vuts.{name}")
        self.pov.validate(f"{s}.pov")
        if self.vut not in self.vuts:
            close = difflib.get_close_matches(self.vut, list(self.vuts), n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise ConfigError(f"{s}.vut must be one of {sorted(self.vuts)}, got {self.vut!r}{hint}")
        _require(self.episode_s > 0, f"{s}.episode_s must be > 0, got {self.episode_s}")
        ratio = self.decision_period_s / self.sim.step_length_s
        _require(
            self.decision_period_s > 0 and abs(ratio - round(ratio)) < 1e-9 and round(ratio) >= 1,
            f"{s}.decision_period_s must be a positive multiple of sim.step_length_s "
            f"({self.sim.step_length_s}), got {self.decision_period_s}",
        )
        _require(
            not self.actuator.highway_env or round(ratio) == 1,
            f"{s}.decision_period_s must equal sim.step_length_s with env.actuator.mode "
            f"highway_env (one SUMO step per decision, {self.actuator.substeps} highway-env "
            f"sub-steps inside it: actuator.substeps), got {self.decision_period_s} and "
            f"{self.sim.step_length_s}",
        )
        _require(
            not (
                self.actuator.highway_env
                and self.case == "cut_in"
                and self.sim.lateral_resolution_m is None
            ),
            f"{s}.sim.lateral_resolution_m must be set (e.g. 0.1) with env.actuator.mode "
            "highway_env in cut_in: the POV's free lateral position needs SUMO's sublane model",
        )
        if self.network is not None:
            path = Path(self.network)
            object.__setattr__(self, "network", path)
            _require(path.is_file(), f"{s}.network: file not found: {path}")
            check_sumo_network(path, f"{s}.network")
        top = self.actuator.max_speed_mps
        _require(
            self.odd.pov_speed_mps[1] <= top,
            f"{s}.odd.pov_speed_mps max ({self.odd.pov_speed_mps[1]}) must be <= "
            f"env.actuator.max_speed_mps ({top}): the POV could not drive its initial speed",
        )

    @property
    def vut_type(self) -> VehicleType:
        return self.vuts[self.vut]

    @property
    def steps_per_decision(self) -> int:
        return round(self.decision_period_s / self.sim.step_length_s)

    @property
    def max_decisions(self) -> int:
        """Decisions per episode (25 for 5 s at 5 Hz)."""
        return round(self.episode_s / self.decision_period_s)


# ----------------------------------------------------------------------------------------
# Generic mapping -> dataclass construction (used for YAML and for run folders).
# ----------------------------------------------------------------------------------------


def _unknown_key(where: str, key: str, allowed: list[str]) -> ConfigError:
    close = difflib.get_close_matches(key, allowed, n=1)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    return ConfigError(f"{where}: unknown key {key!r}{hint}; allowed: {sorted(allowed)}")


def _convert(tp: Any, value: Any, where: str, base_dir: Path, default: Any) -> Any:
    origin = typing.get_origin(tp)
    args = typing.get_args(tp)
    if tp is ControllerSpec:  # free-form params: parsed and validated by the catalog
        if isinstance(value, ControllerSpec):
            return value
        return ControllerSpec.from_mapping(value, where)
    if dataclasses.is_dataclass(tp) and isinstance(tp, type):
        if isinstance(value, tp):
            return value
        return build(tp, value, where, base_dir, default)
    if tp is VehicleType:
        return VehicleType.from_mapping(value, where)
    if origin in (types.UnionType, typing.Union):
        if value is None and type(None) in args:
            return None
        non_none = [a for a in args if a is not type(None)]
        return _convert(non_none[0], value, where, base_dir, default)
    if origin is Literal:
        if value not in args:
            raise ConfigError(f"{where} must be one of {list(args)}, got {value!r}")
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
        merged = dict(default or {}) if args and args[1] is VehicleType else {}
        for k, v in value.items():
            merged[str(k)] = _convert(args[1], v, f"{where}.{k}", base_dir, merged.get(str(k)))
        return merged
    raise ConfigError(f"{where}: unsupported type {tp!r}")  # pragma: no cover


def build(cls: type, data: Any, where: str, base_dir: Path, default: Any = None) -> Any:
    """Build dataclass ``cls`` from a mapping, over ``default`` (or the class defaults)."""
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
            raise _unknown_key(where or "config", str(key), names)
        sub_default = getattr(base, key) if base is not None else _field_default(cls, key)
        child = f"{where}.{key}" if where else str(key)
        kwargs[key] = _convert(hints[key], value, child, base_dir, sub_default)
    if base is not None:
        return dataclasses.replace(base, **kwargs)
    return cls(**kwargs)


def _field_default(cls: type, name: str) -> Any:
    f = next(f for f in dataclasses.fields(cls) if f.name == name)
    if f.default is not dataclasses.MISSING:
        return f.default
    if f.default_factory is not dataclasses.MISSING:
        return f.default_factory()
    return None


def to_dict(obj: Any) -> Any:
    """Plain YAML-safe form of a config (the exact resolved config a run used)."""
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {f.name: to_dict(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    if isinstance(obj, Mapping):
        return {str(k): to_dict(v) for k, v in obj.items()}
    if isinstance(obj, tuple | list):
        return [to_dict(v) for v in obj]
    if isinstance(obj, Path):
        return str(obj)
    return obj


def read_yaml(path: str | Path) -> dict[str, Any]:
    """Read a YAML mapping; a missing file or a non-mapping gives a ConfigError."""
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"config file not found: {path}")
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as e:
        raise ConfigError(f"{path}: unreadable ({e})") from e
    data = safe_load_yaml(text, str(path))
    if data is None:
        raise ConfigError(
            f"{path}: the file is empty; write at least one section (an empty file would "
            "silently run every default)"
        )
    if not isinstance(data, Mapping):
        raise ConfigError(f"{path}: top level must be a mapping, got {type(data).__name__}")
    return dict(data)


class _UniqueKeyLoader(yaml.SafeLoader):
    """PyYAML's safe loader, refusing a key given twice in one mapping (PyYAML keeps the last)."""


def _construct_unique_mapping(loader: yaml.SafeLoader, node: yaml.MappingNode) -> Any:
    loader.flatten_mapping(node)
    seen: dict[Any, Any] = {}
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=True)
        if key in seen:
            raise yaml.constructor.ConstructorError(
                None,
                None,
                f"duplicate key {key!r} (first at line {seen[key].line + 1}); each key may "
                "appear once per mapping",
                key_node.start_mark,
            )
        seen[key] = key_node.start_mark
    return loader.construct_mapping(node, deep=True)


_UniqueKeyLoader.add_constructor(
    yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_unique_mapping
)


def _one_line(text: str) -> str:
    return " ".join(text.split())


def safe_load_yaml(text: str, name: str) -> Any:
    """YAML from ``text`` (safe types only, duplicate keys refused); errors name ``name``."""
    try:
        return yaml.load(text, Loader=_UniqueKeyLoader)
    except yaml.YAMLError as e:
        raise ConfigError(f"{name}: invalid YAML: {_one_line(str(e))}") from e


#: Seeds are passed to SUMO's ``--seed`` (a C int), numpy and torch: the common range.
SEED_MAX = 2**31 - 1


def check_seed(seed: Any, where: str) -> int:
    """``seed`` as an int in [0, SEED_MAX], else a :class:`ConfigError` naming ``where``."""
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed <= SEED_MAX:
        raise ConfigError(f"{where} must be an integer in [0, {SEED_MAX}], got {seed!r}")
    return int(seed)


def check_out_dir(path: Path, where: str) -> None:
    """Refuse an output folder that is, or lies under, an existing file (before any work)."""
    for p in (Path(path), *Path(path).parents):
        if p.exists():
            if not p.is_dir():
                raise ConfigError(f"{where}: {p} is a file; give a folder (it may not exist yet)")
            return


def check_sumo_network(path: Path, where: str) -> None:
    """Refuse a file that is not a SUMO ``.net.xml`` before libsumo loads it.

    libsumo dies with a segmentation fault (no message) on some XML files that are not SUMO
    networks, so the root element (``<net>``) is checked here, in Python, first.
    """
    import xml.etree.ElementTree as ET

    try:
        for _event, elem in ET.iterparse(path, events=("start",)):
            tag = elem.tag.rpartition("}")[2]
            if tag != "net":
                raise ConfigError(
                    f"{where}: {path} is not a SUMO network (root element <{tag}>, expected "
                    "<net>; build one with netconvert)"
                )
            return
    except ET.ParseError as e:
        raise ConfigError(f"{where}: {path} is not valid XML ({e})") from e
    except OSError as e:
        raise ConfigError(f"{where}: cannot read {path} ({e})") from e
    raise ConfigError(f"{where}: {path} is empty, not a SUMO network")


def env_config_from_mapping(data: Mapping[str, Any], base_dir: Path | None = None) -> EnvConfig:
    """Build an :class:`EnvConfig` from the contents of an ``env:`` section."""
    return build(EnvConfig, data, "env", base_dir or Path.cwd())


def write_yaml(path: Path, data: Any) -> None:
    """Write YAML atomically (temp file + rename), so a kill never leaves half a file."""
    from sumo_ayss.atomic import atomic_write_text

    atomic_write_text(path, yaml.safe_dump(data, sort_keys=False))
