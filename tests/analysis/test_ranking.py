"""Tests of sumo_ayss.analysis.ranking, and the analysis package's import hygiene."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

import sumo_ayss.analysis as analysis_pkg
from sumo_ayss.analysis.ranking import (
    DELTA_V_BAR,
    POV_ACCELERATION,
    SafetyIndex,
    compare,
    rank,
    safety_index,
)
from sumo_ayss.util.errors import ConfigError
from tests.helpers import loaded_among


def _vut(shift: float, rng: np.random.Generator, seeds: int = 3, n: int = 200):
    """Per-seed indicator and headway: a mean trend in h, plus ``shift``, plus noise."""
    ys, hs = [], []
    for _ in range(seeds):
        h = rng.uniform(0.0, 5.0, n)
        ys.append(-1.0 - 0.3 * h + shift + rng.normal(0.0, 1.0, n))
        hs.append(h)
    return ys, hs


# --------------------------------------------------------------------------- safety index


def test_safety_index_hand_case() -> None:
    # 5 bins of 1 m on [0, 5]. Bin 0: -2, -4 (mean -3); bin 1: -4; bin 4: 0; h = 6 dropped.
    # Mean of bin means = (-3 - 4 + 0) / 3 = -7/3, so the index is +7/3 (the plain mean of
    # the samples, -2.5, would weight bin 0 twice).
    samples = [np.array([-2.0, -4.0, 50.0]), np.array([-4.0, 0.0])]
    headway = [np.array([0.5, 1.5, 6.0]), np.array([0.2, 4.9])]
    idx = safety_index(samples, headway, (0.0, 5.0), n_bins=5, n_boot=200, rng=0)
    assert idx.point == pytest.approx(7.0 / 3.0)
    assert (idx.n_seeds, idx.n_samples) == (2, 4)
    assert idx.bins_used == (True, True, False, False, True)
    assert idx.lo <= idx.point <= idx.hi
    assert idx.replicates.shape == (200,)
    np.testing.assert_array_equal(np.sort(idx.indicator_samples), [-4.0, -4.0, -2.0, 0.0])
    # Per seed: seed 0 has bins 0 (-2) and 1 (-4) -> 3; seed 1 has bins 0 (-4), 4 (0) -> 2.
    assert idx.seed_points == pytest.approx((3.0, 2.0))


def test_safety_index_last_bin_is_closed_and_min_count() -> None:
    samples = [np.array([-1.0, -2.0, -3.0])]
    idx = safety_index(samples, [np.array([5.0, 4.5, 0.5])], n_bins=5, min_count=2, n_boot=10)
    assert idx.point == pytest.approx(1.5)  # only bin [4, 5] holds 2 samples
    assert idx.n_samples == 2


def test_safety_index_drops_seeds_without_samples_in_range() -> None:
    idx = safety_index(
        [np.array([-1.0]), np.array([-3.0])], [np.array([1.0]), np.array([9.0])], n_boot=10
    )
    assert (idx.n_seeds, idx.n_samples, idx.point) == (1, 1, 1.0)


def test_safety_index_is_reproducible_and_frozen() -> None:
    ys, hs = _vut(0.0, np.random.default_rng(3))
    first = safety_index(ys, hs, n_boot=100, rng=11)
    second = safety_index(ys, hs, n_boot=100, rng=11)
    assert first == second
    np.testing.assert_array_equal(first.replicates, second.replicates)
    with pytest.raises(ValueError):
        first.replicates[0] = 1.0


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"samples_by_seed": [np.ones(2)], "headway_by_seed": []}, "same, non-zero"),
        ({"samples_by_seed": [np.ones(2)], "headway_by_seed": [np.ones(3)]}, r"\[0\]"),
        ({"samples_by_seed": [[np.nan]], "headway_by_seed": [[1.0]]}, "NaN"),
        ({"samples_by_seed": [[1.0]], "headway_by_seed": [[7.0]]}, "no headway bin"),
        ({"samples_by_seed": [[1.0]], "headway_by_seed": [[1.0]], "h_range": (5, 0)}, "h_range"),
        ({"samples_by_seed": [[1.0]], "headway_by_seed": [[1.0]], "n_bins": 0}, "n_bins"),
        ({"samples_by_seed": [[1.0]], "headway_by_seed": [[1.0]], "level": 95}, "level"),
    ],
)
def test_safety_index_rejects_bad_input(kwargs: dict, match: str) -> None:
    with pytest.raises(ConfigError, match=match):
        safety_index(**kwargs)


# --------------------------------------------------------------------------- verdicts


def test_compare_direction_when_one_vuts_spcps_are_clearly_more_aggressive() -> None:
    rng = np.random.default_rng(42)
    pi1 = safety_index(*_vut(0.0, rng), n_boot=500, rng=1)
    pi2 = safety_index(*_vut(-1.5, rng), n_boot=500, rng=2)  # SPCPs brake 1.5 m/s² harder
    verdict = compare(pi1, pi2, name_a="pi1", name_b="pi2", indicator=POV_ACCELERATION)
    assert verdict.safer == "pi2" and verdict.significant
    assert verdict.difference == pytest.approx(-1.5, abs=0.3)
    assert verdict.diff_lo <= verdict.difference <= verdict.diff_hi < 0.0
    assert verdict.p_a_safer < 0.01
    assert verdict.cohens_d < -0.5  # pi2's SPCPs are more aggressive: B safer
    assert verdict.p_seed_welch < 0.01
    # Swapping the arguments flips the signs, not the verdict.
    swapped = compare(pi2, pi1, name_a="pi2", name_b="pi1", indicator=POV_ACCELERATION)
    assert swapped.safer == "pi2"
    assert swapped.difference == pytest.approx(-verdict.difference)
    assert swapped.p_a_safer == pytest.approx(1.0 - verdict.p_a_safer)


def test_compare_same_distribution_is_no_significant_difference() -> None:
    rng = np.random.default_rng(2024)
    first = safety_index(*_vut(0.0, rng), n_boot=1000, rng=5)
    again = safety_index(*_vut(0.0, rng), n_boot=1000, rng=6)  # other seeds, same VUT
    verdict = compare(first, again, name_a="pi1", name_b="pi1'", indicator=DELTA_V_BAR)
    assert verdict.safer is None and not verdict.significant
    assert verdict.diff_lo < 0.0 < verdict.diff_hi
    assert 0.025 < verdict.p_a_safer < 0.975
    assert verdict.p_seed_welch > 0.05


def test_compare_rejects_incomparable_indices() -> None:
    rng = np.random.default_rng(0)
    ys, hs = _vut(0.0, rng, seeds=1, n=20)
    a = safety_index(ys, hs, n_boot=20, rng=0)
    with pytest.raises(ConfigError, match="replicates"):
        compare(a, safety_index(ys, hs, n_boot=30, rng=0))
    with pytest.raises(ConfigError, match="h_range"):
        compare(a, safety_index(ys, hs, (0.0, 4.0), n_boot=20, rng=0))
    with pytest.raises(ConfigError, match="name_b"):
        compare(a, a, name_a="same", name_b="same")
    with pytest.raises(ConfigError, match="replicates"):
        compare(a, SafetyIndex(point=1.0, lo=0.0, hi=2.0, n_seeds=1, n_samples=1))


# --------------------------------------------------------------------------- ranking


def test_rank_orders_safest_first_with_intervals() -> None:
    rng = np.random.default_rng(9)
    indices = {
        name: safety_index(*_vut(shift, rng), n_boot=300, rng=seed)
        for seed, (name, shift) in enumerate([("mid", -1.0), ("unsafe", 0.0), ("safe", -2.5)])
    }
    rows = rank(indices)
    assert [r.name for r in rows] == ["safe", "mid", "unsafe"]
    assert [r.rank for r in rows] == [1, 2, 3]
    assert all(r.lo <= r.point <= r.hi for r in rows)
    assert rows[0].significant_vs_next and rows[1].significant_vs_next
    assert rows[0].p_safer_than_next is not None and rows[0].p_safer_than_next > 0.99
    assert rows[-1].p_safer_than_next is None and rows[-1].significant_vs_next is None
    with pytest.raises(ConfigError, match="indices"):
        rank({})


# --------------------------------------------------------------------------- import hygiene

FORBIDDEN = {"libsumo", "traci", "sumolib", "torch", "stable_baselines3"}
ANALYSIS_DIR = Path(analysis_pkg.__file__).parent


def _imported_roots(path: Path) -> set[str]:
    roots = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            roots |= {alias.name.split(".")[0] for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            roots.add(node.module.split(".")[0])
    return roots


@pytest.mark.parametrize("path", sorted(ANALYSIS_DIR.glob("*.py")), ids=lambda p: p.name)
def test_analysis_imports_no_sumo_or_torch(path: Path) -> None:
    roots = _imported_roots(path)
    assert not roots & FORBIDDEN, f"{path.name} imports {sorted(roots & FORBIDDEN)}"
    if not path.name.startswith("plot"):
        assert "matplotlib" not in roots, f"{path.name}: matplotlib only in a plotting module"


def test_importing_analysis_loads_no_sumo_or_torch() -> None:
    bad = loaded_among("import sumo_ayss.analysis", FORBIDDEN)
    assert bad == [], f"importing sumo_ayss.analysis loaded {bad}"


#: Packages of the project that analysis/ must not import: it reads tables, nothing more.
FORBIDDEN_LAYERS = ("sumo_ayss.report", "sumo_ayss.sim", "sumo_ayss.envs", "sumo_ayss.agents")


def _imported_modules(path: Path) -> set[str]:
    mods = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            mods |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            mods.add(node.module)
    return mods


@pytest.mark.parametrize("path", sorted(ANALYSIS_DIR.glob("*.py")), ids=lambda p: p.name)
def test_analysis_imports_no_report_sim_envs_or_agents(path: Path) -> None:
    bad = sorted(
        m for m in _imported_modules(path) if m == "sumo_ayss" or m.startswith(FORBIDDEN_LAYERS)
    )
    assert not bad, f"{path.name} imports {bad}"
