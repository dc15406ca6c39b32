"""One registry type: records by name, in registration order (the cases, the ranking modes).

Standard library and :mod:`sumo_ayss.util` only, so that the configuration can validate a
name against a registry without loading numpy.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Generic, TypeVar

from sumo_ayss.util.errors import ConfigError
from sumo_ayss.util.validation import require, suggest

__all__ = ["Registry"]

T = TypeVar("T")


class Registry(Generic[T]):
    """Records of one kind by name, in registration order (listings follow it).

    Registering an equal record again under its name is a no-op; a different record under
    a known name needs ``replace=True``. Unknown names raise :class:`ConfigError` naming the
    registered ones (and the closest, if any).

    Args:
        kind: What a record is, for messages: ``"case"``, ``"mode"``.
    """

    def __init__(self, kind: str) -> None:
        self.kind = kind
        self._records: dict[str, T] = {}

    def register(self, name: str, record: T, *, replace: bool = False) -> T:
        """Add ``record`` under ``name`` and return it.

        Raises:
            ConfigError: If the name is taken by another record and ``replace`` is False.
        """
        old = self._records.get(name)
        require(
            old is None or old == record or replace,
            f"{self.kind} {name!r} is already registered (pass replace=True to replace it)",
        )
        self._records[name] = record
        return record

    def unregister(self, name: str) -> T:
        """Remove the record ``name`` and return it (tests register toy records).

        Raises:
            ConfigError: If no record of that name is registered.
        """
        self.get(name)
        return self._records.pop(name)

    def get(self, name: str) -> T:
        """The record ``name``.

        Raises:
            ConfigError: If no record of that name is registered; the message lists them.
        """
        record = self._records.get(name) if isinstance(name, str) else None
        if record is None:
            names = self.names()
            hint = suggest(name, names) if isinstance(name, str) else ""
            raise ConfigError(f"unknown {self.kind} {name!r}{hint}; allowed: {list(names)}")
        return record

    def find(self, name: str) -> T | None:
        """The record ``name``, or None."""
        return self._records.get(name)

    def names(self) -> tuple[str, ...]:
        """The registered names, in registration order."""
        return tuple(self._records)

    def records(self) -> tuple[T, ...]:
        """The registered records, in registration order."""
        return tuple(self._records.values())

    def __contains__(self, name: object) -> bool:
        return name in self._records

    def __iter__(self) -> Iterator[T]:
        return iter(tuple(self._records.values()))
