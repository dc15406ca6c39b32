"""VUTs against the careful human, on synthetic tables with a known answer."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sumo_ayss.analysis.crossplay import crossplay_matrix
from sumo_ayss.analysis.reference import holm_adjust, read_against_reference
from sumo_ayss.util.errors import ConfigError

SEEDS = (0, 1, 2, 3)
N = 50  # scenarios per cell


def _episodes(rng, base_crash, vuts, ref_name="cc_driver"):
    """Episodes of every VUT (and the reference) against opponents (pi, seed), the same
    scenario set: a scenario crashes the reference iff ``base_crash``; each VUT says what it
    does there (its own crash flags, its labels)."""
    cols = {k: [] for k in ("vut", "ov", "os", "harm", "crash", "label")}
    opponents = [("pi", s) for s in SEEDS]
    for name, behaviour in {**vuts, ref_name: None}.items():
        for ov, os_ in opponents:
            for j in range(N):
                ref_crash = bool(base_crash[os_, j])
                if behaviour is None:
                    crash, label = ref_crash, 0.0 if ref_crash else math.nan
                else:
                    crash, label = behaviour(os_, j, ref_crash)
                near = 0.3 + 0.05 * rng.standard_normal()
                cols["vut"].append(name)
                cols["ov"].append(ov)
                cols["os"].append(os_)
                cols["harm"].append(1.0 if crash else float(np.clip(near, 0, 0.99)))
                cols["crash"].append(crash)
                cols["label"].append(label)
    return cols


def _split(cols, ref_name="cc_driver"):
    keep = np.array([v != ref_name for v in cols["vut"]])

    def sub(mask):
        return crossplay_matrix(
            [v for v, k in zip(cols["vut"], mask, strict=True) if k],
            [o for o, k in zip(cols["ov"], mask, strict=True) if k],
            [s for s, k in zip(cols["os"], mask, strict=True) if k],
            np.asarray(cols["harm"])[mask],
            np.asarray(cols["crash"])[mask],
            preventable=np.asarray(cols["label"])[mask],
        )

    return sub(keep), sub(~keep)


def test_the_three_places_where_the_reading_could_invert() -> None:
    rng = np.random.default_rng(5)
    base = rng.random((len(SEEDS), N)) < 0.1  # 10 % of scenarios crash the careful human

    def only_where_the_reference_crashes(s, j, ref_crash):
        return ref_crash, (0.0 if ref_crash else math.nan)

    def also_where_it_does_not(s, j, ref_crash):
        extra = j % 5 == 0  # a fifth of the scenarios besides
        crash = ref_crash or extra
        return crash, (0.0 if ref_crash else (1.0 if crash else math.nan))

    cols = _episodes(
        rng,
        base,
        {"shared": only_where_the_reference_crashes, "careless": also_where_it_does_not},
    )
    # An exact copy of the reference: same flags, same harm per episode.
    ref_rows = [i for i, v in enumerate(cols["vut"]) if v == "cc_driver"]
    for k in ("vut", "ov", "os", "harm", "crash", "label"):
        cols[k] += ["twin" if k == "vut" else cols[k][i] for i in ref_rows]
    m, ref = _split(cols)
    reading = read_against_reference(m, ref, "cc_driver")
    rows = {r.vut: r for r in reading.rows}
    assert rows["twin"].preventable == 0 and rows["twin"].crashes == reading.crashes
    assert rows["twin"].verdict == "not distinguishable"
    assert rows["shared"].preventable == 0 and rows["shared"].labelled == rows["shared"].crashes
    assert rows["shared"].verdict != "less safe"
    assert rows["careless"].preventable > 0
    assert rows["careless"].verdict == "less safe"
    assert rows["careless"].preventable_lo > 0.0 and rows["careless"].preventable_hi < 1.0
    # The reference's own crash rate is the scenario set's share no careful human survived.
    assert reading.crash_rate == pytest.approx(base.mean())


def test_holm_adjusted_verdicts_keep_the_family_wise_error_at_alpha() -> None:
    """Under the null (every VUT distributed as the reference, blocks independent),
    "safer" or "less safe" for any of K VUTs happens in <= 5 % of studies."""
    rng = np.random.default_rng(11)
    for k in (3, 6, 12):
        false = 0
        sims = 400
        for _ in range(sims):
            cols = {c: [] for c in ("vut", "ov", "os", "harm", "crash")}
            for name in [*(f"v{i}" for i in range(k)), "cc_driver"]:
                for s in SEEDS:
                    cols["vut"].append(name)
                    cols["ov"].append("pi")
                    cols["os"].append(s)
                    cols["harm"].append(float(np.clip(0.4 + 0.05 * rng.standard_normal(), 0, 1)))
                    cols["crash"].append(False)
            keep = np.array([v != "cc_driver" for v in cols["vut"]])
            mats = [
                crossplay_matrix(
                    list(np.asarray(cols["vut"])[mask]),
                    list(np.asarray(cols["ov"])[mask]),
                    list(np.asarray(cols["os"])[mask]),
                    np.asarray(cols["harm"])[mask],
                    np.asarray(cols["crash"])[mask],
                )
                for mask in (keep, ~keep)
            ]
            reading = read_against_reference(mats[0], mats[1], "cc_driver")
            false += any(r.verdict in ("safer", "less safe") for r in reading.rows)
        # Holm is conservative under positive dependence (shared reference): a binomial
        # bound on 400 studies at a true 5 % is about 7.2 % (one-sided 99 %).
        assert false / sims <= 0.072, (k, false / sims)


def test_holm_adjust_by_hand() -> None:
    # p = (0.01, 0.04, 0.03): sorted 0.01, 0.03, 0.04 -> 0.03, 0.06, 0.06.
    assert holm_adjust([0.01, 0.04, 0.03]) == pytest.approx([0.03, 0.06, 0.06])
    out = holm_adjust([math.nan, 0.2])
    assert math.isnan(out[0]) and out[1] == pytest.approx(0.2)


def test_reference_rows_of_another_pool_are_refused() -> None:
    m = crossplay_matrix(["a"] * 2, ["pi"] * 2, [0, 1], [0.1, 0.2], [False, False])
    ref = crossplay_matrix(["cc_driver"] * 2, ["pi"] * 2, [0, 2], [0.1, 0.2], [False, False])
    with pytest.raises(ConfigError, match="other opponents"):
        read_against_reference(m, ref, "cc_driver")
    with pytest.raises(ConfigError, match="no 'fsm'"):
        read_against_reference(m, ref, "fsm")


def test_the_difference_interval_stays_possible_and_needs_three_blocks() -> None:
    """A harm difference lies in [-1, 1]; with 2 blocks no interval is given at all."""
    rng = np.random.default_rng(3)
    for seeds in ((0, 1), (0, 1, 2)):
        n = len(seeds)
        harm_v = np.clip(0.5 + 0.45 * rng.standard_normal(n), 0, 1)
        harm_r = np.clip(0.5 + 0.45 * rng.standard_normal(n), 0, 1)
        m = crossplay_matrix(["a"] * n, ["pi"] * n, list(seeds), harm_v, [False] * n)
        ref = crossplay_matrix(["cc_driver"] * n, ["pi"] * n, list(seeds), harm_r, [False] * n)
        t = read_against_reference(m, ref, "cc_driver").rows[0].test
        if n < 3:
            assert math.isnan(t.lo) and math.isnan(t.hi)
        else:
            assert -1.0 <= t.lo <= t.difference <= t.hi <= 1.0
