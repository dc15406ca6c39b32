"""The one validation idiom of every configuration section: checks that raise
:class:`~sumo_ayss.util.errors.ConfigError` naming the dotted field, the allowed values and what
was given (``env.sim.step_length_s must be > 0, got 0``), and the one "did you mean"
suggester.

A leaf module (standard library and :mod:`sumo_ayss.util.errors` only), so that the catalog, the
configuration sections, the agent's hyper-parameters and the report options can all use it
without importing one another.
"""

from __future__ import annotations

import difflib
import math
import numbers
from collections.abc import Collection, Iterable
from pathlib import Path
from typing import Any

from sumo_ayss.util.errors import ConfigError

#: Seeds are passed to SUMO's ``--seed`` (a C int), numpy and torch: the common range.
SEED_MAX = 2**31 - 1


def require(cond: bool, message: str) -> None:
    """Raise :class:`ConfigError` with ``message`` unless ``cond`` holds."""
    if not cond:
        raise ConfigError(message)


def suggest(name: str, allowed: Iterable[str]) -> str:
    """`` (did you mean 'x'?)`` for the allowed name closest to ``name``, else ``""``."""
    close = difflib.get_close_matches(str(name), sorted(str(a) for a in allowed), n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""


def check_choice(where: str, value: Any, allowed: Collection[Any]) -> None:
    """Refuse ``value`` unless it is one of ``allowed``; the message suggests a close match.

    ``where`` is the dotted field (``env.case``); the message lists the allowed values.
    """
    if value in allowed:
        return
    hint = suggest(value, (str(a) for a in allowed)) if isinstance(value, str) else ""
    raise ConfigError(f"{where} must be one of {list(allowed)}, got {value!r}{hint}")


def unknown_key(where: str, key: Any, allowed: Iterable[str]) -> ConfigError:
    """The error for a key ``key`` of mapping ``where`` that is none of ``allowed``."""
    names = sorted(allowed)
    return ConfigError(f"{where}: unknown key {key!r}{suggest(str(key), names)}; allowed: {names}")


def check_keys(where: str, data: Iterable[Any], allowed: Iterable[str]) -> None:
    """Refuse any key of ``data`` that is not in ``allowed`` (see :func:`unknown_key`)."""
    names = set(allowed)
    for key in data:
        if key not in names:
            raise unknown_key(where, key, names)


def check_int(where: str, value: Any, low: int, none_ok: bool = False) -> None:
    """Refuse ``value`` unless it is an int (not a bool) >= ``low`` (or None if ``none_ok``)."""
    if none_ok and value is None:
        return
    if isinstance(value, bool) or not isinstance(value, int) or value < low:
        extra = " or null" if none_ok else ""
        raise ConfigError(f"{where} must be an int >= {low}{extra}, got {value!r}")


def check_number(
    where: str, value: Any, low: float, high: float = math.inf, low_open: bool = False
) -> None:
    """Refuse ``value`` unless it is a finite real number in the interval ``[low, high]``
    (``(low, high]`` with ``low_open``); the message gives the interval."""
    left = "(" if low_open else "["
    right = ")" if math.isinf(high) else "]"
    interval = f"{left}{low:g}, {'inf' if math.isinf(high) else f'{high:g}'}{right}"
    ok = (
        isinstance(value, int | float)
        and not isinstance(value, bool)
        and math.isfinite(value)
        and (value > low if low_open else value >= low)
        and value <= high
    )
    if not ok:
        raise ConfigError(f"{where} must be in {interval}, got {value!r}")


def check_range(where: str, value: Any, low: float = -math.inf) -> tuple[float, float]:
    """``value`` as a finite ``(min, max)`` with ``low <= min <= max``, else a ConfigError."""
    try:
        lo, hi = (float(v) for v in value)
    except (TypeError, ValueError):
        message = f"{where} must be [min, max] with finite numbers, got {value!r}"
        raise ConfigError(message) from None
    require(
        math.isfinite(lo) and math.isfinite(hi),
        f"{where} must be [min, max] with finite numbers, got {[lo, hi]}",
    )
    require(lo <= hi, f"{where} must have min <= max, got {[lo, hi]}")
    require(lo >= low, f"{where} min must be >= {low}, got {lo}")
    return lo, hi


def check_seed(seed: Any, where: str) -> int:
    """``seed`` as an int in [0, SEED_MAX], else a :class:`ConfigError` naming ``where``."""
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed <= SEED_MAX:
        raise ConfigError(f"{where} must be an integer in [0, {SEED_MAX}], got {seed!r}")
    return int(seed)


def check_sumo_seed(seed: Any) -> int | None:
    """``seed`` as an int in [0, SEED_MAX] for SUMO's ``--seed`` (numpy integers too, not a
    bool), or None (the env draws one); else a :class:`ConfigError` naming ``sumo_seed``."""
    if seed is None:
        return None
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral):
        ok = False
    else:
        ok = 0 <= int(seed) <= SEED_MAX
    if not ok:
        raise ConfigError(
            f"sumo_seed must be an integer in [0, {SEED_MAX}] (SUMO's --seed), got {seed!r}"
        )
    return int(seed)


def check_out_dir(path: Path, where: str) -> None:
    """Refuse an output folder that is, or lies under, an existing file (before any work)."""
    for p in (Path(path), *Path(path).parents):
        if p.exists():
            if not p.is_dir():
                raise ConfigError(f"{where}: {p} is a file; give a folder (it may not exist yet)")
            return


def check_sumo_network(
    path: Path, where: str, edge: str = "", min_lanes: int = 1, case: str = ""
) -> None:
    """Refuse a file that is not a SUMO ``.net.xml`` the envs can drive on, before libsumo
    loads it.

    libsumo dies with a segmentation fault (no message) on some XML files that are not SUMO
    networks (another root element than ``<net>``, an ``<edge>`` without ``<lane>``), and
    with a ``TraCIException`` when the edge its route names is missing; so the file is
    checked here, in Python, first.

    Args:
        path: The network file.
        where: The field that names it (``env.network``), first word of every message.
        edge: The edge the envs drive on (``road``); empty: not checked.
        min_lanes: The lanes ``edge`` needs (the case's lanes: 1 car-following, 2 cut-in).
        case: The case that needs them, for the message.
    """
    import xml.etree.ElementTree as ET

    head = f"{where}: {path}"
    root = ""
    road_lanes: int | None = None
    try:
        for event, elem in ET.iterparse(path, events=("start", "end")):
            tag = elem.tag.rpartition("}")[2]
            if not root:
                root = tag
                if tag != "net":
                    raise ConfigError(
                        f"{head} is not a SUMO network (root element <{tag}>, expected "
                        "<net>; build one with netconvert)"
                    )
                continue
            if event != "end" or tag != "edge":
                continue
            lanes = sum(1 for child in elem if child.tag.rpartition("}")[2] == "lane")
            require(lanes > 0, f"{head}: edge {elem.get('id')!r} has no lanes (<lane> elements)")
            if elem.get("id") == edge and elem.get("function", "normal") != "internal":
                road_lanes = lanes
            elem.clear()
    except ET.ParseError as e:
        raise ConfigError(f"{head} is not valid XML ({e})") from e
    except OSError as e:
        raise ConfigError(f"{where}: cannot read {path} ({e})") from e
    require(bool(root), f"{head} is empty, not a SUMO network")
    if not edge:
        return
    require(
        road_lanes is not None,
        f"{head} has no edge {edge!r} (the road the envs drive on, with >= {min_lanes} lane(s))",
    )
    require(
        road_lanes is not None and road_lanes >= min_lanes,
        f"{head}: edge {edge!r} has {road_lanes} lane(s), case {case!r} needs >= {min_lanes}",
    )
