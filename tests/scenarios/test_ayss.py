"""Monte Carlo AYSS: filters, indicators, reproducibility; cut-in runs in real SUMO."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np
import numpy.typing as npt
import pytest

from sumo_ayss.config import ActuatorConfig, AyssConfig
from sumo_ayss.envs.car_following import CarFollowingEnv
from sumo_ayss.envs.cut_in import FIRST_SPEED_ACTION, LANE_CHANGE, CutInEnv
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.records.table import read_table, write_table
from sumo_ayss.run_folder import AYSS_SCHEMA
from sumo_ayss.scenarios.ayss import (
    car_following_indicator,
    cut_in_mask,
    run_ayss,
    safety_critical_mask,
    sample_observations,
    ttc_s,
)
from sumo_ayss.sim.actuator import pov_acceleration
from sumo_ayss.util.errors import ActionError, ConfigError

# --------------------------------------------------------------------------- hand cases

#: (v_pov, v_vut, h, action) -> TTC, kept by h/TTC, kept by the cut-in rules.
#: TTC = h / (v_vut - v_pov) when closing; +inf when not; 0 when h <= 0.
HAND = [
    # v_pov  v_vut    h   act   ttc     h&ttc  cut-in(act 0 & h > 0)
    (20.0, 10.0, 3.0, 0, np.inf, True, True),  # opening: TTC inf
    (10.0, 20.0, 3.0, 0, 0.3, True, True),  # 3 / 10
    (10.0, 30.0, 3.0, 0, 0.15, False, True),  # 3 / 20 < 0.2: unavoidable
    (10.0, 25.0, 3.0, 5, 0.2, True, False),  # 3 / 15 = 0.2 kept; but a speed action
    (20.0, 20.0, 5.0, 0, np.inf, True, True),  # h = 5 m kept (<=)
    (20.0, 20.0, 5.01, 0, np.inf, False, True),  # h > 5 m: not critical in one step
    (20.0, 20.0, 0.0, 0, 0.0, False, False),  # touching: TTC 0, and not ahead
    (20.0, 30.0, -1.0, 0, 0.0, False, False),  # overlapping
]


def _hand() -> tuple[npt.NDArray[np.float64], ...]:
    cols = list(zip(*HAND, strict=True))
    return tuple(np.array(c) for c in cols)


def test_filters_on_hand_cases() -> None:
    v_pov, v_vut, h, actions, ttc_expected, critical, cut_in = _hand()
    ttc = ttc_s(v_pov, v_vut, h)
    assert ttc == pytest.approx(ttc_expected.astype(float))
    assert safety_critical_mask(h, ttc).tolist() == critical.astype(bool).tolist()
    assert cut_in_mask(h, actions).tolist() == cut_in.astype(bool).tolist()
    both = safety_critical_mask(h, ttc) & cut_in_mask(h, actions)
    assert np.flatnonzero(both).tolist() == [0, 1, 4]
    # Thresholds are parameters: a 0.1 s TTC floor keeps the 0.15 s case.
    assert safety_critical_mask(h, ttc, 5.0, 0.1)[2]


#: (v_pov [m/s], action k) -> (target 0.5·k·v_pov [m/s], acceleration [m/s²]) with the
#: default actuator a = clip((target - v) / 0.6 s, -6, 6).
ACCEL_CASES = [
    (20.0, 0, 0.0, -6.0),  # stop request: (0 - 20) / 0.6 = -33.3, clipped to -6
    (20.0, 2, 20.0, 0.0),  # hold
    (20.0, 1, 10.0, -6.0),  # (10 - 20) / 0.6 = -16.7, clipped
    (2.0, 1, 1.0, -1.0 / 0.6),  # (1 - 2) / 0.6 = -1.667, inside the bounds
    (3.0, 3, 4.5, 2.5),  # (4.5 - 3) / 0.6 = 2.5
    (20.0, 3, 30.0, 6.0),  # (30 - 20) / 0.6 = 16.7, clipped to +6
    (0.0, 0, 0.0, 0.0),  # standing still stays
]


def test_car_following_indicator_is_the_actuator_acceleration() -> None:
    v, k, target, accel = (np.array(c) for c in zip(*ACCEL_CASES, strict=True))
    got_target, got_accel = car_following_indicator(v, k, ActuatorConfig())
    assert got_target == pytest.approx(target)
    assert got_accel == pytest.approx(accel)
    # Another actuator (gain, bounds) changes the indicator the same way as the env's.
    soft = ActuatorConfig(time_constant_s=2.0, accel_min_mps2=-3.0)
    assert car_following_indicator([20.0], [1], soft)[1][0] == -3.0  # (10 - 20) / 2 = -5
    assert car_following_indicator([20.0], [0], soft)[1][0] == pov_acceleration(20.0, 0.0, soft)


@pytest.mark.sumo
def test_car_following_indicator_matches_the_env_step(cf_env: CarFollowingEnv) -> None:
    for v_pov, k, _, accel in ACCEL_CASES:
        cf_env.reset(options={"initial_condition": InitialCondition(v_pov, v_pov, 20.0)})
        *_, info = cf_env.step(k)
        assert info["pov_accel_mps2"] == pytest.approx(accel, abs=1e-12)
        assert car_following_indicator([v_pov], [k], cf_env.config.actuator)[1][0] == pytest.approx(
            info["pov_accel_mps2"], abs=1e-12
        )


def test_config_is_validated() -> None:
    with pytest.raises(ConfigError, match=r"ayss\.n_samples"):
        AyssConfig(n_samples=0)
    with pytest.raises(ConfigError, match=r"ayss\.v_pov_mps"):
        AyssConfig(v_pov_mps=(-1.0, 30.0))
    with pytest.raises(ConfigError, match=r"ayss\.h_m"):
        AyssConfig(h_m=(5.0, 0.0))
    with pytest.raises(ConfigError, match=r"ayss\.min_ttc_s"):
        AyssConfig(min_ttc_s=-0.1)
    cfg = AyssConfig.from_odd(CarFollowingEnv().config.odd, n_samples=10)
    assert cfg.v_pov_mps == (10.0, 30.0) and cfg.n_samples == 10


def test_samples_are_float32_in_the_box() -> None:
    cfg = AyssConfig(n_samples=5000, v_pov_mps=(5.0, 6.0), h_m=(-1.0, 2.0), seed=3)
    obs = sample_observations(cfg, "car_following")
    assert obs.shape == (5000, 3) and obs.dtype == np.float32
    assert obs[:, 0].min() >= 5.0 and obs[:, 0].max() <= 6.0
    assert obs[:, 2].min() < 0.0 < obs[:, 2].max() <= 2.0
    cut = sample_observations(cfg, "cut_in")
    assert cut.shape == (5000, 4) and (cut[:, 3] == 0.0).all()  # POV in the left lane
    assert np.array_equal(cut[:, :3], obs)


# --------------------------------------------------------------------------- car-following


def by_headway(obs: npt.NDArray[np.float32]) -> npt.NDArray[np.int64]:
    """A scripted policy that depends on the observation: k = round(4·h), in 0..20."""
    return np.clip(np.round(4.0 * obs[:, 2]), 0, 20).astype(np.int64)


@pytest.fixture
def cf_config_env() -> Iterator[CarFollowingEnv]:
    """A car-following env: AYSS only reads its config, SUMO never starts."""
    env = CarFollowingEnv()
    try:
        yield env
    finally:
        env.close()


def test_car_following_monte_carlo_is_reproducible(
    cf_config_env: CarFollowingEnv, tmp_path: Path
) -> None:
    cfg = AyssConfig(n_samples=4000, h_m=(-2.0, 8.0), seed=1, batch_size=1000)
    first = run_ayss(cf_config_env, by_headway, cfg)
    second = run_ayss(cf_config_env, by_headway, cfg)
    write_table(tmp_path / "a.csv", first.table)
    write_table(tmp_path / "b.csv", second.table)
    assert (tmp_path / "a.csv").read_bytes() == (tmp_path / "b.csv").read_bytes()
    other = run_ayss(cf_config_env, by_headway, AyssConfig(n_samples=4000, h_m=(-2.0, 8.0)))
    assert not other.table.equals(first.table)

    table = read_table(tmp_path / "a.csv", AYSS_SCHEMA)  # passes the schema check
    assert table.equals(first.table)
    c = first.counts
    assert c["n_samples"] == 4000 > c["n_headway"] > c["n_safety_critical"] == c["n_kept"]
    assert c["n_kept"] == len(table) == sum(c["action_counts"].values())
    h, ttc = table["h_m"], table["ttc_s"]
    assert ((h > 0) & (h <= 5.0) & (ttc >= 0.2)).all()
    assert (table["same_lane"] == 1).all() and set(table["indicator_name"]) == {"pov_accel_mps2"}
    assert np.array_equal(table["action"], by_headway(np.stack([h, h, h], axis=1)))
    expected = [
        pov_acceleration(v, 0.5 * k * v, cf_config_env.config.actuator)
        for v, k in zip(table["v_pov_mps"], table["action"], strict=True)
    ]
    assert table["indicator"].tolist() == expected
    assert np.isnan(table["h_after_m"]).all()
    assert first.summary()["counts"]["n_kept"] == len(table)


def test_bad_policy_outputs_are_refused(cf_config_env: CarFollowingEnv) -> None:
    cfg = AyssConfig(n_samples=100)
    with pytest.raises(ActionError, match="outside"):
        run_ayss(cf_config_env, lambda o: np.full(len(o), 21), cfg)
    with pytest.raises(ActionError, match="shape"):
        run_ayss(cf_config_env, lambda o: np.zeros((len(o), 1), dtype=int), cfg)
    with pytest.raises(ActionError, match="integers"):
        run_ayss(cf_config_env, lambda o: np.zeros(len(o)), cfg)  # type: ignore[arg-type,return-value]


# --------------------------------------------------------------------------- cut-in (SUMO)


@pytest.fixture
def ci_env() -> Iterator[CutInEnv]:
    env = CutInEnv(sumo_seed=7)
    try:
        yield env
    finally:
        env.close()


def always_lane_change(obs: npt.NDArray[np.float32]) -> npt.NDArray[np.int64]:
    return np.full(len(obs), LANE_CHANGE, dtype=np.int64)


@pytest.mark.sumo
def test_cut_in_always_lane_change(ci_env: CutInEnv) -> None:
    cfg = AyssConfig(n_samples=1500, h_m=(-1.0, 6.0), seed=2)
    result = run_ayss(ci_env, always_lane_change, cfg)
    t = result.table
    assert result.indicator_name == "delta_v_bar_mps" and len(t) > 500
    h, ttc = t["h_m"], t["ttc_s"]
    assert ((h > 0) & (h <= 5.0) & (ttc >= 0.2)).all()  # every kept row
    assert (t["same_lane"] == 0).all() and (t["action"] == LANE_CHANGE).all()
    assert np.array_equal(t["target_speed_mps"], t["v_pov_mps"])  # the POV keeps its speed
    closing = t["v_pov_mps"] < t["v_vut_mps"]
    assert closing.sum() > 100
    assert (t["indicator"][closing] < 0).all()  # closing in: Δv̄ < 0
    assert (t["h_after_m"][closing] < h[closing]).all()
    # The lateral motion makes Δv̄ more negative than the purely longitudinal start value
    # for most closing states (the geometry changes within the step too).
    assert np.mean(t["indicator"][closing] < t["delta_v_bar_before_mps"][closing]) > 0.5
    c = result.counts
    assert c["n_headway"] < c["n_samples"]  # the h box is sampled, then filtered
    # h <= 0 has TTC 0, so the TTC floor already drops what the "POV ahead" rule would.
    assert c["n_lane_change"] == c["n_safety_critical"] == c["n_kept"] == len(t)
    assert result.sim_wall_s > 0

    again = run_ayss(ci_env, always_lane_change, cfg)
    assert again.table.equals(t)  # SUMO is deterministic: same seed, same table


@pytest.mark.sumo
def test_cut_in_keeps_only_lane_changes(ci_env: CutInEnv) -> None:
    def near_only(obs: npt.NDArray[np.float32]) -> npt.NDArray[np.int64]:
        speed_20 = FIRST_SPEED_ACTION + 20
        return np.where(obs[:, 2] < 2.5, LANE_CHANGE, speed_20).astype(np.int64)

    result = run_ayss(ci_env, near_only, AyssConfig(n_samples=600, seed=4))
    assert len(result.table) == result.counts["n_lane_change"] > 0
    assert (result.table["h_m"] < 2.5).all()
    assert result.counts["action_counts"][str(FIRST_SPEED_ACTION + 20)] > 0
