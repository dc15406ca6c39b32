"""The case record, its registry and the naming records it holds (see :mod:`sumo_ayss.cases`).

Standard library and :mod:`sumo_ayss.util` only (the registry: :class:`~sumo_ayss.util.
registry.Registry`, shared with the ranking modes).
"""

from __future__ import annotations

import importlib
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from sumo_ayss.util.errors import ConfigError
from sumo_ayss.util.registry import Registry
from sumo_ayss.util.validation import require, suggest

__all__ = [
    "BASE_OBSERVATION",
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

#: The edge every case's pair drives on (its network's only edge, built-in or ``env.network``);
#: lane ``road_0`` is the rightmost, and a case needs :attr:`Case.lanes` lanes of it.
ROAD_EDGE = "road"

#: The observation columns every case starts with (the AYSS Monte Carlo samples them):
#: POV speed [m/s], VUT speed [m/s], headway h [m] (POV rear bumper minus VUT front bumper).
BASE_OBSERVATION: tuple[str, ...] = ("v_pov_mps", "v_vut_mps", "h_m")

#: Columns the report's outcome table can show (:attr:`Case.outcome_columns`), key -> header.
#: ``lc_*``: over the episodes with a lane change and no collision (the paper's Table III).
OUTCOME_COLUMNS: Mapping[str, str] = {
    "crash": "crash rate c [%]",
    "lane_change": "lane-change rate lc [%]",
    "lc_return": "r̄_epi (LC, no crash)",
    "lc_headway": "h̄ [m] (LC, no crash)",
    "lc_episodes": "episodes LC, no crash",
    "return": "r̄_epi",
    "headway": "h̄ [m]",
    "return_all": "r̄_epi (all)",
    "headway_all": "h̄ [m] (all)",
}

_NAME = re.compile(r"[a-z][a-z0-9_]*")
_IMPORT_PATH = re.compile(r"[A-Za-z_][\w.]*:[A-Za-z_]\w*")


@dataclass(frozen=True)
class Indicator:
    """How to name an aggressiveness indicator in a verdict sentence.

    Attributes:
        name: Human name, e.g. ``"POV acceleration"``.
        unit: Unit, e.g. ``"m/s²"``; may be empty.
        comparative: What the safer VUT's SPCPs do, with ``{amount}`` (value and unit) and
            optionally ``{name}``; e.g. ``"brake {amount} harder"``.
    """

    name: str = "aggressiveness indicator"
    unit: str = ""
    comparative: str = "have a {name} {amount} lower"

    def amount(self, value: float) -> str:
        """Formats ``value`` with two decimals and the unit, e.g. ``"1.23 m/s²"``."""
        return f"{value:.2f} {self.unit}".rstrip()

    def phrase(self, value: float) -> str:
        """The comparative phrase for a difference ``value`` (>= 0) in the indicator."""
        return self.comparative.format(name=self.name, amount=self.amount(value))


@dataclass(frozen=True)
class PaperRow:
    """One row of the paper's Table II / III (highway-env, not this testbed).

    Attributes:
        vut: VUT name (pi1: s0 = 10 m, pi2: s0 = 20 m).
        seed: Seed index 1..3 within the VUT (the paper's π*_1..6 in order).
        crash_pct: Crash rate c in %.
        lane_change_pct: Lane-change rate lc in % (cut-in), else None.
        mean_return: Mean episode reward r̄_epi.
        mean_final_headway_m: Mean headway at the last step h̄, m.
    """

    vut: str
    seed: int
    crash_pct: float
    lane_change_pct: float | None
    mean_return: float
    mean_final_headway_m: float


@dataclass(frozen=True)
class Case:
    """Everything that differs between cases, as data; the heavy parts as import paths.

    Only ``name`` is required: the defaults describe a case the package knows nothing about
    (what :func:`case_info` returns for a run folder of an unregistered case). A case that
    runs also needs ``network``, ``env`` and ``ayss_rows``.

    Attributes:
        name: Registry key, folder name under a pipeline's output and ``env.case`` value
            (lower-case letters, digits, ``_``).
        title: Section title, e.g. ``"One-lane car-following"``; default ``name``.
        network: Stem of the built-in SUMO network, ``networks/<network>.net.xml``.
        lanes: Lanes of that road (and of every road of a parallel network).
        lane_change: The POV may change lanes: outcomes carry the lane-change rate and the
            lane-change-no-collision subset, the learning curves a lane-change panel, and
            the highway-env actuator needs SUMO's sublane model.
        env: ``"module:Class"`` of the env (a :class:`~sumo_ayss.envs.pair_env.PairEnv`).
        gym_id: Gymnasium id registered for ``env`` on ``import sumo_ayss``; empty: none.
        observation: Observation columns; the first three are :data:`BASE_OBSERVATION`.
        ayss_fixed_obs: Values of the columns after the first three in the AYSS Monte
            Carlo (e.g. cut-in's ``same_lane = 0``: the cut-in moment).
        ayss_rows: ``"module:function"`` building the AYSS rows of the kept samples
            (signature of :func:`sumo_ayss.scenarios.ayss.car_following_rows`).
        indicator_column: The ``indicator_name`` value of the case's ``ayss.csv`` rows.
        indicator: Naming of the aggressiveness indicator for verdict sentences.
        axis_label: Matplotlib axis label of the indicator, with unit.
        symbol: The indicator's symbol in text (HTML / Markdown).
        outcome_columns: Keys of :data:`OUTCOME_COLUMNS` the outcome table shows, in order.
        outcome_note: Sentence appended to the outcome table's note.
        paper_figure: The paper figure the indicator plot reproduces.
        paper_table: The paper table the outcome table reproduces.
        paper_rows: The paper's outcome table, shown for reference; empty: none.
        exposure_caution: Empty when exposure mode recovered known safety orders in this
            case (results/ladders); otherwise the caution every exposure verdict carries.
        one_decision_note: Said by the discriminability section when responses were
            measured over one decision; empty: nothing to say.
        vec_env: The env can run as a member of a
            :class:`~sumo_ayss.envs.vec_env.PairVecEnv` (several pairs in one simulation);
            False: ``train.n_envs`` must be 1 (the configuration refuses more).
        default_grid: A pipeline whose ``grid`` names no cases runs this one
            (:func:`default_grid_cases`); False: only where a grid names it.
        povs: How many POVs an episode has (more than one: the supporting POVs' forbidden
            contacts, ``env.reward.pov_failure_penalty``).
        start_filter: ``"module:function"``, ``(EnvConfig) -> (InitialCondition) -> bool``:
            whether a start drawn from the ODD is admissible when ``env.odd.
            exclude_inevitable`` is set (no inevitable collision); empty: the case has no
            such check and the option is refused.
    """

    name: str
    title: str = ""
    network: str = ""
    lanes: int = 1
    lane_change: bool = False
    env: str = ""
    gym_id: str = ""
    observation: tuple[str, ...] = BASE_OBSERVATION
    ayss_fixed_obs: tuple[float, ...] = ()
    ayss_rows: str = ""
    indicator_column: str = ""
    indicator: Indicator = field(default_factory=Indicator)
    axis_label: str = "aggressiveness indicator"
    symbol: str = "indicator"
    outcome_columns: tuple[str, ...] = ("crash", "return", "headway")
    outcome_note: str = ""
    paper_figure: str = "—"
    paper_table: str = "—"
    paper_rows: tuple[PaperRow, ...] = ()
    exposure_caution: str = ""
    one_decision_note: str = ""
    vec_env: bool = True
    default_grid: bool = True
    povs: int = 1
    start_filter: str = ""

    def __post_init__(self) -> None:
        where = f"case {self.name!r}"
        require(
            isinstance(self.name, str) and _NAME.fullmatch(self.name) is not None,
            f"case name must be lower-case letters, digits and '_', got {self.name!r}",
        )
        if not self.title:
            object.__setattr__(self, "title", self.name)
        require(self.lanes >= 1, f"{where}: lanes must be >= 1, got {self.lanes}")
        require(
            self.observation[:3] == BASE_OBSERVATION,
            f"{where}: observation must start with {list(BASE_OBSERVATION)}, "
            f"got {list(self.observation)}",
        )
        require(
            len(self.ayss_fixed_obs) == len(self.observation) - 3,
            f"{where}: ayss_fixed_obs must give one value per observation column after the "
            f"first three ({list(self.observation[3:])}), got {list(self.ayss_fixed_obs)}",
        )
        for key in self.outcome_columns:
            require(
                key in OUTCOME_COLUMNS,
                f"{where}: unknown outcome column {key!r}{suggest(key, OUTCOME_COLUMNS)}; "
                f"allowed: {list(OUTCOME_COLUMNS)}",
            )
        for attr in ("env", "ayss_rows", "start_filter"):
            path = getattr(self, attr)
            require(
                not path or _IMPORT_PATH.fullmatch(path) is not None,
                f"{where}: {attr} must be 'package.module:name', got {path!r}",
            )

    def env_class(self) -> type[Any]:
        """The env class (imports its module: libsumo, gymnasium)."""
        env: type[Any] = _resolve(self, "env")
        return env

    def ayss_row_builder(self) -> Callable[..., Any]:
        """The AYSS row builder (imports its module)."""
        rows: Callable[..., Any] = _resolve(self, "ayss_rows")
        return rows

    def start_filter_factory(self) -> Callable[..., Any]:
        """The factory of :attr:`start_filter` (imports its module)."""
        factory: Callable[..., Any] = _resolve(self, "start_filter")
        return factory


def _resolve(case: Case, attr: str) -> Any:
    path = getattr(case, attr)
    if not path:
        raise ConfigError(f"case {case.name!r} has no {attr} (not a runnable case)")
    module, _, name = path.partition(":")
    return getattr(importlib.import_module(module), name)


# --------------------------------------------------------------------------- the registry

_REGISTRY: Registry[Case] = Registry("case")


def register_case(case: Case, *, replace: bool = False) -> Case:
    """Add ``case`` to the registry (in order: listings follow it) and return it.

    Registering an equal record again is a no-op; a different record under a known name
    needs ``replace=True``.

    Raises:
        ConfigError: If the name is taken by another record, or its indicator column is
            another case's.
    """
    if case.name in _REGISTRY and not replace:
        _REGISTRY.register(case.name, case)  # raises unless it is the same record
    other = case_of_indicator(case.indicator_column) if case.indicator_column else None
    require(
        other in (None, case.name),
        f"case {case.name!r}: indicator column {case.indicator_column!r} is case {other!r}'s",
    )
    return _REGISTRY.register(case.name, case, replace=replace)


def unregister_case(name: str) -> Case:
    """Remove a registered case and return it (tests register toy cases and remove them)."""
    return _REGISTRY.unregister(name)


def get_case(name: str) -> Case:
    """The registered case ``name``.

    Raises:
        ConfigError: If no case of that name is registered; the message lists them.
    """
    return _REGISTRY.get(name)


def case_names() -> tuple[str, ...]:
    """Names of the registered cases, in registration order."""
    return _REGISTRY.names()


def registered_cases() -> tuple[Case, ...]:
    """The registered cases, in registration order."""
    return _REGISTRY.records()


def default_grid_cases() -> tuple[str, ...]:
    """The cases of a pipeline grid that names none, in registration order."""
    return tuple(c.name for c in _REGISTRY if c.default_grid)


def case_info(name: str) -> Case:
    """The registered case ``name``, else a generic description (for reading run folders of
    an unknown case without failing)."""
    case = _REGISTRY.find(name)
    if case is not None:
        return case
    return Case(name=name if _NAME.fullmatch(name) else "unknown", title=name)


def indicator_columns() -> tuple[str, ...]:
    """The AYSS indicator columns (``ayss.csv``'s ``indicator_name``) of the registered cases."""
    return tuple(c.indicator_column for c in _REGISTRY if c.indicator_column)


def case_of_indicator(column: str) -> str | None:
    """The case whose AYSS rows carry ``indicator_name == column``, or None."""
    return next((c.name for c in _REGISTRY if c.indicator_column == column), None)
