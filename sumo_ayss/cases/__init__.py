"""The case registry: one :class:`Case` record per testing case, one module per case.

A case (``car_following``, ``cut_in``) is everything that differs between the paper's two
experiments: its env class, SUMO network and lane count, observation columns, AYSS
indicator (its ``ayss.csv`` name, how verdicts and plots name it) and AYSS row builder,
the columns of its outcome table, the paper's reference table and figure, and the report's
wording. The rest of the package asks the registry (``get_case(cfg.case).lanes``) instead of
branching on case names.

Two levels, because of the layering (config → sim → envs → … → analysis → report):

* **Data** — a :class:`Case` is a frozen record of plain values. This package imports only
  the standard library, :mod:`sumo_ayss.util.errors` and :mod:`sumo_ayss.util.validation`, so the
  configuration (which validates ``env.case`` against it), the analysis and the report read
  it without loading torch, libsumo, SB3 or matplotlib.
* **Bindings** — the env class and the AYSS row builder live in the layers that may import
  SUMO (``envs/``, ``scenarios/``); a case names them by import path
  (``"sumo_ayss.envs.cut_in:CutInEnv"``) and :meth:`Case.env_class` /
  :meth:`Case.ayss_row_builder` import them on first use. Facts of an env's action space
  (e.g. the POV's action while a VUT's response is measured) stay class attributes of the
  env.

Adding a case: write its env (and AYSS row builder) and one module here that calls
:func:`register_case` with its record, imported below. A case registered at run time
(tests, plugins) is seen by configuration validation, analysis and report at once; the
``ayss.csv`` schema, fixed when :mod:`sumo_ayss.run_folder` is imported, accepts the
indicator columns of the cases registered by then.

Lookups: :func:`get_case` (raises :class:`~sumo_ayss.util.errors.ConfigError` naming the
registered cases), :func:`case_names`, :func:`registered_cases`, :func:`case_info` (lenient:
a generic record for a run folder of an unknown case), :func:`case_of_indicator`.
"""

from __future__ import annotations

# The built-in cases, registered in import order (reports list cases in registry order).
from sumo_ayss.cases.car_following import CAR_FOLLOWING
from sumo_ayss.cases.cut_in import CUT_IN
from sumo_ayss.cases.lead_and_cut_in import LEAD_AND_CUT_IN
from sumo_ayss.cases.registry import (
    BASE_OBSERVATION,
    OUTCOME_COLUMNS,
    ROAD_EDGE,
    Case,
    Indicator,
    PaperRow,
    case_info,
    case_names,
    case_of_indicator,
    default_grid_cases,
    get_case,
    indicator_columns,
    register_case,
    registered_cases,
    unregister_case,
)

#: The case of an ``env`` section that names none.
DEFAULT_CASE = CAR_FOLLOWING.name

__all__ = [
    "BASE_OBSERVATION",
    "CAR_FOLLOWING",
    "CUT_IN",
    "DEFAULT_CASE",
    "LEAD_AND_CUT_IN",
    "OUTCOME_COLUMNS",
    "ROAD_EDGE",
    "Case",
    "Indicator",
    "PaperRow",
    "case_info",
    "case_names",
    "case_of_indicator",
    "default_grid_cases",
    "get_case",
    "indicator_columns",
    "register_case",
    "registered_cases",
    "unregister_case",
]
