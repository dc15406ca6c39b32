"""Discriminability before training: where the one-step responses of VUTs differ.

The paper's indicator reads an SPCP's action on adversarial-yet-safe states (AYSS). It can
only separate two VUTs where the VUTs themselves react differently to those states: if two
VUTs brake alike at every state of the AYSS box, their SPCPs have nothing to adapt to
there. This module compares *measured* one-step responses (the VUT's acceleration over one
decision, m/s², measured in SUMO by :mod:`sumo_ayss.scenarios.responses`) on a grid over the
AYSS box and reports, for every pair of VUTs, the share of states where they differ by more
than a threshold: overall, by headway bin and by speed bin.

Pure numpy (no SUMO, no torch). Units: speeds m/s, headways m, accelerations m/s², TTC s.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from sumo_ayss.analysis.metrics import ttc_longitudinal
from sumo_ayss.util.errors import ConfigError
from sumo_ayss.util.validation import check_range

__all__ = [
    "DEFAULT_THRESHOLD_MPS2",
    "BoxGrid",
    "BoxStates",
    "Discriminability",
    "PairDiscriminability",
    "bin_shares",
    "compare_responses",
    "differ_mask",
    "lowest_differing_headway",
]

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]

#: Two responses "differ" where they are further apart than this [m/s²].
DEFAULT_THRESHOLD_MPS2 = 0.1


def _positive(where: str, value: float) -> float:
    value = float(value)
    if not (math.isfinite(value) and value > 0):
        raise ConfigError(f"{where} must be > 0, got {value}")
    return value


@dataclass(frozen=True)
class BoxStates:
    """The states of a :class:`BoxGrid` kept by the AYSS filter (1-D arrays, same length).

    Attributes:
        v_pov_mps: POV speed [m/s].
        v_vut_mps: VUT speed [m/s].
        h_m: Headway, POV rear bumper minus VUT front bumper [m].
    """

    v_pov_mps: FloatArray
    v_vut_mps: FloatArray
    h_m: FloatArray

    def __len__(self) -> int:
        return len(self.h_m)


@dataclass(frozen=True)
class BoxGrid:
    """A regular grid over the AYSS box, filtered like the AYSS Monte Carlo.

    Speeds take every ``speed_step_mps`` from the range's min to its max (both included);
    headways every ``headway_step_m`` from the range's min to its max. Kept: ``0 < h <=
    max_headway_m`` and ``TTC >= min_ttc_s`` with the longitudinal TTC
    (:func:`~sumo_ayss.analysis.metrics.ttc_longitudinal`), as
    :mod:`sumo_ayss.scenarios.ayss` keeps its samples (``h > 0`` also keeps cut-in's rule
    that the POV's rear is ahead of the VUT's front).

    Defaults: the AYSS stage's box (both speeds in [0, 30] m/s, h in [0, 5] m) at 1 m/s and
    0.1 m: 31 × 31 × 51 = 49,011 grid points of which 38,496 pass the filter; measuring them
    in SUMO took about 3 s per VUT on one (shared) core of this machine, 256 pairs per
    simulation step. The research note's grid (0.25 m/s, 0.05 m) has 1.18 M states.

    Attributes:
        v_pov_mps: POV speed range [m/s].
        v_vut_mps: VUT speed range [m/s].
        h_m: Headway range [m].
        speed_step_mps: Grid step of both speeds [m/s].
        headway_step_m: Grid step of the headway [m].
        max_headway_m: Keep ``h <= max_headway_m`` [m] (paper: 5 m).
        min_ttc_s: Keep ``TTC >= min_ttc_s`` [s] (paper: 0.2 s).
    """

    v_pov_mps: tuple[float, float] = (0.0, 30.0)
    v_vut_mps: tuple[float, float] = (0.0, 30.0)
    h_m: tuple[float, float] = (0.0, 5.0)
    speed_step_mps: float = 1.0
    headway_step_m: float = 0.1
    max_headway_m: float = 5.0
    min_ttc_s: float = 0.2

    def __post_init__(self) -> None:
        for name, low in (("v_pov_mps", 0.0), ("v_vut_mps", 0.0), ("h_m", -math.inf)):
            object.__setattr__(self, name, check_range(name, getattr(self, name), low))
        for name in ("speed_step_mps", "headway_step_m", "max_headway_m"):
            object.__setattr__(self, name, _positive(name, getattr(self, name)))
        if not (math.isfinite(self.min_ttc_s) and self.min_ttc_s >= 0):
            raise ConfigError(f"min_ttc_s must be >= 0, got {self.min_ttc_s}")

    @staticmethod
    def _axis(lo: float, hi: float, step: float) -> FloatArray:
        n = math.floor((hi - lo) / step + 1e-9)
        return np.round(lo + step * np.arange(n + 1), 9)

    def states(self) -> BoxStates:
        """The kept grid points, ordered by ``v_pov``, then ``v_vut``, then ``h``."""
        vp = self._axis(*self.v_pov_mps, self.speed_step_mps)
        vv = self._axis(*self.v_vut_mps, self.speed_step_mps)
        hh = self._axis(*self.h_m, self.headway_step_m)
        grid = np.meshgrid(vp, vv, hh, indexing="ij")
        v_pov, v_vut, h = (g.ravel() for g in grid)
        ttc = np.asarray(ttc_longitudinal(h, v_pov, v_vut), dtype=float)
        keep = (h > 0.0) & (h <= self.max_headway_m) & (ttc >= self.min_ttc_s)
        return BoxStates(v_pov[keep], v_vut[keep], h[keep])

    def to_dict(self) -> dict[str, Any]:
        return {k: list(v) if isinstance(v, tuple) else v for k, v in self.__dict__.items()}


def differ_mask(a_mps2: npt.ArrayLike, b_mps2: npt.ArrayLike, threshold_mps2: float) -> BoolArray:
    """``|a - b| > threshold_mps2`` elementwise (NaN never differs)."""
    a, b = np.asarray(a_mps2, dtype=float), np.asarray(b_mps2, dtype=float)
    if a.shape != b.shape:
        raise ConfigError(f"responses must have the same shape, got {a.shape} and {b.shape}")
    with np.errstate(invalid="ignore"):
        return np.asarray(np.abs(a - b) > threshold_mps2, dtype=bool)


def _bin_index(x: FloatArray, edges: FloatArray) -> npt.NDArray[np.int64]:
    """Bin of each ``x`` in ``[e_i, e_{i+1})``, the last bin closed; -1 outside."""
    idx = np.searchsorted(edges, x, side="right") - 1
    idx[x == edges[-1]] = len(edges) - 2
    idx[(x < edges[0]) | (x > edges[-1])] = -1
    return idx.astype(np.int64)


def bin_shares(
    flags: npt.ArrayLike, x: npt.ArrayLike, edges: npt.ArrayLike
) -> tuple[npt.NDArray[np.int64], FloatArray]:
    """Per bin of ``x``: the number of states and the share of them where ``flags`` holds.

    Args:
        flags: Booleans, one per state.
        x: The binned quantity per state (same length).
        edges: Increasing bin edges, length ``n_bins + 1``; bins are ``[e_i, e_{i+1})``, the
            last one closed. States outside ``[e_0, e_n]`` are ignored.

    Returns:
        ``(counts, shares)``, each of length ``n_bins``; a share is in [0, 1], NaN for an
        empty bin.
    """
    f = np.asarray(flags, dtype=bool)
    xv = np.asarray(x, dtype=float)
    e = np.asarray(edges, dtype=float)
    if e.ndim != 1 or len(e) < 2 or np.any(np.diff(e) <= 0):
        raise ConfigError(f"edges must be increasing with at least 2 values, got {e.tolist()}")
    if f.shape != xv.shape:
        raise ConfigError(f"flags and x must have the same shape, got {f.shape} and {xv.shape}")
    idx = _bin_index(xv, e)
    inside = idx >= 0
    n_bins = len(e) - 1
    counts = np.bincount(idx[inside], minlength=n_bins).astype(np.int64)
    hits = np.bincount(idx[inside], weights=f[inside].astype(float), minlength=n_bins)
    with np.errstate(invalid="ignore", divide="ignore"):
        shares = np.where(counts > 0, hits / np.maximum(counts, 1), np.nan)
    return counts, shares


def _bin_means(y: FloatArray, x: FloatArray, edges: FloatArray) -> FloatArray:
    idx = _bin_index(x, edges)
    inside = idx >= 0
    n_bins = len(edges) - 1
    counts = np.bincount(idx[inside], minlength=n_bins)
    sums = np.bincount(idx[inside], weights=y[inside], minlength=n_bins)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(counts > 0, sums / np.maximum(counts, 1), np.nan)


def lowest_differing_headway(flags: npt.ArrayLike, h_m: npt.ArrayLike) -> float | None:
    """The smallest headway [m] of a state where ``flags`` holds; None if it never holds."""
    f = np.asarray(flags, dtype=bool)
    if not f.any():
        return None
    return float(np.min(np.asarray(h_m, dtype=float)[f]))


@dataclass(frozen=True)
class PairDiscriminability:
    """How two VUTs' one-step responses differ over the box.

    Attributes:
        a, b: VUT names.
        n_states: States compared.
        share: Share of states with ``|a - b| > threshold`` (0..1).
        mean_abs_diff_mps2: Mean ``|a - b|`` over all states [m/s²].
        max_abs_diff_mps2: Largest ``|a - b|`` [m/s²].
        lowest_h_m: Smallest headway where they differ [m]; None if nowhere.
        share_by_h: Share per headway bin (NaN: empty bin).
        share_by_v_vut: Share per VUT-speed bin.
        share_by_v_pov: Share per POV-speed bin.
        mean_abs_diff_by_h_mps2: Mean ``|a - b|`` per headway bin [m/s²].
    """

    a: str
    b: str
    n_states: int
    share: float
    mean_abs_diff_mps2: float
    max_abs_diff_mps2: float
    lowest_h_m: float | None
    share_by_h: FloatArray
    share_by_v_vut: FloatArray
    share_by_v_pov: FloatArray
    mean_abs_diff_by_h_mps2: FloatArray

    def to_dict(self) -> dict[str, Any]:
        def clean(arr: FloatArray) -> list[float | None]:
            return [None if not math.isfinite(v) else float(v) for v in arr]

        return {
            "a": self.a,
            "b": self.b,
            "n_states": self.n_states,
            "share": self.share,
            "mean_abs_diff_mps2": self.mean_abs_diff_mps2,
            "max_abs_diff_mps2": self.max_abs_diff_mps2,
            "lowest_h_m": self.lowest_h_m,
            "share_by_h": clean(self.share_by_h),
            "share_by_v_vut": clean(self.share_by_v_vut),
            "share_by_v_pov": clean(self.share_by_v_pov),
            "mean_abs_diff_by_h_mps2": clean(self.mean_abs_diff_by_h_mps2),
        }


@dataclass(frozen=True)
class Discriminability:
    """Every pair of VUTs compared on the same states.

    Attributes:
        threshold_mps2: Two responses differ where ``|a - b|`` exceeds this [m/s²].
        h_edges_m: Headway bin edges [m].
        v_edges_mps: Speed bin edges [m/s] (VUT and POV speed).
        n_states: States compared.
        mean_response_mps2: Mean response per VUT over all states [m/s²].
        mean_response_by_h_mps2: Mean response per VUT per headway bin [m/s²].
        pairs: One entry per unordered pair, in the order the VUTs were given.
    """

    threshold_mps2: float
    h_edges_m: FloatArray
    v_edges_mps: FloatArray
    n_states: int
    mean_response_mps2: dict[str, float]
    mean_response_by_h_mps2: dict[str, FloatArray]
    pairs: list[PairDiscriminability] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        def clean(arr: FloatArray) -> list[float | None]:
            return [None if not math.isfinite(v) else float(v) for v in arr]

        return {
            "threshold_mps2": self.threshold_mps2,
            "h_edges_m": [float(v) for v in self.h_edges_m],
            "v_edges_mps": [float(v) for v in self.v_edges_mps],
            "n_states": self.n_states,
            "mean_response_mps2": dict(self.mean_response_mps2),
            "mean_response_by_h_mps2": {
                k: clean(v) for k, v in self.mean_response_by_h_mps2.items()
            },
            "pairs": [p.to_dict() for p in self.pairs],
        }


def compare_responses(
    responses: Mapping[str, npt.ArrayLike],
    states: BoxStates,
    *,
    threshold_mps2: float = DEFAULT_THRESHOLD_MPS2,
    h_edges_m: npt.ArrayLike | None = None,
    v_edges_mps: npt.ArrayLike | None = None,
) -> Discriminability:
    """Compare every pair of VUTs' responses on ``states``.

    Args:
        responses: ``{vut: acceleration per state [m/s²]}``, each of length ``len(states)``.
        states: The states the responses were measured at.
        threshold_mps2: Responses differ where ``|a - b| > threshold_mps2``, >= 0.
        h_edges_m: Headway bin edges; default 0.5 m bins over [0, max h].
        v_edges_mps: Speed bin edges; default 3 m/s bins over [0, max speed].

    Returns:
        The :class:`Discriminability` of all pairs.
    """
    if not (math.isfinite(threshold_mps2) and threshold_mps2 >= 0):
        raise ConfigError(f"threshold_mps2 must be >= 0, got {threshold_mps2}")
    n = len(states)
    arrays = {}
    for name, r in responses.items():
        arr = np.asarray(r, dtype=float)
        if arr.shape != (n,):
            raise ConfigError(f"responses[{name!r}] must have shape ({n},), got {arr.shape}")
        arrays[name] = arr
    h, vv, vp = states.h_m, states.v_vut_mps, states.v_pov_mps
    if h_edges_m is None:
        top = max(0.5, 0.5 * math.ceil(float(h.max()) / 0.5)) if n else 5.0
        h_edges_m = np.linspace(0.0, top, round(top / 0.5) + 1)
    if v_edges_mps is None:
        vmax = float(max(vv.max(), vp.max())) if n else 30.0
        top = max(3.0, 3.0 * math.ceil(vmax / 3.0))
        v_edges_mps = np.linspace(0.0, top, round(top / 3.0) + 1)
    he = np.asarray(h_edges_m, dtype=float)
    ve = np.asarray(v_edges_mps, dtype=float)
    pairs = []
    for a, b in itertools.combinations(arrays, 2):
        diff = np.abs(arrays[a] - arrays[b])
        flags = differ_mask(arrays[a], arrays[b], threshold_mps2)
        pairs.append(
            PairDiscriminability(
                a=a,
                b=b,
                n_states=n,
                share=float(flags.mean()) if n else math.nan,
                mean_abs_diff_mps2=float(diff.mean()) if n else math.nan,
                max_abs_diff_mps2=float(diff.max()) if n else math.nan,
                lowest_h_m=lowest_differing_headway(flags, h),
                share_by_h=bin_shares(flags, h, he)[1],
                share_by_v_vut=bin_shares(flags, vv, ve)[1],
                share_by_v_pov=bin_shares(flags, vp, ve)[1],
                mean_abs_diff_by_h_mps2=_bin_means(diff, h, he),
            )
        )
    return Discriminability(
        threshold_mps2=float(threshold_mps2),
        h_edges_m=he,
        v_edges_mps=ve,
        n_states=n,
        mean_response_mps2={k: float(v.mean()) if n else math.nan for k, v in arrays.items()},
        mean_response_by_h_mps2={k: _bin_means(v, h, he) for k, v in arrays.items()},
        pairs=pairs,
    )
