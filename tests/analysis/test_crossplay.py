"""Cross-play ranking on synthetic matrices with a known answer (cell values stand for the
mean harm per episode; the harm itself is tested in test_harm.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sumo_ayss.analysis.crossplay import crossplay_matrix, rank_crossplay
from sumo_ayss.analysis.seeds import compare_seeds, kendall_tau
from sumo_ayss.modes.crossplay import crossplay_sentence
from sumo_ayss.util.errors import ConfigError

VUTS = ("v0", "v1", "v2", "v3")


def _table(returns: np.ndarray, seeds=(0, 1, 2), n_scen: int = 2):
    """Columns of a cross-play table whose cell means are ``returns[vut, opponent]``.

    Opponents are (VUT k, seed s) in the order k-major, like the matrix's sorted order.
    """
    vut, ov, os_, ret, col = [], [], [], [], []
    opps = [(v, s) for v in VUTS[: returns.shape[0]] for s in seeds]
    assert returns.shape[1] == len(opps), "one column per (VUT, seed) opponent"
    for i in range(returns.shape[0]):
        for j, (o, s) in enumerate(opps):
            for k in range(n_scen):  # +-0.5 around the cell mean
                vut.append(VUTS[i])
                ov.append(o)
                os_.append(s)
                ret.append(returns[i, j] + (0.5 if k % 2 else -0.5))
                col.append(k == 0 and i == 0)
    return vut, ov, os_, ret, col


def _null_or_ladder(rng, effects, seeds=3, opp_sd=1.5, seed_sd=1.0, seed_diff_sd=0.0, noise=0.3):
    """Matrix: VUT effect + opponent quality (shared by all VUTs) + seed effects + noise.

    ``seed_diff_sd`` adds a seed effect on the *differences* between VUTs (all opponents of
    one seed see the VUTs alike), which makes opponents of one seed correlated blocks.
    """
    k = len(effects)
    quality = rng.normal(0.0, opp_sd, (k, seeds))  # per opponent (trained vs VUT k, seed s)
    seed_eff = rng.normal(0.0, seed_sd, seeds)
    seed_vut = rng.normal(0.0, seed_diff_sd, (k, seeds))  # per (VUT faced, seed)
    m = np.empty((k, k * seeds))
    for i in range(k):
        for kk in range(k):
            for s in range(seeds):
                m[i, kk * seeds + s] = (
                    10.0
                    + effects[i]
                    + quality[kk, s]
                    + seed_eff[s]
                    + seed_vut[i, s]
                    + rng.normal(0.0, noise)
                )
    return m


def test_matrix_means_and_balance():
    m0 = np.array([[1.0, 2.0, 3.0, 4.0, 5.0, 6.0], [2.0, 3.0, 4.0, 5.0, 6.0, 7.0]])
    m = crossplay_matrix(*_table(m0))
    assert m.vuts == ("v0", "v1")
    assert m.opponents == (("v0", 0), ("v0", 1), ("v0", 2), ("v1", 0), ("v1", 1), ("v1", 2))
    np.testing.assert_allclose(m.harm, m0)
    assert np.isnan(m.returns).all() and np.isnan(m.mobility).all()  # not given
    assert m.n_scenarios == 2
    assert m.crash_rate[0, 0] == 0.5 and m.crash_rate[1].sum() == 0.0
    vut, ov, os_, ret, col = _table(m0)
    with pytest.raises(ConfigError, match="same number of scenarios"):
        crossplay_matrix(vut[:-1], ov[:-1], os_[:-1], ret[:-1], col[:-1])
    with pytest.raises(ConfigError, match="lengths differ"):
        crossplay_matrix(vut, ov, os_, ret[:-1], col)
    ret[3] = math.nan
    with pytest.raises(ConfigError, match="harm has non-finite"):
        crossplay_matrix(vut, ov, os_, ret, col)


def test_seed_blocks_average_each_seeds_opponents():
    m0 = np.array([[1.0, 2.0, 3.0, 4.0, 5.0, 6.0], [2.0, 3.0, 4.0, 5.0, 6.0, 9.0]])
    m = crossplay_matrix(*_table(m0))
    by_seed = m.scores("seed")
    assert by_seed[1].values == {0: 3.5, 1: 4.5, 2: 6.5}  # (2 + 5) / 2, (3 + 6) / 2, (4 + 9) / 2
    by_opp = m.scores("opponent")
    assert by_opp[0].values == dict(enumerate(m0[0].tolist()))
    with pytest.raises(ConfigError, match="blocks must be one of seed, opponent"):
        m.scores("vut")


def test_known_ladder_is_recovered():
    """Exposure 0 / 0.7 / 1.4 / 2.1 above the safest, opponent quality spread 1.5: tau = 1
    and both ends significant in nearly every replicate, whatever the opponents' quality."""
    rng = np.random.default_rng(3)
    truth = list(VUTS)  # v0 safest (lowest exposure)
    n_rep, exact, ends, chains = 200, 0, 0, 0
    for _ in range(n_rep):
        m = crossplay_matrix(*_table(_null_or_ladder(rng, [0.0, 0.7, 1.4, 2.1])))
        rows, pairs = rank_crossplay(m)
        exact += kendall_tau([r.name for r in rows], truth) == 1.0
        end = next(p for p in pairs if {p.name_a, p.name_b} == {"v0", "v3"})
        ends += end.p < end.alpha and end.name_a == "v0"  # the declared ends: one test
        chains += end.significant and end.name_a == "v0"  # every adjacent claim (Holm)
    assert exact / n_rep > 0.95
    assert ends / n_rep > 0.95
    # The family's price with 3 seed blocks (2 df) and steps of 0.7: the ranking claims
    # every adjacent step in 81 of 200 replicates (raw tests: more), never more than the ends.
    assert 0.3 * ends <= chains <= ends


@pytest.mark.parametrize("seeds", [3, 4])  # the paper budget's and the verdict budget's
@pytest.mark.parametrize("blocks", ["seed", "opponent"])
def test_false_positive_rate_is_at_most_nominal(blocks, seeds):
    """No true difference, independent opponents: both block units call a difference in at
    most 5 % of replicates (plus Monte Carlo error); the tests are exact here."""
    rng = np.random.default_rng(5)
    n_rep, hits = 2000, 0
    for _ in range(n_rep):
        null = _null_or_ladder(rng, [0.0, 0.0], seeds=seeds, seed_sd=1.0)
        m = crossplay_matrix(*_table(null, range(seeds)))
        a, b = m.scores(blocks)
        hits += compare_seeds(a, b).significant
    rate, se = hits / n_rep, math.sqrt(0.05 * 0.95 / n_rep)
    assert rate <= 0.05 + 3 * se, rate
    assert rate >= 0.05 - 3 * se, rate


@pytest.mark.parametrize("seeds", [3, 4])
def test_seed_blocks_hold_when_a_seeds_opponents_are_correlated(seeds):
    """When a seed moves the VUT difference for all its opponents alike, opponents are not
    independent: per-opponent blocks then call far more than 5 % of nulls, seed blocks do
    not. This is why seeds are the default block."""
    rng = np.random.default_rng(9)
    n_rep = 2000
    hits = {"seed": 0, "opponent": 0}
    for _ in range(n_rep):
        m = crossplay_matrix(
            *_table(
                _null_or_ladder(rng, [0.0, 0.0], seeds=seeds, seed_diff_sd=0.5, noise=0.1),
                range(seeds),
            )
        )
        for blocks in hits:
            a, b = m.scores(blocks)
            hits[blocks] += compare_seeds(a, b).significant
    se = math.sqrt(0.05 * 0.95 / n_rep)
    assert hits["seed"] / n_rep <= 0.05 + 3 * se, hits
    assert hits["opponent"] / n_rep > 0.15, hits


def test_identical_deterministic_vuts_are_never_called_different():
    m0 = np.tile(np.array([[5.0, 6.0, 7.0, 8.0, 9.0, 4.0]]), (2, 1))
    m = crossplay_matrix(*_table(m0))
    _rows, pairs = rank_crossplay(m)
    assert math.isnan(pairs[0].p) and not pairs[0].significant


def test_sentence_names_mode_amount_and_blocks():
    rng = np.random.default_rng(1)
    m = crossplay_matrix(*_table(_null_or_ladder(rng, [0.0, 3.0], noise=0.05)))
    rows, _ = rank_crossplay(m)
    text = crossplay_sentence(rows[0].vs_next)
    assert text.startswith("[crossplay mode] v0 is safer than v1: the pooled SPCPs bring about ")
    assert "more harm per episode against v1 than against v0" in text
    assert "paired t-test over 3 training seeds" in text
    text = crossplay_sentence(rank_crossplay(m, blocks="opponent")[0][0].vs_next, "opponent")
    assert "paired t-test over 6 opponent SPCPs" in text
