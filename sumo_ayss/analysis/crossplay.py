"""Cross-play ranking: VUTs compared within each opponent SPCP of a common pool.

Input: the cross-play table (:mod:`sumo_ayss.scenarios.crossplay`) as plain columns, one
row per (VUT driven against, opponent SPCP, scenario). Every opponent drove the same
scenarios against every VUT.

Score: the cross-play harm of VUT v, ``H(v) = mean over opponents o of H(o, v)``, with
``H(o, v)`` the mean harm per episode opponent o brought about against v over the scenarios
(:mod:`.harm`: 1 for a collision, else the near-miss pay over the most an episode can pay).
Lower is safer. A collision counts as the worst outcome for the VUT: before issue 22 the
score was the mean episode *reward* the opponents extracted, in which a crash pays the
opponent -10 and so counted as the VUT's gain (a braking ladder came out inverted in cut-in;
opponents trained against other VUTs do crash, a VUT's own SPCP learns not to). The matrix
keeps that reading (:attr:`CrossplayMatrix.returns`) for comparison, beside each cell's crash
rate and the VUT's mobility (mean speed).

Test: a paired t-test over blocks (:func:`sumo_ayss.analysis.seeds.compare_seeds`, blocks in
the role of seeds), by default ``blocks="seed"``: block s is the mean over the opponents of
training seed s (one per VUT). The pipeline gives every VUT's job the same seed (network
initialisation, exploration stream), so opponents of one seed are not independent of each
other (on a cut-in ladder, seed 0's opponents extracted more from every VUT than seed 2's);
training seeds are the independent replications. ``blocks="opponent"`` treats every
opponent as its own block: more degrees of freedom, valid only when opponents are
independent draws. The verdict is about these VUTs under this population of adversaries.
Under no true difference, with normal block-level errors, the test calls a difference in
``alpha`` of cases (checked on synthetic data in ``tests/analysis/test_crossplay.py``).
Deterministic identical VUTs give identical rows, hence no spread and no test (p undefined,
never significant).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np
import numpy.typing as npt

from sumo_ayss.analysis.harm import HARM_RANGE
from sumo_ayss.analysis.hazards import vut_hazards
from sumo_ayss.analysis.seeds import SeedComparison, SeedRankRow, SeedScores, rank_seeds
from sumo_ayss.util.errors import ConfigError

__all__ = [
    "BLOCKS",
    "CrossplayGap",
    "CrossplayInput",
    "CrossplayMatrix",
    "crossplay_matrix",
    "rank_crossplay",
]

#: Block units of the paired test: training seeds (default) or single opponents.
BLOCKS = ("seed", "opponent")


@dataclass(frozen=True)
class CrossplayMatrix:
    """Per (VUT, opponent) cell: mean harm, crash rate, mean reward and mobility.

    Attributes:
        vuts: VUTs driven against, in first-seen order.
        opponents: ``(trained-against VUT, training seed)`` of each opponent, sorted.
        harm: ``harm[i, j]`` = mean harm per episode of opponent j against VUT i, in [0, 1]
            (:func:`~.harm.episode_harm`); the score.
        collisions: ``collisions[i, j]`` = episodes of opponent j against VUT i that ended
            in a collision (:attr:`crash_rate` is the share).
        n_scenarios: Scenarios per cell.
        returns: ``returns[i, j]`` = mean episode reward (the reading before issue 22);
            NaN where not given.
        mobility: ``mobility[i, j]`` = mean of the episodes' VUT mean speed [m/s]; NaN where
            the table does not record it.
        preventable: ``preventable[i, j]`` = the cell's collisions labelled preventable (a
            careful reference driver replaying them avoided contact,
            :mod:`sumo_ayss.scenarios.preventability`); None: no labels given.
        labelled: ``labelled[i, j]`` = the cell's collisions that carry a label (the rest
            were not labelled: an older table); None: no labels given.
    """

    vuts: tuple[str, ...]
    opponents: tuple[tuple[str, int], ...]
    harm: npt.NDArray[np.float64]
    collisions: npt.NDArray[np.int64]
    n_scenarios: int
    returns: npt.NDArray[np.float64]
    mobility: npt.NDArray[np.float64]
    preventable: npt.NDArray[np.int64] | None = None
    labelled: npt.NDArray[np.int64] | None = None
    hazards: dict[str, dict[str, float]] | None = None
    """Per VUT, the hazards it caused (:func:`~.hazards.vut_hazards`); None: not recorded."""

    def preventable_crashes(self, vut: str) -> tuple[int, int]:
        """``(preventable, labelled)`` collisions of ``vut`` against the whole pool;
        ``(0, 0)`` without labels."""
        if self.preventable is None or self.labelled is None:
            return 0, 0
        i = self.vuts.index(vut)
        return int(self.preventable[i].sum()), int(self.labelled[i].sum())

    def scores(self, blocks: str = "seed") -> list[SeedScores]:
        """Per VUT: block -> its mean harm H(opponent, VUT), for :func:`rank_seeds`.

        Args:
            blocks: ``"seed"`` (block = training seed; its value is the mean over that
                seed's opponents) or ``"opponent"`` (block = opponent index).
        """
        if blocks == "opponent":
            return [
                SeedScores(v, dict(enumerate(self.harm[i].tolist())))
                for i, v in enumerate(self.vuts)
            ]
        if blocks != "seed":
            raise ConfigError(f"blocks must be one of {', '.join(BLOCKS)}, got {blocks!r}")
        seeds = sorted({s for _, s in self.opponents})
        cols = {s: [j for j, (_, t) in enumerate(self.opponents) if t == s] for s in seeds}
        return [
            SeedScores(v, {s: float(self.harm[i, cols[s]].mean()) for s in seeds})
            for i, v in enumerate(self.vuts)
        ]

    @property
    def crash_rate(self) -> npt.NDArray[np.float64]:
        """``crash_rate[i, j]`` = share of the cell's episodes that ended in a collision."""
        return self.collisions / self.n_scenarios

    def crashes(self, vut: str) -> tuple[int, int]:
        """``(collisions, episodes)`` of ``vut`` against the whole pool."""
        i = self.vuts.index(vut)
        return int(self.collisions[i].sum()), self.n_scenarios * len(self.opponents)

    def vut_mobility(self, vut: str) -> float:
        """Mean speed [m/s] of ``vut`` over all its episodes against the pool (NaN: not
        recorded)."""
        row = self.mobility[self.vuts.index(vut)]
        return float(row.mean()) if np.all(np.isfinite(row)) else math.nan


def crossplay_matrix(
    vut: Sequence[str],
    opponent_vut: Sequence[str],
    opponent_seed: Sequence[int],
    harm: npt.ArrayLike,
    collided: npt.ArrayLike,
    *,
    episode_return: npt.ArrayLike | None = None,
    mobility: npt.ArrayLike | None = None,
    preventable: npt.ArrayLike | None = None,
    hazards: dict[str, npt.NDArray[np.float64]] | None = None,
) -> CrossplayMatrix:
    """Reduces the cross-play table's columns (one entry per episode) to the matrix.

    Args:
        vut, opponent_vut, opponent_seed: Who drove against whom.
        harm: Each episode's harm (:func:`~.harm.episode_harm`).
        collided: Whether each episode ended in a collision.
        episode_return: Each episode's reward sum (kept for comparison), or None.
        mobility: Each episode's VUT mean speed [m/s] (NaN: not recorded), or None.
        preventable: Each episode's crash label (1 preventable, 0 unpreventable, NaN no
            crash or not labelled), or None.
        hazards: The hazard columns by name (:data:`~.hazards.VUT_HAZARD_COLUMNS`), or None.

    Raises:
        ConfigError: If the lengths differ, a harm or return is not finite, or the design is
            not complete and balanced (every opponent against every VUT on equally many
            scenarios).
    """
    h = np.asarray(harm, dtype=np.float64)
    crash = np.asarray(collided, dtype=np.float64)
    n = len(vut)
    ret = np.full(n, np.nan) if episode_return is None else np.asarray(episode_return, float)
    mob = np.full(n, np.nan) if mobility is None else np.asarray(mobility, dtype=np.float64)
    lab = np.full(n, np.nan) if preventable is None else np.asarray(preventable, np.float64)
    if lab.size != n:
        raise ConfigError("cross-play columns: lengths differ")
    lab = np.where(crash > 0, lab, np.nan)  # a label without a crash means nothing
    if not (len(opponent_vut) == len(opponent_seed) == h.size == crash.size == n):
        raise ConfigError("cross-play columns: lengths differ")
    if ret.size != n or mob.size != n:
        raise ConfigError("cross-play columns: lengths differ")
    if n == 0:
        raise ConfigError("cross-play table: no rows")
    if not np.all(np.isfinite(h)):
        raise ConfigError("cross-play table: harm has non-finite values")
    if episode_return is not None and not np.all(np.isfinite(ret)):
        raise ConfigError("cross-play table: episode_return has non-finite values")
    vuts = tuple(dict.fromkeys(str(v) for v in vut))
    opps = tuple(
        sorted({(str(o), int(s)) for o, s in zip(opponent_vut, opponent_seed, strict=True)})
    )
    vi = {v: i for i, v in enumerate(vuts)}
    oi = {o: j for j, o in enumerate(opps)}
    shape = (len(vuts), len(opps))
    sums = {key: np.zeros(shape) for key in ("harm", "crash", "ret", "mob", "prev", "lab")}
    counts = np.zeros(shape)
    for k in range(n):
        i, j = vi[str(vut[k])], oi[(str(opponent_vut[k]), int(opponent_seed[k]))]
        sums["harm"][i, j] += h[k]
        sums["crash"][i, j] += crash[k]
        sums["ret"][i, j] += ret[k]
        sums["mob"][i, j] += mob[k]
        if not math.isnan(lab[k]):
            sums["lab"][i, j] += 1
            sums["prev"][i, j] += lab[k] == 1.0
        counts[i, j] += 1
    if counts.min() == 0 or counts.min() != counts.max():
        raise ConfigError(
            "cross-play table: not every opponent drove the same number of scenarios against "
            f"every VUT; rows lost: {short_cells(vuts, opps, counts)}"
        )
    return CrossplayMatrix(
        vuts,
        opps,
        harm=sums["harm"] / counts,
        collisions=sums["crash"].astype(np.int64),
        n_scenarios=int(counts[0, 0]),
        returns=sums["ret"] / counts,
        mobility=sums["mob"] / counts,
        preventable=None if preventable is None else sums["prev"].astype(np.int64),
        labelled=None if preventable is None else sums["lab"].astype(np.int64),
        hazards=None if hazards is None else vut_hazards(np.asarray(vut), hazards),
    )


def short_cells(
    vuts: Sequence[str], opponents: Sequence[tuple[str, int]], counts: npt.NDArray[np.float64]
) -> str:
    """Which VUTs, opponents or single cells hold fewer rows than the fullest cell, in words.

    A VUT whose every cell is short is named once ("VUT pi2: 0 of 400 rows"), so is an
    opponent short against every VUT; the other short cells are named one by one (the first
    :data:`_SHOWN`). ``counts[i, j]``: rows of opponent j against VUT i.
    """
    full = int(counts.max())
    short = counts < full
    parts = []
    rows_short = [i for i in range(len(vuts)) if short[i].all()]
    cols_short = [j for j in range(len(opponents)) if short[:, j].all()] if len(vuts) > 1 else []
    for i in rows_short:
        got = int(counts[i].sum())
        parts.append(f"VUT {vuts[i]}: {got} of {full * len(opponents)} rows")
    for j in cols_short:
        o = f"{opponents[j][0]}/seed_{opponents[j][1]}"
        parts.append(f"opponent {o}: {int(counts[:, j].sum())} of {full * len(vuts)} rows")
    covered = np.zeros_like(short)
    covered[rows_short, :] = True
    covered[:, cols_short] = True
    cells = [
        f"{vuts[i]} vs {opponents[j][0]}/seed_{opponents[j][1]}: {int(counts[i, j])} of {full}"
        for i, j in zip(*np.nonzero(short & ~covered), strict=True)
    ]
    parts += cells[:_SHOWN]
    if len(cells) > _SHOWN:
        parts.append(f"and {len(cells) - _SHOWN} more cells")
    return "; ".join(parts)


#: Short cells named one by one in :func:`short_cells`.
_SHOWN = 5


@dataclass(frozen=True)
class CrossplayInput:
    """A case's cross-play table as its loader found it: the matrix, or why there is none.

    The loader (:func:`sumo_ayss.run_folder.load_crossplay`) reads the file; nothing in
    :mod:`sumo_ayss.analysis` does.

    Attributes:
        matrix: The table's :class:`CrossplayMatrix`, or None (the default: no table found).
        path: The table read (shown in the report), or None.
        missing: Why there is no matrix, one sentence from the loader; "" with no matrix
            means that no table was found.
        problem: A line for the case's problem list (an unreadable table), or "".
        diagonal: The diagonal check of the table's record, one ``(vut, seed, n, n_equal)``
            per run: its SPCP against its own VUT reproduced ``n_equal`` of the ``n``
            episodes of its outcome table; empty when the record predates the check.
        reference: The reference drivers' rows against the same pool
            (``crossplay_reference.csv``), or None (no such table, or unreadable).
        inevitable: ``(n, seed, indices)`` of the scenario set and its inevitable-collision
            states (``inevitable.json``), or None.
    """

    matrix: CrossplayMatrix | None = None
    path: Path | None = None
    missing: str = ""
    problem: str = ""
    diagonal: tuple[tuple[str, int, int, int], ...] = ()
    reference: CrossplayMatrix | None = None
    inevitable: tuple[int, int, tuple[int, ...]] | None = None


@dataclass(frozen=True)
class CrossplayGap:
    """Why a case has no cross-play ranking (the cross-play mode words it).

    Attributes:
        reason: ``"one_vut"`` (the case's runs are of one VUT), ``"not_found"`` (its loader
            found no table, or none it could read) or ``"not_these_runs"`` (the table is of
            other VUTs or runs).
        vut: ``"one_vut"``: that VUT.
        loader: ``"not_found"``: the loader's reason (:attr:`CrossplayInput.missing`); ""
            when it found no table.
        path: ``"not_these_runs"``: the table.
        vuts: ``"not_these_runs"``: the table's VUTs.
        n_opponents: ``"not_these_runs"``: the table's opponents.
        n_runs: ``"not_these_runs"``: the case's runs with a seed.
        lost: ``"not_these_runs"``: what of these runs the table holds no row of, in words
            (``"VUT pi2; opponent pi1/seed_1"``); "" when it holds every one (it is of
            other runs besides).
    """

    reason: Literal["one_vut", "not_found", "not_these_runs"]
    vut: str = ""
    loader: str = ""
    path: Path | None = None
    vuts: tuple[str, ...] = ()
    n_opponents: int = 0
    n_runs: int = 0
    lost: str = ""


def rank_crossplay(
    m: CrossplayMatrix, *, blocks: str = "seed", level: float = 0.95, alpha: float = 0.05
) -> tuple[list[SeedRankRow], list[SeedComparison]]:
    """Ranking by cross-play harm H (lower = safer), paired over blocks.

    With balanced blocks (every seed trains one opponent per VUT), H is the same mean for
    both block units; only the test differs.

    Returns:
        ``(rows, pairs)`` as :func:`~sumo_ayss.analysis.seeds.rank_seeds` (``n_seeds`` of a
        row = blocks behind its mean).
    """
    return rank_seeds(
        m.scores(blocks), higher_is_safer=False, level=level, alpha=alpha, bounds=HARM_RANGE
    )
