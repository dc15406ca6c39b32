"""The two-POV case's pure parts: its joint action, its start, its inevitable-start check,
its contact kinds (:mod:`sumo_ayss.envs.lead_and_cut_in`; docs/cases.md). No SUMO."""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from sumo_ayss.config import EnvConfig, OddConfig
from sumo_ayss.envs.odd import InitialCondition, StartFilter
from sumo_ayss.laws import braking_contact
from sumo_ayss.util.errors import ActionError
from sumo_ayss.vuts.reference import FullBraking

__all__ = [
    "CUT_LANE",
    "CUT_LANE_CHANGE",
    "N_ACTIONS",
    "N_CUT",
    "N_LEAD",
    "PRIMARY_CUT_IN",
    "PRIMARY_LEAD",
    "SPEED_OFFSETS_MPS",
    "UNPREVENTABLE_PENALTY",
    "VUT_LANE",
    "Contact",
    "TwoPovStart",
    "decode_action",
    "encode_action",
    "inevitable_start",
    "start_filter",
    "two_pov_start",
]

#: Speed offsets [m/s] of a POV's speed actions: target = own speed + offset.
SPEED_OFFSETS_MPS: tuple[float, ...] = (-5.0, -3.0, -1.5, 0.0, 1.5, 3.0)
#: The lead POV's actions: one per speed offset.
N_LEAD = len(SPEED_OFFSETS_MPS)
#: The cut-in POV's actions: the lane change (0), then one per speed offset.
CUT_LANE_CHANGE = 0
N_CUT = 1 + len(SPEED_OFFSETS_MPS)
N_ACTIONS = N_LEAD * N_CUT
#: Which POV is the primary adversary (``TwoPovStart.primary``, observation's last column).
PRIMARY_LEAD = 0
PRIMARY_CUT_IN = 1
#: Lanes at the start (0 = rightmost): the VUT and the lead POV, the cut-in POV.
VUT_LANE = 0
CUT_LANE = 1
#: The extra cost of a crash the reference driver could not have prevented, in α_C.
UNPREVENTABLE_PENALTY = 1.0
#: Tag of the generator of the supporting POV's start.
_SUPPORT_STREAM = 39


def encode_action(lead: int, cut: int) -> int:
    """The joint action of the lead POV's action ``lead`` (0..5) and the cut-in POV's ``cut``
    (0 = lane change, 1..6 speed offsets)."""
    if not (0 <= lead < N_LEAD and 0 <= cut < N_CUT):
        raise ActionError(f"lead action must be in [0, {N_LEAD}), cut-in in [0, {N_CUT})")
    return lead * N_CUT + cut


def decode_action(action: int) -> tuple[int, int]:
    """``(lead action, cut-in action)`` of a joint action."""
    return divmod(action, N_CUT)


@dataclass(frozen=True)
class TwoPovStart(InitialCondition):
    """An initial condition with the supporting POV's start given explicitly.

    Attributes:
        support_speed_mps: The supporting POV's speed [m/s].
        support_gap_m: Its gap, rear bumper minus the VUT's front bumper [m].
        primary: :data:`PRIMARY_LEAD` or :data:`PRIMARY_CUT_IN`.
    """

    support_speed_mps: float = 0.0
    support_gap_m: float = 0.0
    primary: int = PRIMARY_LEAD


def two_pov_start(ic: InitialCondition, odd: OddConfig) -> TwoPovStart:
    """``ic`` as a :class:`TwoPovStart` (itself if it is one).

    The supporting POV's speed and gap are uniform in ``odd.pov_speed_mps`` and
    ``odd.gap_m``, the primary a fair coin, drawn by a generator keyed by ``ic``'s three
    numbers rounded to 1e-6 (so that a start read back from a table rebuilds the same one).
    """
    if isinstance(ic, TwoPovStart):
        return ic
    key = [_SUPPORT_STREAM, *(round(x * 1e6) % 2**63 for x in ic.as_tuple())]
    u_speed, u_gap, u_primary = np.random.default_rng(key).random(3).tolist()
    (v0, v1), (g0, g1) = odd.pov_speed_mps, odd.gap_m
    return TwoPovStart(
        ic.pov_speed_mps,
        ic.vut_speed_mps,
        ic.gap_m,
        ic.follower_gap_m,
        ic.follower_speed_mps,
        support_speed_mps=v0 + (v1 - v0) * u_speed,
        support_gap_m=g0 + (g1 - g0) * u_gap,
        primary=PRIMARY_CUT_IN if u_primary < 0.5 else PRIMARY_LEAD,
    )


def inevitable_start(start: TwoPovStart, cfg: EnvConfig) -> bool:
    """Whether ``start`` is an inevitable collision with **either** POV (conservative).

    The inevitable-collision check of :mod:`sumo_ayss.scenarios.inevitable` (a VUT braking
    at 0.85 g from the first step touches the POV under one of the POV's worst plain plays,
    ``LeadAndCutInEnv.ICS_STRATEGIES``: the lead brakes at once; the cut-in POV cuts in at
    once and brakes from the next decision, or holds its speed), forecast without SUMO
    (:func:`~sumo_ayss.laws.braking_contact`) and for both POVs, whichever is the primary:
    a supporting POV that starts where its worst play cannot be escaped forces a forbidden
    contact no policy is to blame for either. The cut-in POV counts as in the VUT's lane
    from the first step (SUMO needs part of the lane change first), so every start SUMO's
    check finds is found, and a few more (tests/envs/test_two_pov_starts.py measures both).
    """
    decel = FullBraking().decel_mps2
    brake = SPEED_OFFSETS_MPS[0]
    primary = (start.gap_m, start.pov_speed_mps, start.primary == PRIMARY_CUT_IN)
    support = (start.support_gap_m, start.support_speed_mps, start.primary == PRIMARY_LEAD)
    for gap, speed, is_cut_in in (primary, support):
        plays = (1, None) if is_cut_in else (0,)
        for brake_from in plays:
            if braking_contact(
                cfg,
                gap,
                speed,
                start.vut_speed_mps,
                decel,
                brake_offset_mps=brake,
                brake_from=brake_from,
            ):
                return True
    return False


def start_filter(cfg: EnvConfig) -> StartFilter:
    """The case's admissible starts (:attr:`~sumo_ayss.cases.Case.start_filter`): those
    whose full two-POV start (:func:`two_pov_start`) is not an :func:`inevitable_start`."""

    def admissible(ic: InitialCondition) -> bool:
        return not inevitable_start(two_pov_start(ic, cfg.odd), cfg)

    return admissible


class Contact(NamedTuple):
    """Contacts of one SUMO step, by kind."""

    primary_vut: bool = False
    support_vut: bool = False
    pov_pov: bool = False

    @property
    def any(self) -> bool:
        return self.primary_vut or self.support_vut or self.pov_pov

    @property
    def failure(self) -> bool:
        """The POVs' failure: a contact the primary-only rule forbids."""
        return self.support_vut or self.pov_pov

    @property
    def povs(self) -> int:
        """POVs involved in a contact (each pays its own safe term)."""
        primary = self.primary_vut or self.pov_pov
        support = self.support_vut or self.pov_pov
        return int(primary) + int(support)
