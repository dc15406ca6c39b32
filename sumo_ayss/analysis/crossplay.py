"""Cross-play ranking: VUTs compared within each opponent SPCP of a common pool.

Input: the cross-play table (:mod:`sumo_ayss.scenarios.crossplay`) as plain columns, one
row per (VUT driven against, opponent SPCP, scenario). Every opponent drove the same
scenarios against every VUT.

Score: the cross-play exposure of VUT v, ``X(v) = mean over opponents o of E(o, v)``, with
``E(o, v)`` the mean episode reward opponent o extracts from v over the scenarios. Lower is
safer, as in exposure mode: the same adversarial-yet-safe reward, paid for fewer or less
close near-misses.

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

import numpy as np
import numpy.typing as npt

from sumo_ayss.analysis.seeds import SeedComparison, SeedRankRow, SeedScores, rank_seeds
from sumo_ayss.errors import ConfigError

__all__ = [
    "BLOCKS",
    "CROSSPLAY_COMMAND",
    "NO_CROSSPLAY_TABLE",
    "CrossplayInput",
    "CrossplayMatrix",
    "crossplay_matrix",
    "crossplay_sentence",
    "rank_crossplay",
]

#: Block units of the paired test: training seeds (default) or single opponents.
BLOCKS = ("seed", "opponent")

CROSSPLAY_COMMAND = "python -m sumo_ayss.crossplay <config>"
"""The command that writes a case's cross-play table."""

NO_CROSSPLAY_TABLE = f"no cross-play table for this case (run {CROSSPLAY_COMMAND})"
"""Why a case has no cross-play ranking when its loader found no table."""


@dataclass(frozen=True)
class CrossplayMatrix:
    """Mean episode reward of every opponent against every VUT.

    Attributes:
        vuts: VUTs driven against, in first-seen order.
        opponents: ``(trained-against VUT, training seed)`` of each opponent, sorted.
        returns: ``returns[i, j]`` = mean episode reward of opponent j against VUT i.
        crash_rate: ``crash_rate[i, j]`` = share of its episodes that ended in a collision.
        n_scenarios: Scenarios per cell.
    """

    vuts: tuple[str, ...]
    opponents: tuple[tuple[str, int], ...]
    returns: npt.NDArray[np.float64]
    crash_rate: npt.NDArray[np.float64]
    n_scenarios: int

    def scores(self, blocks: str = "seed") -> list[SeedScores]:
        """Per VUT: block -> its mean E(opponent, VUT), for :func:`rank_seeds`.

        Args:
            blocks: ``"seed"`` (block = training seed; its value is the mean over that
                seed's opponents) or ``"opponent"`` (block = opponent index).
        """
        if blocks == "opponent":
            return [
                SeedScores(v, dict(enumerate(self.returns[i].tolist())))
                for i, v in enumerate(self.vuts)
            ]
        if blocks != "seed":
            raise ConfigError(f"blocks must be one of {', '.join(BLOCKS)}, got {blocks!r}")
        seeds = sorted({s for _, s in self.opponents})
        cols = {s: [j for j, (_, t) in enumerate(self.opponents) if t == s] for s in seeds}
        return [
            SeedScores(v, {s: float(self.returns[i, cols[s]].mean()) for s in seeds})
            for i, v in enumerate(self.vuts)
        ]


def crossplay_matrix(
    vut: Sequence[str],
    opponent_vut: Sequence[str],
    opponent_seed: Sequence[int],
    episode_return: npt.ArrayLike,
    collided: npt.ArrayLike,
) -> CrossplayMatrix:
    """Reduces the cross-play table's columns (one entry per episode) to the matrix.

    Raises:
        ConfigError: If the lengths differ, a value is not finite, or the design is not
            complete and balanced (every opponent against every VUT on equally many
            scenarios).
    """
    ret = np.asarray(episode_return, dtype=np.float64)
    crash = np.asarray(collided, dtype=np.float64)
    n = len(vut)
    if not (len(opponent_vut) == len(opponent_seed) == ret.size == crash.size == n):
        raise ConfigError("cross-play columns: lengths differ")
    if n == 0:
        raise ConfigError("cross-play table: no rows")
    if not np.all(np.isfinite(ret)):
        raise ConfigError("cross-play table: episode_return has non-finite values")
    vuts = tuple(dict.fromkeys(str(v) for v in vut))
    opps = tuple(
        sorted({(str(o), int(s)) for o, s in zip(opponent_vut, opponent_seed, strict=True)})
    )
    vi = {v: i for i, v in enumerate(vuts)}
    oi = {o: j for j, o in enumerate(opps)}
    sums = np.zeros((len(vuts), len(opps)))
    crashes = np.zeros_like(sums)
    counts = np.zeros_like(sums)
    for k in range(n):
        i, j = vi[str(vut[k])], oi[(str(opponent_vut[k]), int(opponent_seed[k]))]
        sums[i, j] += ret[k]
        crashes[i, j] += crash[k]
        counts[i, j] += 1
    if counts.min() == 0 or counts.min() != counts.max():
        raise ConfigError(
            "cross-play table: not every opponent drove the same number of scenarios against "
            f"every VUT (per-cell counts {int(counts.min())}..{int(counts.max())})"
        )
    return CrossplayMatrix(vuts, opps, sums / counts, crashes / counts, int(counts[0, 0]))


@dataclass(frozen=True)
class CrossplayInput:
    """A case's cross-play table as its loader found it: the matrix, or why there is none.

    The loader (:func:`sumo_ayss.report.load.load_crossplay`) reads the file; nothing in
    :mod:`sumo_ayss.analysis` does.

    Attributes:
        matrix: The table's :class:`CrossplayMatrix`, or None (the default: no table found).
        path: The table read (shown in the report), or None.
        missing: Why there is no matrix, one sentence; "" with no matrix means that no
            table was found (:data:`NO_CROSSPLAY_TABLE`).
        problem: A line for the case's problem list (an unreadable table), or "".
    """

    matrix: CrossplayMatrix | None = None
    path: Path | None = None
    missing: str = ""
    problem: str = ""


def rank_crossplay(
    m: CrossplayMatrix, *, blocks: str = "seed", level: float = 0.95, alpha: float = 0.05
) -> tuple[list[SeedRankRow], list[SeedComparison]]:
    """Ranking by cross-play exposure X (lower = safer), paired over blocks.

    With balanced blocks (every seed trains one opponent per VUT), X is the same mean for
    both block units; only the test differs.

    Returns:
        ``(rows, pairs)`` as :func:`~sumo_ayss.analysis.seeds.rank_seeds` (``n_seeds`` of a
        row = blocks behind its mean).
    """
    return rank_seeds(m.scores(blocks), higher_is_safer=False, level=level, alpha=alpha)


def _fmt(x: float) -> str:
    return f"{x:.2f}".replace("-", "−")


def crossplay_sentence(c: SeedComparison, blocks: str = "seed") -> str:
    """One quotable sentence for a cross-play comparison (A ranked above B)."""
    unit = "training seeds (blocks of opponents)" if blocks == "seed" else "opponent SPCPs"
    pct = f"{100 * c.level:g} %"
    b_higher = c.difference < 0
    lo, hi = (-c.hi, -c.lo) if b_higher else (c.lo, c.hi)
    if math.isfinite(lo) and math.isfinite(hi):
        ci = f"{_fmt(lo)}–{_fmt(hi)}" if lo >= 0 else f"{_fmt(lo)} to {_fmt(hi)}"
    else:
        ci = "interval undefined"
    if not math.isfinite(c.p):
        p = "p undefined"
    else:
        p = "p < 0.001" if c.p < 0.001 else f"p = {c.p:.3f}"
    stats = f"{pct} CI {ci}; paired t-test over {c.n_a} {unit}, {p}"
    more = "more" if b_higher else "less"
    what = (
        f"the pooled SPCPs extract {abs(c.difference):.2f} {more} reward per episode "
        f"from {c.name_b} than from {c.name_a}"
    )
    if c.significant and c.difference < 0:
        return f"[crossplay mode] {c.name_a} is safer than {c.name_b}: {what} ({stats})."
    return (
        f"[crossplay mode] No significant difference in safety between {c.name_a} and "
        f"{c.name_b}: {what} ({stats})."
    )
