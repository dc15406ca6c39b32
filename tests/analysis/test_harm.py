"""The harm score on synthetic cross-play tables with a known answer (issue 22).

Each test builds the episode columns of a cross-play table (VUT, opponent, near-miss pay,
collision, mobility) and ranks them as the product does: :func:`episode_harm` ->
:func:`crossplay_matrix` -> :func:`rank_crossplay` (paired t-test over seed blocks).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sumo_ayss.analysis.crossplay import crossplay_matrix, rank_crossplay
from sumo_ayss.analysis.harm import (
    MOBILITY_FLOOR,
    EpisodeStats,
    HarmScale,
    episode_harm,
    mobility_flags,
    vut_outcomes,
)
from sumo_ayss.analysis.seeds import compare_seeds
from sumo_ayss.config import PROJECT_ROOT
from sumo_ayss.util.errors import ConfigError

MAX_PAY = 25.0  # alpha_A = 1, 25 decisions
ALPHA_C = 10.0
SEEDS = (0, 1, 2)


def table(
    rng: np.random.Generator,
    crash_p: dict[str, float],
    pay_mean: dict[str, float],
    *,
    n: int = 100,
    seeds: tuple[int, ...] = SEEDS,
    opp_sd: float = 2.0,
    speed: dict[str, float] | None = None,
) -> dict[str, np.ndarray]:
    """Episode columns: every (VUT, seed) opponent against every VUT on ``n`` scenarios.

    Each opponent has its own strength (shared by all VUTs it meets: a block effect); a VUT
    is crashed into with probability ``crash_p`` and otherwise paid ``pay_mean`` + the
    opponent's strength + noise, clipped to [0, MAX_PAY]. A crashed episode paid a little
    before its collision (as real ones do).
    """
    vuts = list(crash_p)
    cols: dict[str, list] = {k: [] for k in ("vut", "ov", "os", "pay", "crash", "ret", "speed")}
    for ov in vuts:
        for s in seeds:
            strength = rng.normal(0.0, opp_sd)
            for v in vuts:
                crash = rng.random(n) < crash_p[v]
                pay = np.clip(pay_mean[v] + strength + rng.normal(0.0, 3.0, n), 0.0, MAX_PAY)
                pay = np.where(crash, rng.uniform(0.0, 3.0, n), pay)
                cols["vut"] += [v] * n
                cols["ov"] += [ov] * n
                cols["os"] += [s] * n
                cols["pay"] += pay.tolist()
                cols["crash"] += crash.tolist()
                cols["ret"] += np.where(crash, pay - ALPHA_C, pay).tolist()
                cols["speed"] += [(speed or {}).get(v, 20.0)] * n
    return {k: np.asarray(v) for k, v in cols.items()}


def rank(cols: dict[str, np.ndarray], score: str = "harm"):
    """Rows of the cross-play ranking by ``score``: "harm" (the product) or "reward" (the
    score before issue 22, the mean episode reward extracted)."""
    per_episode = (
        episode_harm(cols["pay"], cols["crash"], MAX_PAY) if score == "harm" else cols["ret"]
    )
    m = crossplay_matrix(
        cols["vut"],
        cols["ov"],
        cols["os"],
        per_episode,
        cols["crash"],
        episode_return=cols["ret"],
        mobility=cols["speed"],
    )
    rows, pairs = rank_crossplay(m)
    return m, rows, pairs


# --------------------------------------------------------------------------- the episode score


def test_episode_harm_on_hand_computed_episodes() -> None:
    harm = episode_harm([0.0, 12.5, 25.0, 3.0], [False, False, False, True], MAX_PAY)
    assert harm.tolist() == [0.0, 0.5, 1.0, 1.0]  # a crash = the worst there is
    scale = HarmScale(MAX_PAY, ALPHA_C)
    # a table without near_miss_pay: the return gives it back (a crash step pays -alpha_C)
    pay = scale.near_miss_pay([np.nan, np.nan, 4.0], [-7.0, 6.0, 99.0], [True, False, False])
    assert pay.tolist() == [3.0, 6.0, 4.0]
    with pytest.raises(ConfigError, match="exceeds the most an episode can pay"):
        episode_harm([26.0], [False], MAX_PAY)
    with pytest.raises(ConfigError, match="finite and >= 0"):
        episode_harm([-1.0], [False], MAX_PAY)
    with pytest.raises(ConfigError, match="max_episode_pay must be a finite number > 0"):
        HarmScale(0.0, ALPHA_C)


def test_a_crash_is_never_better_than_any_near_miss() -> None:
    """Monotone in harm: turning any episode into a collision never lowers the harm, and
    more pay without a collision is more harm."""
    rng = np.random.default_rng(0)
    pay = rng.uniform(0.0, MAX_PAY, 1000)
    calm = episode_harm(pay, np.zeros(1000, bool), MAX_PAY)
    crashed = episode_harm(pay, np.ones(1000, bool), MAX_PAY)
    assert np.all(crashed >= calm)
    order = np.argsort(pay)
    assert np.all(np.diff(calm[order]) >= 0)


# --------------------------------------------------------------------------- known answers


def test_more_crashes_under_equal_near_miss_pay_ranks_less_safe() -> None:
    """Three VUTs with the same near-miss pay, crashed into 5 / 12 / 20 % of the time: the
    harm ranks them by crashes, the ends differ significantly; the reward score, which pays
    the opponent -10 for a crash, ranks them exactly backwards."""
    rng = np.random.default_rng(1)
    crash = {"safe": 0.05, "mid": 0.12, "weak": 0.20}
    cols = table(rng, crash, {v: 8.0 for v in crash})
    _m, rows, pairs = rank(cols)
    assert [r.name for r in rows] == ["safe", "mid", "weak"]
    ends = next(p for p in pairs if {p.name_a, p.name_b} == {"safe", "weak"})
    assert ends.p < ends.alpha and ends.name_a == "safe"  # the declared ends: one test
    _m, old, _ = rank(cols, score="reward")
    assert [r.name for r in old] == ["weak", "mid", "safe"]  # the inversion of issue 22


def test_more_near_miss_pay_under_equal_crashes_ranks_less_safe() -> None:
    rng = np.random.default_rng(2)
    crash = {"far": 0.08, "close": 0.08, "closest": 0.08}
    cols = table(rng, crash, {"far": 5.0, "close": 8.0, "closest": 11.0})
    _m, rows, _pairs = rank(cols)
    assert [r.name for r in rows] == ["far", "close", "closest"]
    assert all(r.significant_vs_next for r in rows[:-1])


@pytest.mark.parametrize("crash_p", [0.0, 0.1, 0.3])
def test_false_positive_rate_is_at_most_nominal_with_no_difference(crash_p: float) -> None:
    """Two identical VUTs (same crash probability and pay), opponents of unequal strength:
    the paired test over seed blocks calls a difference in about alpha = 5 % of replicates
    (within 3 standard errors), at any crash rate."""
    rng = np.random.default_rng(int(crash_p * 100) + 5)
    n_rep, hits = 600, 0
    for _ in range(n_rep):
        cols = table(rng, {"a": crash_p, "b": crash_p}, {"a": 8.0, "b": 8.0}, n=20)
        per_episode = episode_harm(cols["pay"], cols["crash"], MAX_PAY)
        m = crossplay_matrix(cols["vut"], cols["ov"], cols["os"], per_episode, cols["crash"])
        a, b = m.scores("seed")
        hits += compare_seeds(a, b).significant
    rate, se = hits / n_rep, math.sqrt(0.05 * 0.95 / n_rep)
    assert rate <= 0.05 + 3 * se, rate


def test_a_vut_that_stands_still_is_flagged_timid() -> None:
    """Mobility stands beside the score: a VUT that brakes to a standstill gets little harm
    but is flagged when its mean speed is below 80 % of the median VUT's."""
    rng = np.random.default_rng(3)
    crash = {"a": 0.08, "b": 0.08, "statue": 0.0}
    cols = table(
        rng, crash, {"a": 8.0, "b": 8.5, "statue": 1.0}, speed={"a": 20, "b": 21, "statue": 3}
    )
    m, rows, _ = rank(cols)
    assert rows[0].name == "statue"  # safest by harm alone ...
    outcomes = vut_outcomes({v: (*m.crashes(v), m.vut_mobility(v)) for v in m.vuts})
    assert outcomes["statue"].timid and not outcomes["a"].timid and not outcomes["b"].timid
    three = {"a": 10.0, "b": 10.0}
    assert mobility_flags({**three, "c": 7.9})["c"]  # median 10: 7.9 < 0.8 x 10
    assert not mobility_flags({**three, "c": MOBILITY_FLOOR * 10.0})["c"]
    assert mobility_flags({"a": 10.0, "b": math.nan}) == {"a": False, "b": False}


def test_crash_rate_interval_stays_inside_0_and_1() -> None:
    out = vut_outcomes({"none": (0, 200, 20.0), "all": (200, 200, 20.0), "two": (1, 2, 20.0)})
    for o in out.values():
        assert 0.0 <= o.crash_lo <= o.crash_rate <= o.crash_hi <= 1.0
    assert out["none"].crash_hi > 0.0 and out["all"].crash_lo < 1.0
    stats = EpisodeStats.of([1.0, 0.5], [True, False], [20.0, np.nan])
    assert (stats.mean_harm, stats.crashes, stats.n) == (0.75, 1, 2)
    assert math.isnan(stats.mobility)  # one episode without mobility: not recorded


# --------------------------------------------------------------------------- the real ladder

BRAKING_CUT_IN = PROJECT_ROOT / "results" / "ladders" / "braking_a" / "cut_in" / "crossplay.csv"


@pytest.mark.skipif(not BRAKING_CUT_IN.is_file(), reason="braking ladder not committed")
def test_the_braking_ladder_in_cut_in_ranks_d9_d6_d45() -> None:
    """The committed cut-in cross-play table of the braking ladder (issue 22): harm ranks
    d9 > d6 > d45 (more braking authority is safer)."""
    from sumo_ayss.analysis.crossplay_scoring import score_crossplay
    from sumo_ayss.run_folder.crossplay import read_crossplay_table

    table = read_crossplay_table(Path(BRAKING_CUT_IN))
    m = score_crossplay(table.columns, HarmScale(MAX_PAY, ALPHA_C))
    rows, _pairs = rank_crossplay(m)
    assert [r.name for r in rows] == ["d9", "d6", "d45"]
    crashes = {v: m.crashes(v)[0] for v in m.vuts}
    assert crashes == {"d45": 356, "d6": 209, "d9": 102}  # 19.8 / 11.6 / 5.7 % of 1,800
    # the reward the opponents extracted (the score before issue 22) ranked d45 safest
    reward = dict(zip(m.vuts, m.returns.mean(axis=1).tolist(), strict=True))
    assert min(reward, key=reward.__getitem__) == "d45"
