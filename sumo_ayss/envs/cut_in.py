"""``sumo_ayss/CutIn-v0``: the POV cuts in from the left adjacent lane (paper V-B).

Road: the built-in two-lane straight road ``networks/straight_2lane.net.xml`` along +x,
lane 0 (``road_0``) on the right, lane 1 (``road_1``) on the left, 3.2 m wide, 30 m/s. Each
episode starts with the VUT centred in lane 0 and the POV centred in lane 1, both heading
along the road, from an :class:`~sumo_ayss.envs.odd.InitialCondition` (speeds and the
longitudinal gap, POV rear bumper - VUT front bumper; negative gaps, side by side, can be
given through ``reset(options={"initial_condition": ...})``).

Observation, float32 ``(v_pov, v_vut, h, same_lane)``:

* ``v_pov``, ``v_vut``: longitudinal speeds [m/s], clipped to ``[0, 50]``.
* ``h``: signed longitudinal bumper gap [m], POV rear bumper minus VUT front bumper, from
  SUMO positions and lengths; negative when the POV's rear is behind the VUT's front
  (longitudinal overlap, or the POV entirely behind). Clipped to ``[-20, 500]``.
* ``same_lane``: 1.0 when SUMO's lane index of the POV equals the VUT's, else 0.0. SUMO's
  lane index is that of the vehicle's *front centre*: during a lane change it flips when the
  POV's centre crosses the lane boundary, half-way through the change (after the 3rd of 5
  steps of a 1.0 s change), not when the POV's body first reaches into the lane.

Actions, ``Discrete(42)`` (:data:`N_ACTIONS`), in this order:

* ``0`` (:data:`LANE_CHANGE`): start a lane change into the VUT's lane. The action carries
  no speed: the POV keeps its last target speed (its initial speed right after reset).
  When the POV is already in the VUT's lane, or a change is under way, it is a no-op and
  ``info["lane_change_ignored"]`` is True (never an error).
* ``1 + k`` for ``k = 0..40`` (:func:`target_speed_mps`): target speed ``k`` m/s, turned into
  a bounded acceleration by :mod:`sumo_ayss.sim.actuator`. Speed actions act at any time,
  also during a lane change: the lateral motion, once started, runs on by itself.

The lane change is forced (lane-change mode 0: SUMO ignores the VUT) and continuous: SUMO
moves the POV sideways at lane width / ``sim.lanechange_duration_s`` (3.2 m/s by default),
so it is centred in the VUT's lane after that duration (5 steps of 0.2 s by default). Near
standstill SUMO moves sideways more slowly (checked: about 1 m/s at 0 m/s, 1.5 m/s at
0.5 m/s), so the change then takes longer; ``info["lane_changing"]`` follows the actual
motion. The VUT never changes lanes and reacts only through its car-following model: SUMO
counts a changing vehicle on both lanes, and the VUT first deviates from free driving in
the step during which the POV's body enters its lane (the 2nd step of a 1.0 s change),
before the POV's lane index flips. SUMO's "no overtaking on the right" speed rule is
switched off for the VUT
(:meth:`~sumo_ayss.sim.pair.VehiclePair.allow_vut_overtake_right`): without it, a VUT
beside or behind a slower POV in the left lane would match its speed, not drive freely.

Paper-fidelity mode (``env.actuator.mode: highway_env``, docs/paper_fidelity.md): the
lane change instead retargets highway-env's lane-centring loop (its lateral speed rises
and decays smoothly, about 2.3 s to settle within 0.1 m for 3.2 m); the POV's position is
integrated in Python and put into SUMO (sublane model); "changing lanes" lasts until its
centre is within ``env.actuator.lane_change_done_m`` of the target centre line; Δv̄ uses
its velocity ``speed·(cos ψ, sin ψ)``; collisions are highway-env's when the VUT runs
highway-env's IDM too.

Reward ``R = α_A·R_A + α_C·R_C`` (:mod:`sumo_ayss.envs.rewards`), R_A on the state at the end
of the decision (``info["reward_phase"]``):

* ``"lane_change"`` while the POV changes lanes: ``config.reward.lane_change`` on h (peak
  1 m, 0 beyond 5 m). "Changing lanes" (``info["lane_changing"]``) = the POV is off the
  centre line of its lane, or moved sideways during the last SUMO step; so a 1.0 s change
  pays this shape for 5 decisions, the last one ending centred in the VUT's lane.
* ``"same_lane"`` in the same lane otherwise: ``config.reward.same_lane`` (peak 0.25 m,
  0 beyond 20 m).
* ``"different_lanes"``: 0 in different lanes and not changing.
* ``"behind"``: 0 when the POV is entirely behind the VUT (its front behind the VUT's rear,
  ``h <= -(L_pov + L_vut)``). Our addition: the shapes pay ``value_at_contact`` for every
  ``h <= 0``, which would pay a POV for changing lanes behind the VUT and tailgating it.
* A collision gets the minimum reward ``-α_C`` and ends the episode (the base class).
  SUMO's own check (``--collision.action warn``, ``--collision.mingap-factor 0``) catches
  the side-swipe of a cut-in: while a change is under way SUMO counts the POV on both lanes
  and tests the bodies' lateral overlap, so it flags the collision in the first step the
  bodies overlap, also before the POV's lane index flips. Checked on SUMO 1.28 against a
  geometric test (bodies as rectangles along the road): 1,896 random side-by-side cut-ins
  at lane-change durations 0.6-3 s and steps 0.1-0.2 s agreed step for step (one case
  differed by bodies touching end to end within 1e-15 m). No extra check is needed.

Aggressiveness ``info["delta_v_bar_mps"]``: Δv̄ = (Δp/|Δp|)·Δv with Δp = p_vut - p_pov and
Δv = v_vut - v_pov as 2-D vectors in world coordinates (x along the road, y to the left);
negative when the two close in. p = the vehicle's centre point: front bumper centre moved
back half a length along the road (SUMO shifts a changing vehicle sideways as a whole);
v = (longitudinal speed, lateral speed from SUMO's ``getLateralSpeed``, which equals the
lateral displacement of the last step over its length during a continuous change). The
formula is :func:`sumo_ayss.analysis.metrics.delta_v_bar`, inlined here in plain floats
(the numpy version costs about 12 µs per call, a third of a SUMO step); a test checks that
both agree. The world-frame reading assumes a straight road along +x, as built in.
"""

from __future__ import annotations

import math
from typing import Any, ClassVar, NamedTuple

from sumo_ayss.cases.cut_in import CUT_IN
from sumo_ayss.config import EnvConfig
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.envs.pair_env import (
    HEADWAY_HIGH_M,
    HEADWAY_LOW_M,
    SPEED_HIGH_MPS,
    VUT_START_POS_M,
    PairEnv,
    PairKinematics,
)
from sumo_ayss.envs.rewards import lane_phase_reward
from sumo_ayss.laws import VehicleLaws
from sumo_ayss.sim.pair import PairPlacement
from sumo_ayss.util.errors import ActionError

#: Action index of the lane change.
LANE_CHANGE = 0
#: Target speeds [m/s] of the speed actions: action ``1 + k`` asks for ``k`` m/s.
MIN_TARGET_SPEED_MPS = 0
MAX_TARGET_SPEED_MPS = 40
#: Index of the first speed action (target 0 m/s).
FIRST_SPEED_ACTION = 1
#: Number of actions: the lane change and 41 target speeds.
N_ACTIONS = FIRST_SPEED_ACTION + MAX_TARGET_SPEED_MPS - MIN_TARGET_SPEED_MPS + 1

#: Lane indices at the start of an episode (0 = rightmost).
VUT_LANE = 0
POV_LANE = 1


def target_speed_mps(action: int) -> float:
    """Target speed [m/s] of speed action ``action`` (``1 + k`` -> ``k`` m/s, k = 0..40)."""
    if not FIRST_SPEED_ACTION <= action < N_ACTIONS:
        raise ActionError(f"action {action} is not a speed action (1..{N_ACTIONS - 1})")
    return float(action - FIRST_SPEED_ACTION + MIN_TARGET_SPEED_MPS)


class LaneState(NamedTuple):
    """The lateral state read back with each observation (lanes are SUMO front lanes).

    Attributes:
        pov_lane, vut_lane: SUMO lane indices (0 = rightmost).
        same_lane: ``pov_lane == vut_lane``.
        changing: the POV is off its lane's centre line or moved sideways in the last step.
        pov_lateral_offset_m: POV's offset from its lane's centre line [m], + = left.
        pov_y_m, vut_y_m: world y of the front bumper centres [m] (+ = left).
        pov_lateral_speed_mps, vut_lateral_speed_mps: lateral speeds [m/s], + = left.
        delta_v_bar_mps: Δv̄ [m/s] of the centre points, negative when closing in.
    """

    pov_lane: int
    vut_lane: int
    same_lane: bool
    changing: bool
    pov_lateral_offset_m: float
    pov_y_m: float
    vut_y_m: float
    pov_lateral_speed_mps: float
    vut_lateral_speed_mps: float
    delta_v_bar_mps: float


def _delta_v_bar(dx: float, dy: float, dvx: float, dvy: float) -> float:
    """Scalar :func:`sumo_ayss.analysis.metrics.delta_v_bar`: (Δp/|Δp|)·Δv, NaN at Δp = 0."""
    dist = math.hypot(dx, dy)
    return (dx * dvx + dy * dvy) / dist if dist > 0.0 else math.nan


class CutInEnv(PairEnv):
    """Two-lane cut-in: the POV, in the left lane, may change into the VUT's lane once.

    Args:
        config: environment configuration of the cut-in case; default: its defaults.
        vut: shortcut to override ``config.vut``.
        sumo_seed: SUMO's ``--seed``; default: drawn from the env's RNG at the first reset.
        laws: The POV's and the VUT's laws; default: built from the config.
    """

    CASE: ClassVar[str] = CUT_IN.name
    RESPONSE_ACTION: ClassVar[int] = LANE_CHANGE  # keeps its speed, the lateral motion runs on
    OBS_LOW: ClassVar[tuple[float, ...]] = (0.0, 0.0, HEADWAY_LOW_M, 0.0)
    OBS_HIGH: ClassVar[tuple[float, ...]] = (SPEED_HIGH_MPS, SPEED_HIGH_MPS, HEADWAY_HIGH_M, 1.0)
    N_ACTIONS: ClassVar[int] = N_ACTIONS
    IC_GAP_MIN_M: ClassVar[float] = HEADWAY_LOW_M  # side by side: the POV's rear behind
    ICS_STRATEGIES: ClassVar[dict[str, tuple[int, ...]]] = {
        "cut in, brake": (LANE_CHANGE, FIRST_SPEED_ACTION),
        "cut in, hold speed": (LANE_CHANGE,),
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
        self._lane_request_s = self.config.episode_s
        self._lane_change_cfg = self.config.reward.lane_change
        self._same_lane_cfg = self.config.reward.same_lane
        self._vut_length_m = self.config.vut_type.length_m
        # h at which the POV's front is level with the VUT's rear (POV entirely behind).
        self._both_lengths_m = self._pov_length_m + self._vut_length_m
        self._lane: LaneState | None = None
        self._target_mps = 0.0
        self._lc_started = False
        self._lc_ignored = False

    # ------------------------------------------------------------------ episode phases

    def start_episode(self, ic: InitialCondition) -> tuple[tuple[float, ...], dict[str, Any]]:
        """See :meth:`PairEnv.start_episode`; adds the lateral state to ``info``."""
        values, info = super().start_episode(ic)
        assert self._pair is not None and self._k is not None
        if self.config.sim.lateral_resolution_m is None:
            # Before the first step: the VUT drives freely. (SUMO's sublane model has no
            # per-vehicle lcOvertakeRight; the session passes the global option instead.)
            self._pair.allow_vut_overtake_right()
        self._target_mps = ic.pov_speed_mps
        self._lc_started = self._lc_ignored = False
        info.update(self._lane_info(self._k))
        # The boundary of the VUT's lane that the POV crosses to cut in (safety measures).
        side = 1.0 if POV_LANE > VUT_LANE else -1.0
        info["vut_lane_edge_y_m"] = self._pair.lane_centre_y_m(
            VUT_LANE
        ) + side * 0.5 * self._pair.lane_width_m(VUT_LANE)
        return values, info

    # ------------------------------------------------------------------ case hooks

    def _placement(self, ic: InitialCondition) -> PairPlacement:
        pov_front = VUT_START_POS_M + ic.gap_m + self._pov_length_m
        return PairPlacement(
            VUT_START_POS_M, ic.vut_speed_mps, VUT_LANE, pov_front, ic.pov_speed_mps, POV_LANE
        )

    def _observation_values(self, k: PairKinematics) -> tuple[float, ...]:
        assert self._lane is not None
        return (
            min(k.pov_speed_mps, SPEED_HIGH_MPS),
            min(k.vut_speed_mps, SPEED_HIGH_MPS),
            min(max(k.headway_m, HEADWAY_LOW_M), HEADWAY_HIGH_M),
            1.0 if self._lane.same_lane else 0.0,
        )

    def _apply_action(self, action: int, k: PairKinematics) -> float:
        lane, pair = self._lane, self._pair
        assert lane is not None and pair is not None
        self._lc_started = self._lc_ignored = False
        if action == LANE_CHANGE:
            if lane.same_lane or lane.changing:
                self._lc_ignored = True
            else:
                # SUMO's request lasts the whole episode (its duration only says how long
                # SUMO keeps trying; the motion takes --lanechange.duration); highway-env's
                # POV retargets its steering loop instead.
                self._pov_law.change_lane(pair, lane.vut_lane, self._lane_request_s)
                self._lc_started = True
        else:
            self._target_mps = target_speed_mps(action)
        return self._target_mps

    def _reward_terms(self, k: PairKinematics, collided: bool) -> tuple[float, dict[str, Any]]:
        lane = self._lane
        assert lane is not None
        h = k.headway_m
        r_a, phase = lane_phase_reward(
            h,
            self._both_lengths_m,
            lane.changing,
            lane.same_lane,
            self._lane_change_cfg,
            self._same_lane_cfg,
        )
        extra = {
            "reward_phase": phase,
            "lane_change_started": self._lc_started,
            "lane_change_ignored": self._lc_ignored,
            **self._lane_info(k),
        }
        return r_a, extra

    # ------------------------------------------------------------------ internals

    def _kinematics(self) -> PairKinematics:
        k = super()._kinematics()
        pair = self._pair
        assert pair is not None
        pov_lane, vut_lane = pair.lanes()
        offset = pair.pov_lateral_offset_m()
        lat_pov, lat_vut = pair.lateral_speeds()
        (pov_x, pov_y), (vut_x, vut_y) = pair.world_fronts()
        pov_len, vut_len = self._pov_length_m, self._vut_length_m
        # The POV's velocity and "changing lanes" as its law defines them.
        pov_vx, lat_pov, changing = self._pov_law.lane_motion(k.pov_speed_mps, offset, lat_pov)
        dvb = _delta_v_bar(
            (vut_x - 0.5 * vut_len) - (pov_x - 0.5 * pov_len),
            vut_y - pov_y,
            k.vut_speed_mps - pov_vx,
            lat_vut - lat_pov,
        )
        self._lane = LaneState(
            pov_lane,
            vut_lane,
            pov_lane == vut_lane,
            changing,
            offset,
            pov_y,
            vut_y,
            lat_pov,
            lat_vut,
            dvb,
        )
        return k

    def _lane_info(self, k: PairKinematics) -> dict[str, Any]:
        lane = self._lane
        assert lane is not None
        return {
            "pov_speed_mps": k.pov_speed_mps,
            "vut_speed_mps": k.vut_speed_mps,
            "same_lane": lane.same_lane,
            "lane_changing": lane.changing,
            "pov_lane": lane.pov_lane,
            "vut_lane": lane.vut_lane,
            "pov_y_m": lane.pov_y_m,
            "vut_y_m": lane.vut_y_m,
            "pov_lateral_speed_mps": lane.pov_lateral_speed_mps,
            "vut_lateral_speed_mps": lane.vut_lateral_speed_mps,
            "delta_v_bar_mps": lane.delta_v_bar_mps,
        }
