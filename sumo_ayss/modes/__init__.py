"""The ranking-mode registry: one :class:`Mode` object per way of ranking VUTs, one module
per mode, registered the way :mod:`sumo_ayss.cases` registers cases.

A mode decides how a case's VUTs are scored, ranked and compared, and how its verdicts
read: ``crossplay`` (default; every SPCP against every VUT), ``exposure`` (each VUT's own
SPCPs) and ``paper`` (the paper's AYSS safety index). The rest of the package asks the
registry (``get_mode(options.mode).standings(analysis)``) instead of branching on mode
names: the stages check ``report.mode`` against it (:func:`check_mode`),
:func:`analyse_case` runs the analysis and asks :attr:`Mode.verdict` for the case's verdict
record and the report words it with :attr:`Mode.headline` (:func:`headline_text`), ``rank``
writes ``ranking.csv`` from :attr:`Mode.standings`, the report's leaderboard and verdict
callout read the mode's hooks, and the pipeline runs the cross-play stage when
:attr:`Mode.runs_crossplay`.

Layering: this package sits above :mod:`sumo_ayss.analysis` (which imports no mode) and
below the report; at module level it imports only the standard library, the error tree and
the range checks; its hooks import :mod:`sumo_ayss.analysis` when called, and nothing above
it. The configuration imports no mode: it checks ``report.mode``'s form, and the stages check
the name against this registry when they start (:func:`check_mode`).

How numbers, intervals and rankings read, in the modes' sentences and the report's tables
alike: :mod:`.formatting` (standard library only).

Adding a mode: one module here that calls :func:`register_mode` with its record, imported
below (rows of the modes follow in registry order).
"""

from __future__ import annotations

# The built-in modes, registered in import order (ranking rows follow it).
from sumo_ayss.modes.analyse import analyse_case, analyse_cases, input_problems
from sumo_ayss.modes.crossplay import CROSSPLAY
from sumo_ayss.modes.exposure import EXPOSURE
from sumo_ayss.modes.paper import PAPER
from sumo_ayss.modes.registry import (
    Mode,
    Standing,
    check_mode,
    get_mode,
    headline_text,
    missing_rows_line,
    mode_names,
    register_mode,
    registered_modes,
    unregister_mode,
)

#: The mode of a report and a ranking unless ``report.mode`` says otherwise (the same name
#: as :data:`sumo_ayss.config.report.DEFAULT_MODE`, which the configuration holds).
DEFAULT_MODE = CROSSPLAY.name

__all__ = [
    "CROSSPLAY",
    "DEFAULT_MODE",
    "EXPOSURE",
    "PAPER",
    "Mode",
    "Standing",
    "analyse_case",
    "analyse_cases",
    "check_mode",
    "get_mode",
    "headline_text",
    "input_problems",
    "missing_rows_line",
    "mode_names",
    "register_mode",
    "registered_modes",
    "unregister_mode",
]
