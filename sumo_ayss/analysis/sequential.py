"""Adaptive seeding: when has a cross-play ranking settled, with repeated looks accounted for.

A grid starts with a few training seeds per VUT and adds one seed at a time (up to a cap)
while the ranking has not settled. Each look reads the per-seed block scores of every VUT
(:meth:`~sumo_ayss.analysis.crossplay.CrossplayMatrix.scores`, a ``k × n`` matrix of VUTs ×
seed blocks, lower = safer) and calls the ranking **settled** when both hold:

1. **the gate**: the repeated-measures F test (VUTs × seed blocks, the two-way table without
   replication; ``F = MS_vut / MS_residual`` on ``k - 1`` and ``(k - 1)(n - 1)`` degrees of
   freedom) says the VUTs differ, at the *look level* ``gate_level``; and
2. **the ends**: the report's own test (:func:`~sumo_ayss.analysis.seeds.compare_seeds`,
   paired t over the seed blocks) finds the safest and the least safe VUT of the current
   ranking different at the report's ``alpha``.

Why a gate. Stopping as soon as the ends' paired t is below 0.05 would claim a difference far
too often when every VUT is equally safe: the ends are the two extremes of ``k`` means (for
``k = 4`` and four seeds, 14 % of pure-noise grids have "significant ends"), and every
extra look is another chance (28 % over looks at 4, 5 and 6 seeds; checked in
``tests/analysis/test_sequential.py``). The F test reads all ``k`` VUTs at once, so it does
not pick the extremes, and its look level is **calibrated** (:func:`gate_level`) by Monte
Carlo so that, with no true difference between the VUTs and normal seed-level errors, the
whole sequence of looks ends in a "settled" claim in ``alpha`` of grids (both statistics are
pivotal there: the answer depends only on ``k``, the looks and ``alpha``). This is a
Pocock-type design: one constant level at every look. The false-positive rate under other
nulls (seed blocks of very different scale, heavy tails, correlated opponents) and the
procedure's power and wrong-order rate on ladders are measured by
``scripts/adaptive_seeds.py`` (results in ``results/adaptive_seeds/``).

Everything here is pure numpy/scipy: the pipeline hands in the block scores and records the
:class:`SettleCheck` (:mod:`sumo_ayss.run_folder`).
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy import stats as _scipy_stats

from sumo_ayss.analysis.seeds import SeedScores, compare_seeds
from sumo_ayss.analysis.validate import check_level
from sumo_ayss.util.errors import ConfigError

__all__ = [
    "CALIBRATION_REPS",
    "SettleCheck",
    "block_matrix",
    "gate_level",
    "looks_of",
    "omnibus_p",
    "settle_check",
]

CALIBRATION_REPS = 200_000
"""Monte Carlo grids behind :func:`gate_level` (standard error of the calibrated
false-positive rate: about 0.0005 at ``alpha = 0.05``)."""

_CALIBRATION_SEED = 20_261_126


def looks_of(first: int, max_seeds: int) -> tuple[int, ...]:
    """Seeds per VUT at each look: ``first, first + 1, ..., max_seeds``.

    Raises:
        ConfigError: If ``first < 2`` (a paired test needs two seeds) or ``max_seeds <
            first``.
    """
    if first < 2:
        raise ConfigError(f"adaptive seeding: needs at least 2 seeds to start, got {first}")
    if max_seeds < first:
        raise ConfigError(f"max_seeds: must be at least the {first} seeds to start with")
    return tuple(range(first, max_seeds + 1))


def omnibus_p(blocks: npt.ArrayLike) -> float:
    """p-value of the repeated-measures F test that the rows (VUTs) of ``blocks`` differ.

    ``blocks[i, j]``: VUT i's score in seed block j. NaN when the residual is zero (rows
    that differ by constants only, e.g. identical deterministic VUTs: no spread, no test).
    """
    p = _omnibus_p(np.asarray(blocks, dtype=np.float64)[None])[0]
    return float(p)


def _omnibus_p(x: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """:func:`omnibus_p` of a stack of matrices ``x[r, i, j]``."""
    k, n = x.shape[-2:]
    grand = x.mean(axis=(-1, -2), keepdims=True)
    rows = x.mean(axis=-1, keepdims=True)
    cols = x.mean(axis=-2, keepdims=True)
    ss_vut = n * ((rows - grand) ** 2).sum(axis=(-1, -2))
    ss_res = ((x - rows - cols + grand) ** 2).sum(axis=(-1, -2))
    df1, df2 = k - 1, (k - 1) * (n - 1)
    with np.errstate(divide="ignore", invalid="ignore"):
        f = (ss_vut / df1) / (ss_res / df2)
    scale = np.maximum(ss_vut, 1.0) * 1e-12
    f = np.where(ss_res > scale, f, np.nan)
    return np.asarray(_scipy_stats.f.sf(f, df1, df2), dtype=np.float64)


def _ends_p(x: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """Paired-t p of the lowest- against the highest-mean row, for a stack ``x[r, i, j]``."""
    means = x.mean(axis=-1)
    idx = np.arange(x.shape[0])
    d = x[idx, means.argmin(axis=-1)] - x[idx, means.argmax(axis=-1)]
    n = d.shape[-1]
    se = d.std(axis=-1, ddof=1) / math.sqrt(n)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.abs(d.mean(axis=-1)) / se
    return np.asarray(2.0 * _scipy_stats.t.sf(t, n - 1), dtype=np.float64)


@functools.lru_cache(maxsize=64)
def gate_level(k: int, looks: tuple[int, ...], alpha: float = 0.05) -> float:
    """The F gate's level at every look, calibrated so that the sequence of looks calls a
    grid of ``k`` equally safe VUTs settled in ``alpha`` of cases.

    Monte Carlo under the complete null with normal seed-level errors
    (:data:`CALIBRATION_REPS` grids, a fixed random stream: the same arguments always give
    the same level), bisection on the level; the ends' test keeps the report's ``alpha``.

    Args:
        k: VUTs in the case (>= 2).
        looks: Seeds per VUT at each look, ascending (:func:`looks_of`).
        alpha: The whole procedure's false-positive rate, and the ends' test level.

    Raises:
        ConfigError: On ``k < 2``, ``alpha`` outside (0, 1) or looks that are not ascending
            from 2.
    """
    alpha = check_level(alpha, "alpha")
    if k < 2:
        raise ConfigError(f"adaptive seeding: needs at least 2 VUTs, got {k}")
    if not looks or looks[0] < 2 or any(b <= a for a, b in itertools.pairwise(looks)):
        raise ConfigError(f"looks: must ascend from 2 or more seeds, got {list(looks)}")
    rng = np.random.default_rng(_CALIBRATION_SEED)
    gate = np.empty((CALIBRATION_REPS, len(looks)))
    ends = np.empty((CALIBRATION_REPS, len(looks)), dtype=bool)
    chunk = 50_000
    for start in range(0, CALIBRATION_REPS, chunk):
        x = rng.standard_normal((min(chunk, CALIBRATION_REPS - start), k, looks[-1]))
        for j, n in enumerate(looks):
            gate[start : start + len(x), j] = _omnibus_p(x[..., :n])
            ends[start : start + len(x), j] = _ends_p(x[..., :n]) < alpha
    lo, hi = 0.0, alpha
    for _ in range(40):  # the rate is monotone in the level
        mid = 0.5 * (lo + hi)
        rate = float(((gate < mid) & ends).any(axis=1).mean())
        lo, hi = (mid, hi) if rate <= alpha else (lo, mid)
    return lo


def block_matrix(scores: Sequence[SeedScores]) -> tuple[tuple[str, ...], npt.NDArray[np.float64]]:
    """``(vuts, blocks)``: the VUTs' per-seed scores as a ``k × n`` matrix over their shared
    seeds.

    Raises:
        ConfigError: If the VUTs do not share one seed set (cross-play blocks always do).
    """
    if not scores:
        raise ConfigError("adaptive seeding: no VUT scores")
    seeds = scores[0].seeds
    for s in scores[1:]:
        if s.seeds != seeds:
            raise ConfigError(
                f"adaptive seeding: {s.name} has seeds {list(s.seeds)}, "
                f"{scores[0].name} {list(seeds)}; the blocks must be shared"
            )
    return tuple(s.name for s in scores), np.array([s.array for s in scores])


@dataclass(frozen=True)
class SettleCheck:
    """One look of adaptive seeding at one case.

    Attributes:
        n_seeds: Seed blocks per VUT at this look.
        omnibus_p: p of the F gate (NaN: no residual spread, no test).
        gate_level: The calibrated level the gate must be below (:func:`gate_level`).
        safest: The VUT with the lowest score (lower = safer).
        least_safe: The VUT with the highest score.
        ends_p: The report's paired-t p of ``safest`` against ``least_safe`` (NaN: no test).
        alpha: The level ``ends_p`` must be below.
        settled: Both tests passed.
    """

    n_seeds: int
    omnibus_p: float
    gate_level: float
    safest: str
    least_safe: str
    ends_p: float
    alpha: float
    settled: bool


def settle_check(
    scores: Sequence[SeedScores], looks: tuple[int, ...], alpha: float = 0.05
) -> SettleCheck:
    """Whether the ranking of ``scores`` (lower = safer) has settled at this look.

    Args:
        scores: Per VUT, its block scores (the same seeds for every VUT).
        looks: The grid's whole look schedule (the gate's level depends on it).
        alpha: The procedure's false-positive rate and the report's significance level.
    """
    vuts, x = block_matrix(scores)
    n = x.shape[1]
    level = gate_level(len(vuts), tuple(looks), alpha)
    gate = omnibus_p(x)
    means = x.mean(axis=1)
    top, bottom = int(means.argmin()), int(means.argmax())
    ends = compare_seeds(scores[top], scores[bottom], alpha=alpha) if top != bottom else None
    ends_p = math.nan if ends is None else float(ends.p)
    settled = bool(
        ends is not None
        and math.isfinite(gate)
        and gate < level
        and math.isfinite(ends_p)
        and ends_p < alpha
    )
    return SettleCheck(n, gate, level, vuts[top], vuts[bottom], ends_p, alpha, settled)
