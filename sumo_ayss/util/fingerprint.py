"""One fingerprint of inputs: what a stage's done marker, a cross-play cell's file name and a
VUT's definition key record.

Imports nothing of the package.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

__all__ = ["fingerprint"]


def fingerprint(*parts: Any) -> str:
    """16 hex digits of SHA-256 over ``parts`` in order: a :class:`~pathlib.Path` counts
    by its file's bytes, anything else by its JSON (sorted keys; ``str()`` of what JSON
    cannot hold).

    Raises:
        OSError: A path's file cannot be read.
    """
    h = hashlib.sha256()
    for part in parts:
        if isinstance(part, Path):
            h.update(part.read_bytes())
        else:
            h.update(json.dumps(part, sort_keys=True, default=str).encode())
    return h.hexdigest()[:16]
