"""One number formatter for sentences and tables: hand-checked tiny cases."""

from __future__ import annotations

import math

from sumo_ayss.modes.formatting import (
    fmt_interval,
    fmt_num,
    fmt_p,
    fmt_prob,
    rank_labels,
    ranking_line,
    seed_interval_text,
)


def test_fmt_num() -> None:
    assert fmt_num(1.234) == "1.23"
    assert fmt_num(-1.235, 1) == "−1.2"
    assert fmt_num(-1.234, minus="-") == "-1.23"
    assert fmt_num(math.nan) == "—"
    assert fmt_num(None) == "—"
    assert fmt_num(math.inf, missing="n/a") == "n/a"


def test_fmt_interval() -> None:
    assert fmt_interval(0.8, 1.6) == "0.80–1.60"
    assert fmt_interval(-0.3, 0.4) == "−0.30 to 0.40"
    assert fmt_interval(-0.3, 0.4, minus="-") == "-0.30 to 0.40"
    assert fmt_interval(math.nan, 1.0) == ""
    assert fmt_interval(None, 1.0, missing="interval undefined") == "interval undefined"


def test_fmt_p_and_prob() -> None:
    assert fmt_p(0.0123) == "= 0.012"
    assert fmt_p(0.0004) == "< 0.001"
    assert fmt_p(0.9995) == "= 1.000"
    assert fmt_p(0.9995, cap_high=True) == "> 0.999"
    assert fmt_p(math.nan) == "n/a"
    assert fmt_p(math.nan, undefined="undefined") == "undefined"
    assert fmt_prob(0.953) == "0.953"
    assert fmt_prob(0.0001) == "< 0.001"
    assert fmt_prob(0.9999) == "> 0.999"
    assert fmt_prob(math.nan) == "—"


def test_seed_interval_text_says_why_there_is_none() -> None:
    assert seed_interval_text(math.nan, math.nan, 2) == "2 seeds: no interval"
    assert seed_interval_text(math.nan, math.nan, 1) == "1 seed: no interval"
    assert seed_interval_text(0.0, 1.0, 3) == "0.00–1.00"
    assert seed_interval_text(0.1234, 0.5, 3, 3) == "0.123–0.500"


def test_ties_read_the_same_in_every_mode() -> None:
    # The ranking's order inside a tie too: the first VUT named is the leaderboard's first.
    assert ranking_line(["pi2", "pi1"], [False]) == "pi2 ≈ pi1"
    assert ranking_line(["c", "b", "a"], [True, False]) == "c > b ≈ a"
    assert ranking_line(["c", "b", "a"], [False, True]) == "c ≈ b > a"
    assert rank_labels([False, True]) == ["1–2", "1–2", "3"]
    assert rank_labels([True, False, False]) == ["1", "2–4", "2–4", "2–4"]
    assert rank_labels([]) == ["1"]
    assert ranking_line(["a"], []) == "a" and ranking_line([], []) == ""
