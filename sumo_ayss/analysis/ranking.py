"""Rankings of VUTs by their safety index (numpy and the stdlib only).

The safety index itself is :mod:`.safety_index`, the pairwise verdict :mod:`.verdict`; both
are re-exported here.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from sumo_ayss.analysis.safety_index import (
    DELTA_V_BAR,
    POV_ACCELERATION,
    Indicator,
    SafetyIndex,
    safety_index,
)
from sumo_ayss.analysis.verdict import Verdict, compare
from sumo_ayss.util.errors import ConfigError

__all__ = [
    "DELTA_V_BAR",
    "POV_ACCELERATION",
    "Indicator",
    "RankedVut",
    "SafetyIndex",
    "Verdict",
    "compare",
    "rank",
    "safety_index",
]


# --------------------------------------------------------------------------- ranking


@dataclass(frozen=True)
class RankedVut:
    """One row of a safety ranking.

    Attributes:
        rank: 1 for the safest.
        name: VUT name.
        point: Safety index (indicator's unit); larger = safer.
        lo: Lower bound of its interval.
        hi: Upper bound of its interval.
        n_seeds: Seeds behind the index.
        p_safer_than_next: Bootstrap probability that this VUT's index exceeds the next
            one's; None for the last row.
        significant_vs_next: Whether the interval of the difference to the next excludes 0;
            None for the last row.
    """

    rank: int
    name: str
    point: float
    lo: float
    hi: float
    n_seeds: int
    p_safer_than_next: float | None
    significant_vs_next: bool | None


def rank(indices: Mapping[str, SafetyIndex], *, level: float = 0.95) -> list[RankedVut]:
    """Orders VUTs from safest to least safe by their safety index.

    Ties in the point estimate are broken by name. Each row but the last also says how sure
    the ordering against the next row is (see :func:`compare`).

    Args:
        indices: VUT name to safety index; all built with the same ``h_range``, ``n_bins``
            and ``n_boot``.
        level: Confidence level for the significance against the next row, in (0, 1).

    Returns:
        One :class:`RankedVut` per VUT, safest first.

    Raises:
        ConfigError: If ``indices`` is empty or two indices are not comparable.
    """
    if not indices:
        raise ConfigError("indices: expected at least one VUT")
    order = sorted(indices, key=lambda name: (-indices[name].point, name))
    rows = []
    for pos, name in enumerate(order):
        idx = indices[name]
        p_next: float | None = None
        sig_next: bool | None = None
        if pos + 1 < len(order):
            nxt = order[pos + 1]
            verdict = compare(idx, indices[nxt], name_a=name, name_b=nxt, level=level)
            p_next, sig_next = verdict.p_a_safer, verdict.significant and verdict.safer == name
        rows.append(
            RankedVut(pos + 1, name, idx.point, idx.lo, idx.hi, idx.n_seeds, p_next, sig_next)
        )
    return rows
