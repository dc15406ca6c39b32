"""The report says what its data say: captions checked against what is plotted, intervals
inside what is possible, a leaderboard first, one minus sign, modes stated as they ran."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from sumo_ayss.modes import analyse_case
from sumo_ayss.modes.crossplay import crossplay_result
from sumo_ayss.modes.formatting import fmt_num
from sumo_ayss.modes.paper import paper_result
from sumo_ayss.report import write_report
from sumo_ayss.report.crossplay_figure import crossplay_lines
from sumo_ayss.report.figstyle import set_wrapped_title, style
from sumo_ayss.report.leaderboard import leaderboard_rows, leaderboard_table, leaderboard_text
from sumo_ayss.run_folder import read_run
from sumo_ayss.run_folder.crossplay import load_crossplay
from tests.report.test_report import FAST, make_crossplay, make_run


def scored_crossplay(runs):  # type: ignore[no-untyped-def]
    """The case's cross-play files as stored (:func:`load_crossplay`), scored by the analysis."""
    from sumo_ayss.analysis.crossplay_scoring import crossplay_input

    return crossplay_input(load_crossplay(runs), runs)


def _runs(root: Path, case: str, vuts: tuple[str, ...], seeds: range) -> dict:
    for vut in vuts:
        for seed in seeds:
            make_run(root, case, vut, seed)
    return {v: [read_run(root / case / v / f"seed_{s}") for s in seeds] for v in vuts}


@pytest.fixture(scope="module")
def crossplay_report(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("runs")
    _runs(root, "car_following", ("pi1", "pi2"), range(3))
    make_crossplay(root / "car_following", ["pi1", "pi2"], range(3))
    return write_report([root], options=FAST)


def _section(html: str, start: str, end: str) -> str:
    return html.split(f'id="{start}"')[1].split(f'id="{end}"')[0]


def test_crossplay_caption_claim_matches_the_plotted_lines(tmp_path: Path) -> None:
    runs = _runs(tmp_path, "car_following", ("pi1", "pi2"), range(3))
    make_crossplay(tmp_path / "car_following", ["pi1", "pi2"], range(3))
    a = analyse_case("car_following", runs, FAST, crossplay=scored_crossplay(runs))
    result = crossplay_result(a)
    assert result.matrix is not None and result.rows[0].vs_next is not None
    assert result.rows[0].vs_next.significant  # the ranking is a finding here
    order = [r.name for r in result.rows]
    lines = crossplay_lines(order, result.matrix.harm, result.matrix.vuts)
    # What the figure draws, left to right: safest first, so the mean over opponents rises.
    assert np.all(np.diff(lines.mean(axis=0)) > 0)
    rising = int(np.sum(np.all(np.diff(lines, axis=1) > 0, axis=1)))
    falling = int(np.sum(np.all(np.diff(lines, axis=1) < 0, axis=1)))
    assert rising > falling
    # ... and the caption says that rising lines agree with the ranking.
    html = write_report([tmp_path], options=FAST).read_text(encoding="utf-8")
    caption = html.split("brings about against each VUT, VUTs in cross-play ranking order")[1]
    caption = caption.split("</figcaption>")[0]
    assert "lines that rise from left to right agree with the ranking" in caption
    assert "fall from left to right agree" not in html


def test_leaderboard_comes_first_with_rank_score_crashes_and_verdict(
    crossplay_report: Path,
) -> None:
    html = crossplay_report.read_text(encoding="utf-8")
    assert html.index('id="leaderboard"') < html.index('id="verdicts"')
    board = _section(html, "leaderboard", "verdicts")
    for head in (
        "rank",
        "VUT",
        "cross-play harm H per episode",
        "crash rate",
        "vs next",
        "mean speed",
    ):
        assert head in board
    assert board.index("pi2") < board.index("pi1")  # pi2 is safer in the synthetic data
    # The margin against the next VUT with its interval, then the test.
    assert re.search(r"safer than pi1 by \d\.\d{3} \(\d\.\d{3}–\d\.\d{3}\); paired t, p", board)
    assert re.search(r"\d+\.\d m/s", board)  # mobility in the first table
    assert re.search(r"\d\.\d % \(\d+\.\d–\d+\.\d %\), \d+/\d+", board)  # crash rate cell


def test_leaderboard_text_fits_80_columns_and_matches_the_report(tmp_path: Path) -> None:
    runs = _runs(tmp_path, "car_following", ("pi1", "pi2"), range(3))
    make_crossplay(tmp_path / "car_following", ["pi1", "pi2"], range(3))
    a = analyse_case("car_following", runs, FAST, crossplay=scored_crossplay(runs))
    text = leaderboard_text([a])
    rows = leaderboard_rows(a)
    assert [r.vut for r in rows] == ["pi2", "pi1"]
    assert all(len(line) <= 80 for line in text.splitlines()), text
    flat = " ".join(text.split())
    assert rows[0].score in flat and rows[0].vs_next in flat


def test_two_seed_report_prints_no_t_interval_over_two_points(tmp_path: Path) -> None:
    _runs(tmp_path, "car_following", ("pi1", "pi2"), range(2))
    html = write_report([tmp_path], options=FAST).read_text(encoding="utf-8")
    premise = html.split("Outcome of the SPCPs per VUT")[1].split("</table>")[0]
    assert premise.count("2 seeds: no interval") == 6  # 3 metrics x 2 VUTs
    assert "(no interval with 2 seeds)" in _section(html, "leaderboard", "verdicts")


def test_premise_crash_rate_intervals_lie_in_0_100(tmp_path: Path) -> None:
    _runs(tmp_path, "car_following", ("pi1", "pi2"), range(4))
    html = write_report([tmp_path], options=FAST).read_text(encoding="utf-8")
    premise = html.split("Outcome of the SPCPs per VUT")[1].split("</table>")[0]
    row = premise.split("crash rate [%]")[1].split("</tr>")[0]
    cells = re.findall(r"([−\d.]+) \(([−\d.]+)(?:–| to )([−\d.]+)\)", row)
    assert len(cells) == 2, row
    for mean, lo, hi in cells:
        lo_v, mean_v, hi_v = (float(x.replace("−", "-")) for x in (lo, mean, hi))
        assert 0.0 <= lo_v <= mean_v <= hi_v <= 100.0


def test_one_minus_sign_in_the_report(crossplay_report: Path) -> None:
    html = crossplay_report.read_text(encoding="utf-8")
    html = re.sub(r"<style.*?</style>", " ", html, flags=re.S)
    text = re.sub(r"<[^>]+>", " ", html)
    assert not re.search(r"(?<![\w.])-\d", text), re.findall(r".{30}(?<![\w.])-\d.{10}", text)


def test_single_vut_report_claims_no_verdict_mode(tmp_path: Path) -> None:
    _runs(tmp_path, "car_following", ("pi1",), range(1))
    html = write_report([tmp_path], options=FAST).read_text(encoding="utf-8")
    assert "Verdicts above are in" not in html
    assert "No verdict: every case of this report has fewer than two VUTs" in html
    assert "from 1 run folder (" in html


@pytest.mark.parametrize("width_in", [4.0, 5.4, 8.0])
def test_wrapped_title_fits_its_figure(width_in: float) -> None:
    title = "One-lane car-following: exposure harm per seed (lower = safer), a long title"
    with style():
        fig = Figure(figsize=(width_in, 4.0), layout="constrained")
        canvas = FigureCanvasAgg(fig)
        ax = fig.subplots()
        text = set_wrapped_title(ax, title, width_in)
        canvas.draw()
        box = text.get_window_extent(canvas.get_renderer())
    assert box.width <= fig.bbox.width
    assert box.x0 >= 0 and box.x1 <= fig.bbox.width


def test_paper_mode_leaderboard_reads_the_safety_index(tmp_path: Path) -> None:
    from sumo_ayss.config.report import ReportOptions

    runs = _runs(tmp_path, "car_following", ("pi1", "pi2"), range(3))
    a = analyse_case("car_following", runs, ReportOptions(mode="paper", n_boot=300))
    rows = leaderboard_rows(a)
    assert a.ranking_mode == "paper"
    ranking = paper_result(a).ranking
    assert [r.vut for r in rows] == [r.name for r in ranking]
    assert rows[0].score == fmt_num(ranking[0].point)
    table = leaderboard_table(a, 0.95)
    assert table is not None and "m/s²" in table.headers[3]  # the unit, in the score's header
    assert "Welch t, p" in rows[0].vs_next and rows[-1].vs_next == "—"
    assert "safety index (higher = safer)" in leaderboard_text([a])


def test_the_first_aggressiveness_panel_carries_the_between_seed_spread(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Left panel (read first): every seed's bin mean lies inside its VUT's band; right
    panel: the pooled view, named as such."""
    from matplotlib.collections import PolyCollection
    from matplotlib.colors import to_rgb

    from sumo_ayss.report import figures

    runs = _runs(tmp_path, "car_following", ("pi1", "pi2"), range(2))
    drawn: list[Figure] = []
    monkeypatch.setattr(figures, "save", lambda fig, path: drawn.append(fig) or path)
    figures.indicator_figure(
        runs,
        {"pi1": "C0", "pi2": "C1"},
        tmp_path / "fig.png",
        edges=np.linspace(0.0, 5.0, 11),
        axis_label="a [m/s²]",
        title="t",
    )
    left, _, right, _ = drawn[0].axes
    assert left.get_title().startswith("Primary, between seeds (what the verdict uses)")
    assert "range of the 2 seeds" in left.get_title()
    assert right.get_title().startswith("Secondary: all samples pooled")
    assert "ignores the seed-to-seed spread" in right.get_title()
    bands = {}
    for poly in (c for c in left.collections if isinstance(c, PolyCollection)):
        verts = np.concatenate([p.vertices for p in poly.get_paths()])
        bands[tuple(poly.get_facecolor()[0][:3])] = verts
    assert len(bands) == 2
    checked = 0
    for line in left.get_lines():
        if " seed " not in str(line.get_label()):
            continue
        color = to_rgb(line.get_color())
        verts = next(v for c, v in bands.items() if np.allclose(c, color))
        for x, y in zip(*line.get_data(), strict=True):
            if not np.isfinite(y):
                continue
            at = verts[np.isclose(verts[:, 0], x)][:, 1]
            assert at.min() - 1e-9 <= y <= at.max() + 1e-9, (line.get_label(), x, y)
            checked += 1
    assert checked >= 20  # 2 VUTs x 2 seeds x 10 bins, all inside their band
