"""``sumo_ayss/LeadAndCutIn-v0``: a lead POV and a cut-in POV around one VUT (issue 39).

The rules and their reasons are in docs/cases.md; in short:

* Two lanes; the VUT in lane 0, the *lead* POV ahead of it in lane 0, the *cut-in* POV in
  lane 1. One of them is the episode's **primary** adversary, the other **supports**.
* A start :class:`~sumo_ayss.envs.odd.InitialCondition` ``(v_pov, v_vut, h)`` is the
  primary's speed, the VUT's speed and the primary's gap; the supporting POV's speed and
  gap (from the ODD's ranges) and the primary (a fair coin) come from a generator keyed by
  those three numbers (:func:`two_pov_start`), or explicitly from a :class:`TwoPovStart`.
* One joint discrete action: ``a = i_lead · N_CUT + i_cut`` (:func:`decode_action`).
* Reward ``α_A·R_A(primary) − α_C·(POVs in a contact) − α_U·[unpreventable crash]
  − α_F·[forbidden contact]`` (``env.reward.pov_failure_penalty``, default 0);
  primary–VUT contact is the VUT's crash (``info["collision"]``); supporting–VUT and
  POV–POV contacts end the episode as ``info["pov_failure"]``; a primary crash is replayed
  online with the careful-human reference in the VUT's body (``info["crash_unpreventable"]``).
"""

from __future__ import annotations

import math
from typing import Any, ClassVar, SupportsFloat, SupportsInt

import numpy as np
import numpy.typing as npt

from sumo_ayss.cases.lead_and_cut_in import LEAD_AND_CUT_IN
from sumo_ayss.config import EnvConfig
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.envs.pair_env import (
    HEADWAY_HIGH_M,
    HEADWAY_LOW_M,
    IC_GAP_MAX_M,
    SPEED_HIGH_MPS,
    VUT_START_POS_M,
    PairEnv,
    PairKinematics,
    session_vtypes,
)
from sumo_ayss.envs.reference import reference_config
from sumo_ayss.envs.rewards import adversarial_reward, lane_phase_reward
from sumo_ayss.envs.two_pov import (
    CUT_LANE,
    CUT_LANE_CHANGE,
    N_ACTIONS,
    PRIMARY_CUT_IN,
    PRIMARY_LEAD,
    SPEED_OFFSETS_MPS,
    UNPREVENTABLE_PENALTY,
    VUT_LANE,
    Contact,
    TwoPovStart,
    decode_action,
    encode_action,
    two_pov_start,
)
from sumo_ayss.laws import VehicleLaws, build_laws
from sumo_ayss.sim.pair import PairPlacement, VehiclePair
from sumo_ayss.sim.second_pov import SecondPov
from sumo_ayss.util.errors import ActionError, ConfigError
from sumo_ayss.vuts.catalog import VehicleType
from sumo_ayss.vuts.reference_types import DEFAULT_REFERENCE, REFERENCE_VUTS

__all__ = [
    "CUT_LANE_CHANGE",
    "N_ACTIONS",
    "PRIMARY_CUT_IN",
    "PRIMARY_LEAD",
    "SPEED_OFFSETS_MPS",
    "LeadAndCutInEnv",
    "TwoPovStart",
    "decode_action",
    "encode_action",
    "two_pov_start",
]


class LeadAndCutInEnv(PairEnv):
    """A VUT between a lead POV and a cut-in POV; one of them the primary adversary.

    The pair's POV (:class:`~sumo_ayss.sim.pair.VehiclePair`) is the episode's primary;
    the supporting POV is a :class:`~sumo_ayss.sim.second_pov.SecondPov`. Runs one pair
    per simulation (no :class:`~sumo_ayss.envs.vec_env.PairVecEnv`).

    Args: as :class:`~sumo_ayss.envs.pair_env.PairEnv`.
    """

    CASE: ClassVar[str] = LEAD_AND_CUT_IN.name
    #: Both POVs hold their speed (offset 0).
    RESPONSE_ACTION: ClassVar[int] = encode_action(
        SPEED_OFFSETS_MPS.index(0.0), 1 + SPEED_OFFSETS_MPS.index(0.0)
    )
    OBS_LOW: ClassVar[tuple[float, ...]] = (0.0, 0.0, HEADWAY_LOW_M, 0.0, 0.0, HEADWAY_LOW_M, 0.0)
    OBS_HIGH: ClassVar[tuple[float, ...]] = (
        SPEED_HIGH_MPS,
        SPEED_HIGH_MPS,
        HEADWAY_HIGH_M,
        1.0,
        SPEED_HIGH_MPS,
        HEADWAY_HIGH_M,
        1.0,
    )
    N_ACTIONS: ClassVar[int] = N_ACTIONS
    #: The lead brakes (offset -5 m/s: the actuator's -6 m/s²), or the cut-in POV cuts in
    #: at once and brakes or holds; the other POV holds its speed.
    ICS_STRATEGIES: ClassVar[dict[str, tuple[int, ...]]] = {
        "lead brakes": (encode_action(0, 1 + SPEED_OFFSETS_MPS.index(0.0)),),
        "cut in, brake": (
            encode_action(SPEED_OFFSETS_MPS.index(0.0), CUT_LANE_CHANGE),
            encode_action(SPEED_OFFSETS_MPS.index(0.0), 1),
        ),
        "cut in, hold speed": (encode_action(SPEED_OFFSETS_MPS.index(0.0), CUT_LANE_CHANGE),),
    }

    def __init__(
        self,
        config: EnvConfig | None = None,
        *,
        vut: str | None = None,
        sumo_seed: int | None = None,
        laws: VehicleLaws | None = None,
    ) -> None:
        super().__init__(config, vut=vut, sumo_seed=sumo_seed, laws=laws)
        cfg = self.config
        if cfg.actuator.mode != "clipped":
            raise ConfigError(
                f"env.actuator.mode must be 'clipped' for case {self.CASE!r}, got "
                f"{cfg.actuator.mode!r}"
            )
        if cfg.follower.enabled:
            raise ConfigError(f"env.follower.enabled must be false for case {self.CASE!r}")
        self._vut_length_m = cfg.vut_type.length_m
        self._both_lengths_m = self._pov_length_m + self._vut_length_m
        self._dt_s = cfg.sim.step_length_s
        self._lane_request_s = cfg.episode_s
        # The online preventability replay: not in an env whose VUT is a reference already.
        self.online_labels = cfg.vut not in REFERENCE_VUTS
        self._ref_config = reference_config(cfg, DEFAULT_REFERENCE)
        self._ref_law = build_laws(self._ref_config).vut if self.online_labels else None
        self._second: SecondPov | None = None
        self._start: TwoPovStart | None = None
        self._support_target = self._support_speed = self._support_accel = 0.0
        self._cut_target = 0.0
        self._actions: list[int] = []
        self._contact = Contact()
        self._lane: dict[str, Any] = {}
        self._lc_started = self._lc_ignored = False
        #: Online replays run and their wall time [s] (the label's cost).
        self.replays = 0
        self.replay_wall_s = 0.0

    @classmethod
    def ayss_start(cls, sample: InitialCondition) -> InitialCondition:
        """The AYSS sample with the case's fixed supporting POV and primary
        (:attr:`~sumo_ayss.cases.Case.ayss_fixed_obs`)."""
        _same_lane, v_support, h_support, primary = LEAD_AND_CUT_IN.ayss_fixed_obs
        return TwoPovStart(
            *sample.as_tuple(),
            support_speed_mps=v_support,
            support_gap_m=h_support,
            primary=round(primary),
        )

    # ------------------------------------------------------------------ gym API

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[npt.NDArray[np.float32], dict[str, Any]]:
        """See :meth:`PairEnv.reset`; adds the supporting POV."""
        if self._shared:
            raise self._step_error()
        ic = self.begin_reset(seed, options)
        pair = self._ensure_sim()
        self._add_vehicles(pair)
        pair.session.step()  # inserts the fresh vehicles
        values, info = self.start_episode(ic)
        return np.array(values, dtype=np.float32), info

    def step(
        self, action: SupportsInt
    ) -> tuple[npt.NDArray[np.float32], SupportsFloat, bool, bool, dict[str, Any]]:
        """One decision; see :meth:`PairEnv.step` and the module docstring for the rules."""
        pair = self._pair
        if pair is None or self._k is None or self._shared:
            raise self._step_error()
        if self._done:
            raise ActionError("step() after the episode ended; call reset() first")
        self.begin_decision(action)
        self._contact = self._run_substeps(pair)
        values, reward, terminated, truncated, info = self.end_decision(self._contact.any)
        return np.array(values, dtype=np.float32), reward, terminated, truncated, info

    def close(self) -> None:
        """Close SUMO and the laws; safe to call twice."""
        if self._ref_law is not None:
            self._ref_law.close()
        self._second = None
        super().close()

    def join_shared(self, pair: VehiclePair, sumo_seed: int) -> None:
        """Refused: this case runs one pair per simulation (``train.n_envs: 1``)."""
        raise ConfigError(f"case {self.CASE!r} cannot run in a PairVecEnv (train.n_envs: 1)")

    # ------------------------------------------------------------------ episode phases

    def _check_initial_condition(self, ic: InitialCondition) -> None:
        super()._check_initial_condition(ic)
        if isinstance(ic, TwoPovStart):
            v_max = min(SPEED_HIGH_MPS, self.config.actuator.max_speed_mps)
            ok = (
                0.0 <= ic.support_speed_mps <= v_max
                and 0.0 <= ic.support_gap_m <= IC_GAP_MAX_M
                and ic.primary in (PRIMARY_LEAD, PRIMARY_CUT_IN)
            )
            if not ok:
                raise ConfigError(
                    f"reset options['initial_condition']: support speed in [0, {v_max:g}] "
                    f"m/s, support gap in [0, {IC_GAP_MAX_M:g}] m and primary 0 or 1, got {ic}"
                )

    def start_episode(self, ic: InitialCondition) -> tuple[tuple[float, ...], dict[str, Any]]:
        """See :meth:`PairEnv.start_episode`; both POVs placed, the lateral state in ``info``."""
        self._start = two_pov_start(ic, self.config.odd)
        self._actions = []
        self._contact = Contact()
        self._cut_target = ic.pov_speed_mps if self._primary_is_cut() else 0.0
        values, info = super().start_episode(ic)
        assert self._pair is not None
        self._pair.allow_vut_overtake_right()
        self._lc_started = self._lc_ignored = False
        info.update(self._lane, **self._support_info())
        half = 0.5 * self._pair.lane_width_m(VUT_LANE)
        info["vut_lane_edge_y_m"] = self._pair.lane_centre_y_m(VUT_LANE) + half
        return values, info

    def command_pov(self) -> None:
        """The supporting POV's actuator, then the primary's and the VUT's laws."""
        second = self._second
        assert second is not None
        self._support_accel, self._support_speed = second.drive_toward(
            self._support_speed, self._support_target, self._dt_s, self.config.actuator
        )
        super().command_pov()

    def end_decision(
        self, collided: bool
    ) -> tuple[tuple[float, ...], float, bool, bool, dict[str, Any]]:
        """See :meth:`PairEnv.end_decision`; applies the contact rules to reward and info."""
        c = self._contact
        values, reward, terminated, truncated, info = super().end_decision(collided)
        info["collision"] = c.primary_vut
        info["pov_failure"] = c.failure
        info["vut_contact"] = c.primary_vut or c.support_vut
        info["contact"] = c.any
        info["support_vut_contact"] = c.support_vut
        info["pov_pov_contact"] = c.pov_pov
        info["reward_collision"] = -float(c.povs)
        alpha_c = self._reward_cfg.alpha_collision
        if c.any:
            reward = -alpha_c * c.povs
        if c.failure:
            reward -= self._reward_cfg.pov_failure_penalty * alpha_c
        if c.primary_vut and self.online_labels:
            unpreventable = self._reference_collides()
            info["crash_unpreventable"] = float(unpreventable)
            if unpreventable:
                reward -= UNPREVENTABLE_PENALTY * alpha_c
        return values, reward, terminated, truncated, info

    # ------------------------------------------------------------------ case hooks

    def _primary_is_cut(self) -> bool:
        assert self._start is not None
        return self._start.primary == PRIMARY_CUT_IN

    def _placement(self, ic: InitialCondition) -> PairPlacement:
        """The primary's placement; places the supporting POV too (before the reads)."""
        start, second = self._start, self._second
        assert start is not None and second is not None
        cut_primary = self._primary_is_cut()
        front = VUT_START_POS_M + self._pov_length_m
        support_lane = VUT_LANE if cut_primary else CUT_LANE
        second.place(support_lane, front + start.support_gap_m, start.support_speed_mps)
        self._support_speed = self._support_target = start.support_speed_mps
        self._support_accel = 0.0
        if not cut_primary:
            self._cut_target = start.support_speed_mps
        pov_lane = CUT_LANE if cut_primary else VUT_LANE
        return PairPlacement(
            VUT_START_POS_M,
            ic.vut_speed_mps,
            VUT_LANE,
            front + ic.gap_m,
            ic.pov_speed_mps,
            pov_lane,
        )

    def _observation_values(self, k: PairKinematics) -> tuple[float, ...]:
        lane = self._lane
        return (
            min(k.pov_speed_mps, SPEED_HIGH_MPS),
            min(k.vut_speed_mps, SPEED_HIGH_MPS),
            min(max(k.headway_m, HEADWAY_LOW_M), HEADWAY_HIGH_M),
            1.0 if lane["same_lane"] else 0.0,
            min(lane["support_speed_mps"], SPEED_HIGH_MPS),
            min(max(lane["support_gap_m"], HEADWAY_LOW_M), HEADWAY_HIGH_M),
            1.0 if self._primary_is_cut() else 0.0,
        )

    def _apply_action(self, action: int, k: PairKinematics) -> float:
        pair, second = self._pair, self._second
        assert pair is not None and second is not None
        self._actions.append(action)
        lead, cut = decode_action(action)
        cut_primary = self._primary_is_cut()
        v_lead = self._lane["support_speed_mps"] if cut_primary else k.pov_speed_mps
        lead_target = max(v_lead + SPEED_OFFSETS_MPS[lead], 0.0)
        self._lc_started = self._lc_ignored = False
        if cut == CUT_LANE_CHANGE:
            if self._lane["cut_in_vut_lane"] or self._lane["cut_changing"]:
                self._lc_ignored = True
            elif cut_primary:
                self._pov_law.change_lane(pair, VUT_LANE, self._lane_request_s)
                self._lc_started = True
            else:
                second.change_lane(VUT_LANE, self._lane_request_s)
                self._lc_started = True
        else:
            v_cut = k.pov_speed_mps if cut_primary else self._lane["support_speed_mps"]
            self._cut_target = max(v_cut + SPEED_OFFSETS_MPS[cut - 1], 0.0)
        if cut_primary:
            self._support_target = lead_target
            return self._cut_target
        self._support_target = self._cut_target
        return lead_target

    def _reward_terms(self, k: PairKinematics, collided: bool) -> tuple[float, dict[str, Any]]:
        lane, h = self._lane, k.headway_m
        shapes = self._reward_cfg
        if not self._primary_is_cut():
            r_a, phase = adversarial_reward(h, shapes.same_lane), "same_lane"
        else:
            r_a, phase = lane_phase_reward(
                h,
                self._both_lengths_m,
                bool(lane["lane_changing"]),
                bool(lane["same_lane"]),
                shapes.lane_change,
                shapes.same_lane,
            )
        extra = {
            "reward_phase": phase,
            "lane_change_started": self._lc_started,
            "lane_change_ignored": self._lc_ignored,
            **lane,
            **self._support_info(),
        }
        return r_a, extra

    # ------------------------------------------------------------------ internals

    def _session_vtypes(self) -> dict[str, VehicleType]:
        # The reference driver's type too, for the online replays.
        return session_vtypes(self._ref_config)

    def _add_vehicles(self, pair: VehiclePair) -> None:
        if self._second is None or self._second.pair is not pair:
            self._second = SecondPov(pair, pair.pov_type)
        pair.add()
        self._second.add()

    def _run_substeps(self, pair: VehiclePair) -> Contact:
        """The decision's SUMO steps; stops at the first contact, which it classifies."""
        session = pair.session
        second = self._second
        assert second is not None
        vut, primary, support = pair.vut, pair.pov, second.id
        for _ in range(self._substeps):
            self.command_pov()
            session.step()
            if not session.colliding_ids():
                continue
            kinds = {frozenset(p) for p in session.collision_pairs()}
            contact = Contact(
                frozenset((vut, primary)) in kinds,
                frozenset((vut, support)) in kinds,
                frozenset((primary, support)) in kinds,
            )
            if contact.any:
                return contact
        return Contact()

    def _kinematics(self) -> PairKinematics:
        k = super()._kinematics()
        pair, second = self._pair, self._second
        assert pair is not None and second is not None
        s = second.state()
        pov_lane, vut_lane = pair.lanes()
        offset = pair.pov_lateral_offset_m()
        lat_pov, lat_vut = pair.lateral_speeds()
        (pov_x, pov_y), (vut_x, vut_y) = pair.world_fronts()
        changing_primary = abs(offset) > 1e-9 or abs(lat_pov) > 1e-9
        changing_support = abs(s.lateral_offset_m) > 1e-9 or abs(s.lateral_speed_mps) > 1e-9
        cut_primary = self._primary_is_cut()
        dx = (vut_x - 0.5 * self._vut_length_m) - (pov_x - 0.5 * self._pov_length_m)
        dy = vut_y - pov_y
        dist = math.hypot(dx, dy)
        dvx, dvy = k.vut_speed_mps - k.pov_speed_mps, lat_vut - lat_pov
        dvb = (dx * dvx + dy * dvy) / dist if dist > 0.0 else math.nan
        self._lane = {
            "same_lane": pov_lane == vut_lane,
            "lane_changing": changing_primary,
            "pov_lane": pov_lane,
            "vut_lane": vut_lane,
            "pov_y_m": pov_y,
            "vut_y_m": vut_y,
            "pov_lateral_speed_mps": lat_pov,
            "vut_lateral_speed_mps": lat_vut,
            "delta_v_bar_mps": dvb,
            "support_speed_mps": s.speed_mps,
            "support_gap_m": s.pos_m - self._pov_length_m - k.vut_pos_m,
            "support_pos_m": s.pos_m,
            "support_lane": s.lane,
            "support_y_m": pair.lane_centre_y_m(s.lane) + s.lateral_offset_m,
            "support_lateral_speed_mps": s.lateral_speed_mps,
            "cut_in_vut_lane": (pov_lane if cut_primary else s.lane) == vut_lane,
            "cut_changing": changing_primary if cut_primary else changing_support,
        }
        return k

    def _support_info(self) -> dict[str, Any]:
        return {"primary": self._start.primary if self._start else PRIMARY_LEAD}

    def _reference_collides(self) -> bool:
        """Replay this episode with the reference driver in the VUT's place, the POVs'
        actions open loop (the last held to the episode's end), in this env's simulation;
        whether the reference touches a POV. The episode is over afterwards (``reset``)."""
        import time

        pair, ic, law = self._pair, self.initial_condition, self._ref_law
        assert pair is not None and ic is not None and law is not None
        actions = list(self._actions)
        t0 = time.perf_counter()
        own_law, own_type = self._vut_law, pair.vut_type
        self._vut_law, pair.vut_type = law, f"vut_{DEFAULT_REFERENCE}"
        try:
            self._add_vehicles(pair)
            pair.session.step()
            self.start_episode(self._start if self._start is not None else ic)
            for i in range(self._max_decisions):
                self.begin_decision(actions[min(i, len(actions) - 1)])
                contact = self._run_substeps(pair)
                self._vut_law.sync(pair)
                self._pov_law.sync(pair)
                if contact.primary_vut or contact.support_vut:
                    return True
                self._k = self._kinematics()
            return False
        finally:
            self._vut_law, pair.vut_type = own_law, own_type
            self.initial_condition = ic  # the episode's, as given (a checkpoint stores it)
            self._done = True
            self.replays += 1
            self.replay_wall_s += time.perf_counter() - t0
