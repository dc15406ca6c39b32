"""Cross-play: every SPCP of a case against every VUT of that case, on common scenarios.

A VUT's own SPCP is one draw from a noisy search: two training seeds against the same VUT
can settle on different strategies (on a cut-in ladder, one seed's SPCP extracted 12.3
reward per episode and the other two 9.6 and 9.9 from the same VUT). Scoring each VUT by its
own SPCPs alone mixes that search noise into the comparison. Cross-play instead lets the
whole *pool* of SPCPs trained in a case (every VUT, every seed) drive against every VUT,
on the same outcome scenarios. Each SPCP is then a block: the difference between two VUTs
is read within one opponent (same network, same scenarios), which removes the opponent's
own quality from the comparison (:mod:`sumo_ayss.analysis.crossplay`).

:func:`run_crossplay` drives each opponent against each VUT exactly as the outcome stage
drives a VUT's own SPCP (:func:`~sumo_ayss.scenarios.outcome.run_outcome`): a fresh single
env of the VUT's config with SUMO seed = the opponent's training seed (the outcome stage
uses the run's seed), the ``n`` initial conditions of ``seed`` in order, the greedy policy
called on one observation per step. The diagonal "own SPCP vs own VUT" is therefore the
outcome table episode for episode, for every VUT law, action step and random stream (a
stochastic SUMO model draws the same numbers in both), and the cross-play stage checks it
(:func:`diagonal_check`). Within a seed block every VUT meets the same SUMO seed (common
random numbers). One row per (VUT, opponent, scenario) goes to
:data:`~sumo_ayss.run_folder.CROSSPLAY_SCHEMA`.

Why not the vec env (many pairs in one simulation, fewer Python calls per step): a pair
placed there takes another SUMO path (inserted while waiting), and a batch of N
observations gives the Q-network other last float bits than a batch of one (measured: all
5,000 of 5,000 rows differ, by up to 4e-6, between batch sizes 1 and 50), which flips the
greedy action at near-ties; stochastic models draw from streams shared by all pairs. Each
is a way for cross-play to drive another vehicle than the one the opponents were trained
and scored against (issue 21).
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from sumo_ayss.analysis.hazards import HAZARD_NAMES
from sumo_ayss.analysis.safety_measures import MEASURE_NAMES
from sumo_ayss.config import EnvConfig
from sumo_ayss.envs.odd import scenario_set, with_followers
from sumo_ayss.envs.pair_env import PairEnv
from sumo_ayss.records.table import Table, table_from_rows
from sumo_ayss.run_folder import CROSSPLAY_SCHEMA, DiagonalCheck
from sumo_ayss.scenarios.preventability import DEFAULT_REFERENCE, label_crashes
from sumo_ayss.scenarios.rollout import Policy, run_episodes
from sumo_ayss.util.errors import AyssError, ConfigError, DiagonalMismatchError
from sumo_ayss.vuts.controller_spec import controller_imports, controller_imports_allowed

__all__ = [
    "DIAGONAL_COLUMNS",
    "CellCache",
    "CellDone",
    "CellRunner",
    "CellTask",
    "Opponent",
    "check_diagonal",
    "check_one_world",
    "diagonal_check",
    "drive_cell",
    "run_crossplay",
]


@dataclass(frozen=True)
class Opponent:
    """One SPCP of the pool.

    Attributes:
        vut: The VUT it was trained against.
        seed: Its training seed.
        load: Builds its greedy policy for an env's spaces (called once: the pool's envs
            share their spaces).
    """

    vut: str
    seed: int
    load: Callable[[PairEnv], Policy]
    identity: str = ""
    """What tells this SPCP from another of the same run (the SHA-256 of its ``spcp.zip``);
    "" when unknown: its cells are then never kept across runs (:class:`CellCache`)."""


class CellCache(Protocol):
    """Where finished (VUT, opponent) cells are kept, so that an interrupted cross-play
    resumes from the cells it finished (:class:`~sumo_ayss.run_folder.CellStore`). ``key``
    holds everything the cell's rows depend on."""

    def load(self, key: Sequence[Any]) -> list[dict[str, Any]] | None:
        """The finished cell's rows, or None."""
        ...

    def save(self, key: Sequence[Any], rows: Sequence[dict[str, Any]]) -> None:
        """Keep a finished cell's rows."""
        ...


def check_one_world(envs: Mapping[str, EnvConfig]) -> None:
    """Refuses a pool whose VUT env configs differ in anything but the VUT (the VUT's name
    and definition, and the catalog of the study its run was made in: a VUT added to a
    finished study comes with a larger catalog than the runs before it)."""
    items = list(envs.items())
    ref_name, ref = items[0]
    for name, cfg in items[1:]:
        if dataclasses.replace(cfg, vut=ref.vut, vuts=ref.vuts) != ref:
            raise ConfigError(
                f"cross-play: the env configs of {ref_name!r} and {name!r} differ in more "
                "than the VUT (case, ODD, reward, actuator or timing); cross-play needs one "
                "world for all"
            )


def run_crossplay(
    envs: Mapping[str, EnvConfig],
    opponents: Sequence[Opponent],
    *,
    n: int,
    seed: int,
    progress: Callable[[str], None] | None = None,
    reference: str | None = DEFAULT_REFERENCE,
    cells: CellCache | None = None,
    runner: CellRunner | None = None,
) -> Table:
    """Every opponent against every VUT on ``n`` common scenarios.

    Args:
        envs: VUT name -> its env config (identical but for the VUT).
        opponents: The SPCP pool.
        n: Scenarios per (VUT, opponent), >= 1.
        seed: Seed of :func:`~sumo_ayss.envs.odd.scenario_set` (the outcome
            stage's).
        progress: Called with one line per (VUT, opponent) done.
        reference: The reference driver that replays each crash to label it preventable
            or not (:func:`~sumo_ayss.scenarios.preventability.label_crashes`, after the
            block's env closed, on its SUMO seed); None: no labels (NaN).
        cells: Where each finished cell is kept as soon as it is done and read back
            instead of driven again (an opponent with an ``identity`` only); None: none.
        runner: Drives the cells not kept on worker processes (:class:`CellRunner`, e.g.
            :class:`sumo_ayss.grid.cells.CellPool`; the opponents' ``load`` must then
            pickle); None: one after the other in this process. Each cell is its own fresh
            simulation either way, so the table is the same, row for row; this process
            alone writes ``cells``, as each cell comes back.

    Returns:
        The cross-play table, VUTs in the given order, then opponents, then scenarios.
    """
    if not envs or not opponents:
        raise ConfigError("cross-play needs at least one VUT and one opponent SPCP")
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise ConfigError(f"n: expected an integer >= 1, got {n!r}")
    check_one_world(envs)
    trusted = controller_imports_allowed()  # the caller's trust, carried to a worker
    tasks = [
        CellTask(v, cfg, o, n, seed, reference, trusted)
        for v, cfg in envs.items()
        for o in opponents
    ]
    found: dict[int, list[dict[str, Any]]] = {}
    for i, task in enumerate(tasks):
        kept = cells.load(task.key) if cells is not None and task.opponent.identity else None
        if kept is not None:  # a finished cell of an interrupted run: the same rows
            found[i] = kept
            if progress is not None:
                progress(f"{task.name}: kept from an earlier run")
    todo = [i for i in range(len(tasks)) if i not in found]
    if runner is None:
        done = _drive_here([tasks[i] for i in todo])
    else:
        done = runner.drive([tasks[i] for i in todo])
    for j, rows, seconds in done:  # as each cell is done (in any order on a pool)
        task = tasks[todo[j]]
        found[todo[j]] = rows
        if cells is not None and task.opponent.identity:
            cells.save(task.key, rows)
        if progress is not None:
            mean = float(np.mean([r["episode_return"] for r in rows]))
            crashes = sum(bool(r["collided"]) for r in rows)
            progress(
                f"{task.name}: mean return {mean:.2f}, {crashes}/{n} crashes ({seconds:.1f} s)"
            )
    return table_from_rows(CROSSPLAY_SCHEMA, [r for i in range(len(tasks)) for r in found[i]])


@dataclass(frozen=True)
class CellTask:
    """One (VUT, opponent) cell of :func:`run_crossplay`: all that driving it needs, small
    enough to send to a worker process (no rows, no scenarios: they are drawn where it runs).

    Attributes:
        vut: The VUT's name.
        cfg: Its env config.
        opponent: The SPCP driving against it.
        n: Scenarios.
        seed: Seed of the scenario set.
        reference: The crash labeller (None: no labels).
        trusted: Whether user controllers may be imported where it runs
            (:func:`~sumo_ayss.vuts.controller_spec.controller_imports`).
    """

    vut: str
    cfg: EnvConfig
    opponent: Opponent
    n: int
    seed: int
    reference: str | None
    trusted: bool = True

    @property
    def key(self) -> tuple[Any, ...]:
        """Everything the cell's rows depend on (its :class:`CellCache` key)."""
        o = self.opponent
        return (
            self.vut,
            repr(self.cfg),
            o.vut,
            o.seed,
            o.identity,
            self.n,
            self.seed,
            self.reference,
        )

    @property
    def name(self) -> str:
        """The cell, as progress lines and errors name it."""
        return f"{self.vut} vs SPCP {self.opponent.vut}/seed_{self.opponent.seed}"


#: A finished cell: its index among the tasks handed over, its rows, its seconds.
CellDone = tuple[int, list[dict[str, Any]], float]


class CellRunner(Protocol):
    """Drives cross-play cells elsewhere (:class:`sumo_ayss.grid.cells.CellPool`: worker
    processes), each with :func:`drive_cell`."""

    def drive(self, tasks: Sequence[CellTask]) -> Iterator[CellDone]:
        """Drive ``tasks``, yielding each as it is done (any order)."""
        ...


def _drive_here(tasks: Sequence[CellTask]) -> Iterator[CellDone]:
    """The cells in this process, in order; each opponent loaded once (0.48 s a load here
    under load, against 15 ms for a fresh SUMO): its greedy policy depends on the spaces
    only, the same for every VUT of the pool."""
    policies: dict[int, Policy] = {}  # by the opponent object, shared by its cells
    scenarios: dict[str, list[Any]] = {}
    for j, task in enumerate(tasks):
        if task.vut not in scenarios:
            scenarios[task.vut] = _scenarios(task)
        t0 = time.perf_counter()
        rows, policies[id(task.opponent)] = _drive(
            task, scenarios[task.vut], policies.get(id(task.opponent))
        )
        yield j, rows, time.perf_counter() - t0


def drive_cell(task: CellTask) -> tuple[list[dict[str, Any]], float]:
    """One cell on its own (a worker process's task): its rows and seconds; the opponent is
    loaded for it and dropped after (a worker holds one SPCP at a time)."""
    scenarios = _scenarios(task)
    t0 = time.perf_counter()
    with controller_imports(task.trusted):
        rows, _ = _drive(task, scenarios, None)
    return rows, time.perf_counter() - t0


def _scenarios(task: CellTask) -> list[Any]:
    cfg = task.cfg
    return with_followers(scenario_set(cfg, task.n, task.seed), cfg.follower, task.seed)


def _drive(
    task: CellTask, scenarios: Sequence[Any], policy: Policy | None
) -> tuple[list[dict[str, Any]], Policy]:
    """The cell's rows (and the opponent's policy, loaded when ``policy`` is None) on a fresh
    SUMO seeded with the opponent's seed, as the outcome stage drives it.

    Raises:
        AyssError: the error of the cell (its type), its message prefixed with the cell.
    """
    from sumo_ayss.envs import make_env

    cfg, opp = task.cfg, task.opponent
    try:
        env = make_env(cfg, sumo_seed=opp.seed)  # as the outcome stage: a fresh SUMO
        try:
            if policy is None:
                policy = opp.load(env)
            episodes = run_episodes(env, policy, scenarios)
        finally:
            env.close()
        labels = (
            label_crashes(
                cfg,
                scenarios,
                [e.collided for e in episodes],
                [e.actions for e in episodes],
                sumo_seed=opp.seed,
                reference=task.reference,
            )
            if task.reference is not None
            else np.full(len(episodes), np.nan)
        )
    except AyssError as e:
        named = _named(e, task.name)
        if named is e:
            raise
        raise named from e
    rows = [
        {
            "vut": task.vut,
            "opponent_vut": opp.vut,
            "opponent_seed": opp.seed,
            "scenario": j,
            "episode_return": e.episode_return,
            "collided": e.collided,
            "final_headway_m": e.final_headway_m,
            "n_steps": e.n_steps,
            "near_miss_pay": e.near_miss_pay,
            "vut_mean_speed_mps": e.vut_mean_speed_mps,
            **e.measure_row(),
            "crash_preventable": float(labels[j]),
            **e.hazard_row(),
        }
        for j, e in enumerate(episodes)
    ]
    return rows, policy


def _named(error: AyssError, cell: str) -> AyssError:
    """``error`` again, its message naming the cross-play cell (the same type; the error
    itself where its type takes more than a message)."""
    try:
        named = type(error)(f"cross-play cell {cell}: {error}")
    except TypeError:
        return error
    return named


#: Columns of a cross-play row compared with the same episode of ``outcome.csv``.
DIAGONAL_COLUMNS = (
    "episode_return",
    "collided",
    "final_headway_m",
    "n_steps",
    "near_miss_pay",
    "vut_mean_speed_mps",
    *MEASURE_NAMES,
    "crash_preventable",
    *HAZARD_NAMES,
)


def diagonal_check(crossplay: Table, vut: str, seed: int, outcome: Table) -> DiagonalCheck:
    """Compares the SPCP of run (``vut``, ``seed``) against its own VUT with its outcome table.

    Episodes are matched by scenario index; values must be equal exactly (both come from
    the same rollout code on the same SUMO seed). A column that one of the tables does not
    hold (NaN throughout: written before the column existed) is left out.

    Raises:
        ConfigError: If the cross-play table has no rows for that opponent against that VUT.
    """
    rows = (
        (crossplay["vut"] == vut)
        & (crossplay["opponent_vut"] == vut)
        & (crossplay["opponent_seed"] == seed)
    )
    idx = np.flatnonzero(rows)
    if idx.size == 0:
        raise ConfigError(f"cross-play table: no episodes of SPCP {vut}/seed_{seed} against {vut}")
    cols = [c for c in DIAGONAL_COLUMNS if not (_absent(crossplay, c) or _absent(outcome, c))]
    position = {int(sc): i for i, sc in enumerate(outcome["scenario"].tolist())}
    n_equal = 0
    for row, sc in zip(idx.tolist(), crossplay["scenario"][idx].tolist(), strict=True):
        i = position.get(int(sc))
        n_equal += i is not None and all(_same(crossplay[c][row], outcome[c][i]) for c in cols)
    return DiagonalCheck(vut, seed, int(idx.size), int(n_equal))


def _absent(table: Table, col: str) -> bool:
    """A float column with no value at all: the file was written before the column existed."""
    values = table[col]
    return values.dtype.kind == "f" and bool(np.isnan(values).all())


def _same(a: object, b: object) -> bool:
    """Exactly equal (NaN equal to NaN)."""
    return bool(a == b) or (isinstance(a, float) and isinstance(b, float) and a != a and b != b)


def check_diagonal(checks: Sequence[DiagonalCheck], case: str) -> None:
    """Refuse a cross-play table whose diagonal did not reproduce the outcome tables.

    Raises:
        DiagonalMismatchError: naming each VUT and run that differed and by how much.
    """
    bad = [c for c in checks if not c.ok]
    if bad:
        parts = "; ".join(
            f"{c.vut} (seed {c.seed}): {c.n - c.n_equal} of {c.n} episodes differ "
            f"({100 * c.share_differing:.1f} %)"
            for c in bad
        )
        raise DiagonalMismatchError(
            f"cross-play of {case} drove a VUT differently from the outcome stage: an SPCP "
            f"against its own VUT did not reproduce its outcome.csv: {parts}. Its verdict "
            "would be about another vehicle than the one its opponents were trained against; "
            "the cross-play table is kept for inspection but not ranked"
        )
