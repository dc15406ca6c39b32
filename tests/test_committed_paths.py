"""Committed results and docs name files relative to the repository, never by a machine path.

A run folder records where it lay (``run_dir`` in its summaries, ``command.txt``); made
outside the repository root (e.g. from another checkout) those become absolute paths of one
machine, which mean nothing in a clone.
"""

from __future__ import annotations

import re

from sumo_ayss.config import PROJECT_ROOT

#: Prefixes of paths that exist only on some machine.
MACHINE_PATH = re.compile(r"(?<![\w.])/(?:work|tmp|root|home|Users)/")
TEXT_SUFFIXES = {".json", ".md", ".csv", ".yaml", ".yml", ".txt", ".html"}


def test_no_committed_result_or_doc_names_a_machine_path() -> None:
    offenders = []
    for top in ("results", "docs"):
        for path in sorted((PROJECT_ROOT / top).rglob("*")):
            if path.suffix not in TEXT_SUFFIXES or not path.is_file():
                continue
            text = path.read_text(encoding="utf-8", errors="replace")
            if MACHINE_PATH.search(text):
                offenders.append(str(path.relative_to(PROJECT_ROOT)))
    readme = (PROJECT_ROOT / "README.md").read_text(encoding="utf-8")
    if MACHINE_PATH.search(readme):
        offenders.append("README.md")
    assert not offenders, f"machine paths in: {offenders[:10]} ({len(offenders)} files)"
