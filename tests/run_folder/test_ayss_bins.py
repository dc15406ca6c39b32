"""``ayss_bins.csv``: the AYSS samples as per-cell moments give what the samples give.

Tolerance: counts, used bins and the sample count are equal exactly; means, t-intervals,
the safety index's point and per-seed values and Cohen's d agree to 1e-9 (float rounding of
sums taken in another order). The safety index's bootstrap interval from cells is a draw of
nearly the same bootstrap (:mod:`sumo_ayss.analysis.ayss_cells`), checked to be within a
tenth of its width of the samples' interval.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
import yaml

from sumo_ayss.analysis import ayss_cells as analysis_cells
from sumo_ayss.analysis.ayss_cells import (
    binned_stats_from_cells,
    cells_of,
    inside_moments,
    run_cells,
    safety_index_from_cells,
)
from sumo_ayss.analysis.case import vut_safety_index
from sumo_ayss.analysis.safety_index import safety_index
from sumo_ayss.analysis.seed_intervals import binned_seed_means, seed_bands
from sumo_ayss.analysis.stats import binned_mean_ci, cohens_d
from sumo_ayss.analysis.verdict import _moments_cohens_d
from sumo_ayss.config import AyssConfig, load_experiment
from sumo_ayss.config.report import ReportOptions
from sumo_ayss.evaluate import evaluate_run
from sumo_ayss.report import figures
from sumo_ayss.run_folder import ayss_bins as stored_cells
from sumo_ayss.run_folder import read_run
from sumo_ayss.run_folder.ayss_bins import AyssCells, read_ayss_bins, write_ayss_bins
from sumo_ayss.train import train
from sumo_ayss.util.errors import ConfigError
from tests.helpers import tiny_experiment

RTOL = 1e-9
REPORT_EDGES = np.arange(0.0, 5.0 + 1e-9, 0.25)  # the report's default bins (0.25 m)


def _samples(seed: int, n: int = 4000) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    h = rng.uniform(0.0, 5.0, n).astype(np.float32).astype(np.float64)
    h[:40] = np.repeat([0.0, 0.25, 0.5, 2.5, 5.0], 8)  # samples exactly on edges, both ends
    y = -2.0 + 0.3 * h + rng.normal(0.0, 1.0, n)
    return h, y


def _close(a: np.ndarray, b: np.ndarray) -> None:
    np.testing.assert_allclose(a, b, rtol=RTOL, atol=RTOL, equal_nan=True)


def test_cells_give_the_figures_bins_and_the_safety_index_of_the_samples() -> None:
    seeds = [_samples(s) for s in range(3)]
    cells = [cells_of(h, y) for h, y in seeds]
    assert [int(c.n.sum()) for c in cells] == [len(h) for h, _ in seeds]
    for (h, y), c in zip(seeds, cells, strict=True):
        a, b = binned_mean_ci(h, y, REPORT_EDGES), binned_stats_from_cells([c], REPORT_EDGES)
        assert np.array_equal(a.counts, b.counts)
        for name in ("means", "lo", "hi"):
            _close(getattr(a, name), getattr(b, name))
        n_in, mean_in = inside_moments(c, 0.0, 4.0)  # the closed [0, h_max] of the table
        inside = (h >= 0) & (h <= 4.0)
        assert n_in == int(inside.sum()) and mean_in == pytest.approx(y[inside].mean(), RTOL)
    bands = binned_seed_means(seeds, REPORT_EDGES)
    from_cells = seed_bands(
        [binned_stats_from_cells([c], REPORT_EDGES) for c in cells], REPORT_EDGES
    )
    for name in ("means", "lo", "hi"):
        _close(getattr(bands, name), getattr(from_cells, name))
    pooled = binned_mean_ci(
        np.concatenate([h for h, _ in seeds]), np.concatenate([y for _, y in seeds]), REPORT_EDGES
    )
    _close(pooled.means, binned_stats_from_cells(cells, REPORT_EDGES).means)

    idx = safety_index([y for _, y in seeds], [h for h, _ in seeds], rng=0)
    alt = safety_index_from_cells(cells, rng=0)
    assert alt.point == pytest.approx(idx.point, RTOL)
    _close(np.array(alt.seed_points), np.array(idx.seed_points))
    assert (alt.n_samples, alt.bins_used, alt.n_seeds) == (idx.n_samples, idx.bins_used, 3)
    width = idx.hi - idx.lo
    assert abs(alt.lo - idx.lo) < 0.1 * width and abs(alt.hi - idx.hi) < 0.1 * width
    ya, yb = seeds[0][1], seeds[1][1]
    n, m, s = len(ya), ya.mean(), float(np.sum((ya - ya.mean()) ** 2))
    moments_b = (len(yb), yb.mean(), float(np.sum((yb - yb.mean()) ** 2)))
    assert _moments_cohens_d((n, m, s), moments_b) == pytest.approx(cohens_d(-ya, -yb), RTOL)


def test_the_reduction_and_the_file_share_one_lattice() -> None:
    """The analysis reduces on the lattice the reader checks (storage imports no analysis)."""
    assert analysis_cells.CELL_WIDTH_M == stored_cells.CELL_WIDTH_M == 1.0 / 32.0


def test_a_grid_off_the_cells_lattice_is_refused(tmp_path: Path) -> None:
    h, y = _samples(0)
    c = cells_of(h, y)
    cells = AyssCells(c.h_low_m, c.h_high_m, c.n, c.mean, c.m2, "pov_accel_mps2")
    with pytest.raises(ConfigError, match="lattice"):
        binned_stats_from_cells([cells], np.arange(0.0, 5.01, 0.3))
    write_ayss_bins(tmp_path / "ayss_bins.csv", cells)
    back = read_ayss_bins(tmp_path / "ayss_bins.csv")
    for name in ("h_low_m", "h_high_m", "n", "mean", "m2"):
        assert np.array_equal(getattr(back, name), getattr(cells, name))
    assert back.indicator_name == "pov_accel_mps2"


@pytest.mark.sumo
def test_a_run_with_only_ayss_bins_reads_and_draws_as_with_its_samples(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    config = tmp_path / "tiny.yaml"
    config.write_text(yaml.safe_dump(tiny_experiment()))
    run = train(load_experiment(config), seed=1, out=tmp_path / "runs")
    evaluate_run(run, n_outcome=2, ayss=AyssConfig(n_samples=3000, seed=5), progress=False)
    assert (run / "ayss_bins.csv").is_file()  # written by the evaluate stage with ayss.csv
    written = (run / "ayss_bins.csv").read_bytes()
    (run / "ayss_bins.csv").unlink()  # a run evaluated before the file existed: reduced, not re-run
    again = evaluate_run(run, n_outcome=2, ayss=AyssConfig(n_samples=3000, seed=5), progress=False)
    assert not again.ran_ayss and (run / "ayss_bins.csv").read_bytes() == written
    with_samples = read_run(run)
    assert with_samples.ayss is not None and len(with_samples.ayss) > 0
    only_bins = tmp_path / "only_bins"
    shutil.copytree(run, only_bins)
    (only_bins / "ayss.csv").unlink()
    summary = read_run(only_bins)
    assert summary.ayss is None and isinstance(summary.ayss_bins, AyssCells)
    assert not any("ayss.csv" in p for p in summary.problems)
    cells = run_cells(summary)
    assert cells is not None and int(cells.n.sum()) == len(with_samples.ayss)

    # the figures' data: bands between seeds and the pooled bins
    a_bands, a_pooled = figures._vut_bins([with_samples], REPORT_EDGES, 0.95)
    b_bands, b_pooled = figures._vut_bins([summary], REPORT_EDGES, 0.95)
    assert np.array_equal(a_pooled.counts, b_pooled.counts)
    for a, b in ((a_bands, b_bands), (a_pooled, b_pooled)):
        for name in ("means", "lo", "hi"):
            _close(getattr(a, name), getattr(b, name))
    # the paper mode's safety index
    options = ReportOptions()
    a_idx = vut_safety_index([with_samples], options, rng=0)
    b_idx = vut_safety_index([summary], options, rng=0)
    assert a_idx is not None and b_idx is not None
    assert b_idx.point == pytest.approx(a_idx.point, RTOL)
    assert (b_idx.n_samples, b_idx.bins_used) == (a_idx.n_samples, a_idx.bins_used)

    # the figure draws from ayss_bins.csv; with neither file it says there are no samples
    said: list[str] = []
    real_no_data = figures.no_data
    monkeypatch.setattr(
        figures, "no_data", lambda ax, text: said.append(text) or real_no_data(ax, text)
    )
    draw = {"edges": REPORT_EDGES, "axis_label": "a", "title": "t"}
    figures.indicator_figure({"pi1": [summary]}, {"pi1": "C0"}, tmp_path / "a.png", **draw)
    assert not said
    (only_bins / "ayss_bins.csv").unlink()
    neither = read_run(only_bins)
    assert not figures.has_ayss(neither)
    figures.indicator_figure({"pi1": [neither]}, {"pi1": "C0"}, tmp_path / "b.png", **draw)
    assert said == ["no AYSS samples (ayss.csv) in these runs yet"]


def test_git_keeps_ayss_bins_and_leaves_out_ayss_csv() -> None:
    from fnmatch import fnmatch

    from sumo_ayss.config import PROJECT_ROOT

    patterns = [
        line.strip()
        for line in (PROJECT_ROOT / ".gitignore").read_text().splitlines()
        if line.strip() and not line.startswith("#")
    ]
    run = "results/paper/car_following/pi1/seed_0"

    def ignored(name: str) -> bool:
        path = f"{run}/{name}"
        return any(fnmatch(path, p.replace("**/", "*")) or fnmatch(name, p) for p in patterns)

    assert ignored("ayss.csv") and not ignored("ayss_bins.csv")
