"""YAML in and out: safe types only, a key given twice refused, atomic writes."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml

from sumo_ayss.util.errors import ConfigError


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


def write_yaml(path: Path, data: Any) -> None:
    """Write YAML atomically (temp file + rename), so a kill never leaves half a file."""
    from sumo_ayss.util.atomic import atomic_write_text

    atomic_write_text(path, yaml.safe_dump(data, sort_keys=False))
