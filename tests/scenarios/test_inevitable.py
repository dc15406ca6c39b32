"""Inevitable-collision states with real SUMO: where no braking helps, and where it does."""

from __future__ import annotations

from sumo_ayss.config import EnvConfig
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.scenarios.inevitable import ics_flags, ics_share


def test_car_following_ics_by_hand() -> None:
    # 30 m/s toward a 10 m/s POV 2 m ahead that brakes at 6 m/s²: the gap closes by about
    # 20 · 0.2 - ... = 3.8 m in the first 0.2 s step whatever the VUT does: inevitable.
    # 10 m/s behind a 10 m/s POV 25 m ahead: 0.85 g against 6 m/s² never closes the gap.
    flags = ics_flags(
        EnvConfig(case="car_following"),
        [InitialCondition(10.0, 30.0, 2.0), InitialCondition(10.0, 10.0, 25.0)],
    )
    assert flags == [True, False]


def test_cut_in_ics_and_a_rammed_vut_is_not_counted() -> None:
    cfg = EnvConfig(case="cut_in")
    flags = ics_flags(
        cfg,
        [
            # Beside (its rear 3 m behind the VUT's front), same speed, cuts in at once: its
            # side reaches the VUT's lane in about 0.44 s, when braking at 0.85 g has won
            # 0.8 m: still beside, contact.
            InitialCondition(20.0, 20.0, -3.0),
            InitialCondition(20.0, 20.0, 24.0),  # far ahead: braking avoids it
            InitialCondition(30.0, 10.0, -12.0),  # far behind and faster: a ram, not ICS
        ],
    )
    assert flags == [True, False, False]


def test_share_has_its_wilson_interval() -> None:
    s = ics_share(EnvConfig(case="car_following"), 40, 4242)
    assert s.n == 40 and 0 <= s.ics <= 40 and s.lo <= s.share <= s.hi
