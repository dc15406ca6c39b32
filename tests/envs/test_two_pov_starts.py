"""The two-POV case's ODD without inevitable starts (``env.odd.exclude_inevitable``,
issue 39): the pure check against SUMO's, the sampling that uses it, and that the paper's
cases and the stored configurations do not move."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from sumo_ayss.analysis.safety_measures import EpisodeMeasures
from sumo_ayss.config import EnvConfig, ExperimentConfig, OddConfig
from sumo_ayss.config.identity import run_identity
from sumo_ayss.config.mapping import to_dict
from sumo_ayss.envs import make_env
from sumo_ayss.envs.odd import sample_initial_conditions, scenario_set, start_filter
from sumo_ayss.envs.two_pov import (
    PRIMARY_CUT_IN,
    PRIMARY_LEAD,
    TwoPovStart,
    inevitable_start,
    two_pov_start,
)
from sumo_ayss.scenarios.inevitable import ics_flags
from sumo_ayss.scenarios.outcome import supporting_pov_summary
from sumo_ayss.scenarios.rollout import EpisodeResult
from sumo_ayss.util.errors import ConfigError

CASE = "lead_and_cut_in"
SAFE = EnvConfig(case=CASE, odd=OddConfig(exclude_inevitable=True))


def swapped(s: TwoPovStart) -> TwoPovStart:
    """The same vehicles with the roles of the two POVs exchanged."""
    return TwoPovStart(
        s.support_speed_mps,
        s.vut_speed_mps,
        s.support_gap_m,
        support_speed_mps=s.pov_speed_mps,
        support_gap_m=s.gap_m,
        primary=PRIMARY_LEAD if s.primary == PRIMARY_CUT_IN else PRIMARY_CUT_IN,
    )


def test_the_check_flags_the_obvious_starts() -> None:
    """A lead 3 m ahead closing at 5 m/s cannot be escaped, neither as primary nor as the
    supporting POV; both POVs 40 m ahead at equal speeds can."""
    cfg = EnvConfig(case=CASE)
    far = dict(support_speed_mps=20.0, support_gap_m=40.0)
    assert inevitable_start(TwoPovStart(20.0, 25.0, 3.0, primary=PRIMARY_LEAD, **far), cfg)  # type: ignore[arg-type]
    near_support = TwoPovStart(
        20.0, 25.0, 40.0, support_speed_mps=20.0, support_gap_m=3.0, primary=PRIMARY_CUT_IN
    )
    assert inevitable_start(near_support, cfg)
    assert not inevitable_start(TwoPovStart(20.0, 20.0, 40.0, primary=PRIMARY_LEAD, **far), cfg)  # type: ignore[arg-type]


@pytest.mark.sumo
def test_the_pure_check_finds_every_inevitable_start_sumo_finds() -> None:
    """Against the SUMO check (:func:`ics_flags`: a VUT braking at 0.85 g under the case's
    own worst plays, the primary's contact only), for each POV as the primary: on 200 ODD
    draws none is missed, and the pure check is at most a little stricter."""
    cfg = EnvConfig(case=CASE)
    starts = [two_pov_start(ic, cfg.odd) for ic in sample_initial_conditions(cfg.odd, 200, 4242)]
    sumo = np.array(ics_flags(cfg, starts)) | np.array(ics_flags(cfg, map(swapped, starts)))
    pure = np.array([inevitable_start(s, cfg) for s in starts])
    assert sumo.sum() >= 25  # the committed ladder's set: 25 with the primary alone
    assert not (sumo & ~pure).any(), "an inevitable start the pure check misses"
    assert (pure & ~sumo).sum() <= 0.05 * len(starts)


@pytest.mark.sumo
def test_a_safe_scenario_set_holds_no_inevitable_start() -> None:
    """``exclude_inevitable``: the scenario set SUMO's check finds no ICS in, for either POV."""
    starts = [two_pov_start(ic, SAFE.odd) for ic in scenario_set(SAFE, 60, 4242)]
    assert not any(ics_flags(SAFE, starts)) and not any(ics_flags(SAFE, map(swapped, starts)))
    assert len({s.as_tuple() for s in starts}) == 60


@pytest.mark.sumo
def test_the_env_draws_its_training_starts_from_the_safe_odd() -> None:
    env = make_env(SAFE, sumo_seed=3)
    try:
        check = start_filter(SAFE)
        assert check is not None
        for seed in range(25):
            _, info = env.reset(seed=seed)
            assert check(info["initial_condition"])
    finally:
        env.close()


def test_without_the_option_nothing_moves() -> None:
    """The draws, the stored configuration and a run's identity are those from before the
    option, in every case, unless it is set."""
    for case in ("car_following", "cut_in", CASE):
        cfg = EnvConfig(case=case)
        assert start_filter(cfg) is None
        assert scenario_set(cfg, 50, 7) == sample_initial_conditions(cfg.odd, 50, 7)
        assert "exclude_inevitable" not in to_dict(cfg)["odd"]
        assert "exclude_inevitable" not in repr(cfg)
        ident = run_identity(ExperimentConfig(env=cfg), 0)
        assert not any("exclude_inevitable" in k for k in ident)
    assert to_dict(SAFE)["odd"]["exclude_inevitable"] is True
    assert run_identity(ExperimentConfig(env=SAFE), 0)["env.odd.exclude_inevitable"] is True
    plain = scenario_set(EnvConfig(case=CASE), 200, 4242)
    assert scenario_set(SAFE, 200, 4242) != plain


def test_the_option_is_refused_where_a_case_has_no_check() -> None:
    for case in ("car_following", "cut_in"):
        with pytest.raises(ConfigError, match="exclude_inevitable"):
            EnvConfig(case=case, odd=OddConfig(exclude_inevitable=True))
    with pytest.raises(ConfigError, match="true or false"):
        OddConfig(exclude_inevitable="yes")  # type: ignore[arg-type]


def test_the_outcome_counts_forbidden_contacts_by_kind() -> None:
    """``outcome.json``'s ``supporting_pov``: the failure share and its two kinds."""
    measures = EpisodeMeasures(*([1.0] * len(dataclasses.fields(EpisodeMeasures))))
    base = EpisodeResult(0.0, False, 10.0, 25, False, support_measures=measures)
    episodes = [
        dataclasses.replace(base, pov_failure=True, support_vut_contact=True),
        dataclasses.replace(base, pov_failure=True, pov_pov_contact=True),
        base,
        base,
    ]
    summary = supporting_pov_summary(episodes)
    assert summary is not None
    assert summary["pov_failure_rate"] == 0.5
    assert summary["support_vut_rate"] == 0.25 and summary["pov_pov_rate"] == 0.25
