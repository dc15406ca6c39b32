"""Reference drivers: what a competent and careful human (and two safe-distance models) do.

Three built-in controllers (:class:`~sumo_ayss.vuts.controllers.Controller`) that drive a
VUT like a reference driver, for the question a safety engineer asks first: *would a
careful human have avoided this crash?* (UN R157 Annex 4 Appendix 3). They read the
controller view (own speed, the leader in the own lane, and the object list, which shows a
cut-in before it reaches the own lane) and return an acceleration [m/s²], negative braking.
Between threats they hold their speed (a reference driver does not chase the leader; in the
counterfactual replays of :mod:`sumo_ayss.scenarios.preventability` the episode is seconds
long).

* :class:`CarefulDriver` (``cc_driver``) — R157's competent and careful (CC) human driver.
* :class:`FuzzySafetyDriver` (``fsm``) — JRC's Fuzzy Safety Model (Mattas et al. 2020).
* :class:`RssDriver` (``rss``) — RSS's longitudinal proper response.

Every number below is cited; the regulation's own text could not be read here, so the CC
driver's come from three public implementations that quote it (read through the project's
search tool, `../shared/research/reference-drivers.md` lists lines):

* esmini (``esmini/esmini``, commit ``77028d8``),
  ``EnvironmentSimulator/Modules/Controllers/ControllerALKS_R157SM.{hpp,cpp}``: reaction
  0.75 s, 0.774 g (7.593 m/s²) reached in 0.6 s (jerk 12.65 m/s³), risk perception 0.4 s or
  0.72 m of further lateral motion, wandering 0.375 m, critical TTC 2.0 s (cut-in) and THW
  2.0 s (deceleration), lead deceleration trigger 5 m/s², foot-off 0.4 m/s², AEB 0.85 g at
  TTC < 1.5 s on full overlap (``ControllerCatalog.xosc``: 1.4 s);
* ``ControllerECE_ALKS_RefDriver.cpp`` (esmini): the same constants, AEB without reaction;
* JRC-FSM (``ec-jrc/JRC-FSM``), ``utility/vehicle.py`` (``CC_rt = 0.75``,
  ``CC_min_jerk = 12.65``, ``CC_release_deceleration = 0.4``, ``CC_critical_ttc = 2``; FSM
  ``FSM_rt = 0.75``, ``b_r,min 4``, ``b_r,max 6``, ``b_l 7``, margins 2 m + 2 m),
  ``utility/fuzzy_functs.py`` (PFS, CFS);
* RSS: ad-rss-lib ``ad_rss/src/structured/RssFormulas.cpp``
  (``calculateSafeLongitudinalDistanceSameDirection``, ``calculateSafeLateralDistance``) with
  its documented starting point ρ = 1 s, a_max 3.5, b_min 4, b_max 8 m/s²,
  a_lat,max 0.2, b_lat,min 0.8 m/s², μ 0.1 m (``doc/ad_rss/Appendix-ParameterDiscussion.md``;
  the same in Apollo's ``rss_decider.cc``). The formula is reimplemented (ad-rss-lib is
  LGPL), not copied.

**Timing inside a step.** The testbed asks a controller once per SUMO step (0.2 s) and
applies the returned acceleration for the whole step. A reaction of 0.75 s does not fall on
a step boundary, so the drivers here describe their braking as a continuous profile in
time (reaction, then a linear ramp at the jerk, then the hold) and return the *mean* of that
profile over the coming step: the speed at every step boundary is then the continuous
profile's speed exactly (``tests/vuts/test_reference.py`` checks it by hand). Events are
read at the step's readings; a lateral threshold crossed between two readings is placed in
time by linear interpolation of the two readings.

Units: m, s, m/s, m/s²; decelerations are positive numbers; lateral + = left.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from sumo_ayss.sim.pair import SensedObject
from sumo_ayss.util.errors import ConfigError
from sumo_ayss.vuts.controllers import ControllerInput

__all__ = [
    "G_MPS2",
    "CarefulDriver",
    "FuzzySafetyDriver",
    "RssDriver",
    "braking_distance_m",
    "rss_lateral_safe_distance_m",
    "rss_safe_distance_m",
]

#: Standard gravity [m/s²] (0.774 g = 7.593 m/s², 0.85 g = 8.338 m/s²).
G_MPS2 = 9.81

#: Default width of the own body [m] where a driver needs it (SUMO's passenger default).
OWN_WIDTH_M = 1.8

# The catalog entries that name these classes (``cc_driver``, ``fsm``, ``rss``) are
# :data:`sumo_ayss.vuts.catalog.REFERENCE_VUTS`.


# ----------------------------------------------------------------------------- geometry


def _in_lane(o: SensedObject, lane_width_m: float) -> bool:
    """The object's body reaches into the own lane (between its edges)."""
    half = 0.5 * (lane_width_m if math.isfinite(lane_width_m) else 3.2)
    return abs(o.lateral_offset_m) < half + 0.5 * o.width_m


def _ahead(o: SensedObject) -> bool:
    """The object's front is ahead of the own front."""
    return o.gap_m + o.length_m > 0.0


def _ttc_s(gap_m: float, rel_speed_mps: float) -> float:
    """Longitudinal TTC [s] from a bumper gap and the object's relative speed (< 0 closing)."""
    if gap_m <= 0.0:
        return 0.0
    return gap_m / -rel_speed_mps if rel_speed_mps < 0.0 else math.inf


def _lead(state: ControllerInput) -> SensedObject | None:
    """The nearest object ahead whose body reaches into the own lane (the leader)."""
    best: SensedObject | None = None
    for o in state.objects:
        if _ahead(o) and _in_lane(o, state.lane_width_m) and (best is None or o.gap_m < best.gap_m):
            best = o
    if best is None and state.has_leader:  # a view without an object list (older callers)
        best = SensedObject(state.gap_m, 0.0, state.rel_speed_mps, 0.0, 5.0, OWN_WIDTH_M)
    return best


# ----------------------------------------------------------------------------- profile


@dataclass
class _Ramp:
    """A braking profile: ``decel(t) = min(peak, peak · (t - t0) / ramp_s)`` for t >= t0."""

    t0: float
    peak: float
    ramp_s: float

    def at(self, t: float) -> float:
        if t <= self.t0:
            return 0.0
        if self.ramp_s <= 0.0:
            return self.peak
        return min(self.peak, self.peak * (t - self.t0) / self.ramp_s)

    def breaks(self) -> tuple[float, float]:
        return (self.t0, self.t0 + max(self.ramp_s, 0.0))


def _mean_of_max(parts: Sequence[tuple[Any, Sequence[float]]], t0: float, t1: float) -> float:
    """Exact mean over ``[t0, t1]`` of ``max_i f_i(t)`` for piecewise-linear ``f_i``.

    ``parts``: ``(f, breakpoints)`` pairs; each ``f_i`` is linear between its breakpoints
    (it may jump at one). On each piece between breakpoints every ``f_i`` is read at two
    interior points (which defines its line without touching a jump); their upper envelope
    is split where two lines cross, and each linear piece's mean is its midpoint value.
    """
    pts = {t0, t1}
    for _f, br in parts:
        pts.update(b for b in br if t0 < b < t1)
    grid = sorted(pts)
    total = 0.0
    for a, b in itertools.pairwise(grid):
        w = b - a
        lines = []
        for f, _ in parts:
            y1, y3 = f(a + 0.25 * w), f(a + 0.75 * w)
            slope = (y3 - y1) / (0.5 * w)
            lines.append((y1 - slope * 0.25 * w, slope))  # value at a, slope
        cuts = [a, b]
        for i in range(len(lines)):
            for j in range(i + 1, len(lines)):
                dv, ds = lines[i][0] - lines[j][0], lines[i][1] - lines[j][1]
                if ds != 0.0 and 0.0 < -dv / ds < w:
                    cuts.append(a - dv / ds)
        cuts.sort()
        for c, d in itertools.pairwise(cuts):
            mid = 0.5 * (c + d) - a
            total += (d - c) * max(v + s * mid for v, s in lines)
    return total / (t1 - t0)


def braking_distance_m(
    speed_mps: float, delay_s: float, decel_mps2: float = 0.774 * G_MPS2, ramp_s: float = 0.6
) -> float:
    """Distance [m] to a stop after ``delay_s`` at constant speed and a linear ramp to
    ``decel_mps2`` over ``ramp_s`` (research notes' formula, foot-off ignored):
    ``v·T + (v·r − a·r²/6) + (v − a·r/2)² / (2a)`` for a stop after the ramp."""
    v, a, r = speed_mps, decel_mps2, ramp_s
    v_after_ramp = v - 0.5 * a * r
    if v_after_ramp <= 0.0:
        raise ConfigError("braking_distance_m: the car stops within the ramp (not covered)")
    return v * delay_s + (v * r - a * r * r / 6.0) + v_after_ramp**2 / (2.0 * a)


# ----------------------------------------------------------------------------- CC driver


@dataclass
class CarefulDriver:
    """R157's competent and careful human driver (the CC driver), longitudinal.

    Phases, per threat (the cited implementations' state machine, adapted to one VUT lane):

    1. **Risk perceived** at the earliest of
       (a) *cut-in*: an object in the next lane has moved more than ``wander_m`` (0.375 m)
       from its lane position toward the own lane; perception then lasts until it has moved
       a further ``perception_dist_m`` (0.72 m; ``perception: time`` instead waits
       ``perception_s``, 0.4 s);
       (b) *deceleration*: ``decel_perception: onset`` (default) — the leader's brake
       lights: it decelerates by more than ``brake_light_mps2`` (0.5 m/s², above a coasting
       car's 0.4 m/s²), and the reaction runs from the braking's onset, as JRC-FSM's
       car-following comparison and the ECE reference driver do; ``threshold`` — the
       regulation as JRC-FSM issue #2 quotes it: the leader brakes harder than
       ``decel_trigger_mps2`` (5 m/s²), then ``perception_s`` of perception. The default is
       the stricter (more careful) reading: with ``threshold`` a leader braking at 4.9 m/s²
       is never perceived as braking (the "weakness" JRC-FSM issue #2 names), which would
       excuse a VUT for crashes a driver watching the brake lights avoids;
       (c) *closing in*: TTC to the leader <= ``critical_ttc_s`` (2 s), the JAMA C&C
       model's longitudinal risk boundary (JAMA framework 2.0 §2.3.3.1 as
       ``fomaad/sgcpd`` ``logverify/jama_cc_model.py`` cites it); no further perception
       time. This also covers a leader that is already closing in at the episode's start,
       which the regulation's cut-in and deceleration cases never perceive.
    2. **Criticality gate** at the end of perception: TTC < ``critical_ttc_s`` (cut-in,
       closing in) or time headway < ``critical_thw_s`` (2 s; deceleration). If it does not
       hold the threat is dropped ("non critical"; a later trigger starts over).
    3. **Reaction** for ``reaction_s`` (0.75 s), easing off at ``release_decel_mps2``
       (0.4 m/s² "foot off", an implementer's value in esmini and JRC-FSM: 0 turns it off).
    4. **Braking**: a linear ramp to ``brake_decel_mps2`` (0.774 g) over ``ramp_s`` (0.6 s),
       held until the threat is over: the leader no longer closes in and no longer brakes
       harder than 0.5 m/s² (or the car stops); then the driver holds its speed again.
    5. **AEB** (``aeb: true``): whenever TTC to an object fully in the own lane (full
       overlap within 0.1 m) is below ``aeb_ttc_s`` (1.5 s, esmini's code; its catalogue
       says 1.4), braking ramps to ``aeb_decel_mps2`` (0.85 g) over ``aeb_ramp_s`` (0.6 s)
       without reaction time; the stronger of the driver's and the AEB's braking acts.

    Args: the named parameters above (defaults cited in the module docstring).
    """

    reaction_s: float = 0.75
    perception_s: float = 0.4
    perception: str = "distance"
    perception_dist_m: float = 0.72
    wander_m: float = 0.375
    critical_ttc_s: float = 2.0
    critical_thw_s: float = 2.0
    decel_perception: str = "onset"
    brake_light_mps2: float = 0.5
    decel_trigger_mps2: float = 5.0
    release_decel_mps2: float = 0.4
    brake_decel_mps2: float = 0.774 * G_MPS2
    ramp_s: float = 0.6
    aeb: bool = True
    aeb_ttc_s: float = 1.5
    aeb_decel_mps2: float = 0.85 * G_MPS2
    aeb_ramp_s: float = 0.6
    own_width_m: float = OWN_WIDTH_M
    # Episode state (reset()).
    _pending: list[tuple[float, str]] = field(default_factory=list, init=False, repr=False)
    _cut_in_seen: bool = field(default=False, init=False, repr=False)
    _react_from: float | None = field(default=None, init=False, repr=False)
    _aeb: _Ramp | None = field(default=None, init=False, repr=False)
    _lane0: dict[int, float] = field(default_factory=dict, init=False, repr=False)
    _prev: ControllerInput | None = field(default=None, init=False, repr=False)
    _wandered_at: float | None = field(default=None, init=False, repr=False)

    def __post_init__(self) -> None:
        if self.decel_perception not in ("onset", "threshold"):
            raise ConfigError(
                "cc_driver: decel_perception must be one of ['onset', 'threshold'], "
                f"got {self.decel_perception!r}"
            )
        if self.perception not in ("distance", "time"):
            raise ConfigError(
                "cc_driver: perception must be one of ['distance', 'time'], "
                f"got {self.perception!r}"
            )
        for name in ("reaction_s", "perception_s", "perception_dist_m", "wander_m",
                     "release_decel_mps2", "ramp_s", "aeb_ramp_s"):  # fmt: skip
            _check(name, getattr(self, name), low=0.0)
        for name in ("critical_ttc_s", "critical_thw_s", "decel_trigger_mps2", "brake_light_mps2",
                     "brake_decel_mps2", "aeb_ttc_s", "aeb_decel_mps2", "own_width_m"):  # fmt: skip
            _check(name, getattr(self, name), low=0.0, strict=True)

    def reset(self) -> None:
        """Forget the last episode."""
        self._react_from = self._wandered_at = None
        self._pending = []
        self._cut_in_seen = False
        self._aeb = None
        self._lane0 = {}
        self._prev = None

    @property
    def braking_from_s(self) -> float | None:
        """When the driver's braking ramp starts (reaction start + reaction time) [s]."""
        return None if self._react_from is None else self._react_from + self.reaction_s

    # -- the decision ------------------------------------------------------------------

    def acceleration(self, state: ControllerInput) -> float:
        """Mean acceleration [m/s²] of the driver's profile over the coming step."""
        t = state.time_s
        lead = _lead(state)
        prev, self._prev = self._prev, state
        self._update_threat(state, prev, lead)
        self._update_aeb(state, lead)
        parts: list[tuple[Any, Sequence[float]]] = []
        if self._react_from is not None:
            start = self._react_from
            end = start + self.reaction_s
            ramp = _Ramp(end, self.brake_decel_mps2, self.ramp_s)
            foot = self.release_decel_mps2

            def driver(x: float, s: float = start, f: float = foot, r: _Ramp = ramp) -> float:
                return max(f if x > s else 0.0, r.at(x))

            parts.append((driver, (start, end, end + self.ramp_s)))
        if self._aeb is not None:
            parts.append((self._aeb.at, self._aeb.breaks()))
        if not parts:
            return 0.0
        return -_mean_of_max(parts, t, t + state.dt_s)

    def _update_threat(
        self, state: ControllerInput, prev: ControllerInput | None, lead: SensedObject | None
    ) -> None:
        t = state.time_s
        eps = 1e-9
        if self._react_from is not None:
            braking = t + eps >= self._react_from + self.reaction_s
            if braking and self._threat_over(state, prev, lead):
                self._react_from = None
                self._pending = []
            return
        self._pending += self._triggers(state, prev, lead)
        due = sorted(p for p in self._pending if p[0] <= t + eps)
        self._pending = [p for p in self._pending if p[0] > t + eps]  # still perceiving
        for end, gate in due:  # earliest first; one not critical now is dropped
            if self._critical(state, lead, gate):
                # The reaction starts when perception ended (it ended within the last step
                # or at this reading; one found later starts now).
                self._react_from = end if end >= t - state.dt_s - eps else t
                self._pending = []
                return

    def _threat_over(
        self, state: ControllerInput, prev: ControllerInput | None, lead: SensedObject | None
    ) -> bool:
        if state.speed_mps <= 0.0:
            return False  # stopped: stay on the brake
        if lead is None:
            return not any(self._approaching(o, state) for o in state.objects)
        return lead.rel_speed_mps >= 0.0 and _lead_accel(state, prev, lead) > -0.5

    def _critical(self, state: ControllerInput, lead: SensedObject | None, gate: str) -> bool:
        targets = [lead] if lead is not None else []
        targets += [o for o in state.objects if self._approaching(o, state)]
        if gate == "now":
            return True
        for o in targets:
            if gate == "thw":
                if state.speed_mps > 0.0 and o.gap_m / state.speed_mps < self.critical_thw_s:
                    return True
            elif _ttc_s(o.gap_m, o.rel_speed_mps) < self.critical_ttc_s:
                return True
        return False

    def _approaching(self, o: SensedObject, state: ControllerInput) -> bool:
        """An object ahead outside the own lane moving toward it."""
        toward = -math.copysign(1.0, o.lateral_offset_m) * o.lateral_speed_mps
        return _ahead(o) and not _in_lane(o, state.lane_width_m) and toward > 0.0

    def _triggers(
        self, state: ControllerInput, prev: ControllerInput | None, lead: SensedObject | None
    ) -> list[tuple[float, str]]:
        """``(end of perception [s], gate)`` of each risk perceived at this reading.

        Gates: ``now`` (closing in: the trigger is the criticality), ``thw``, ``ttc``.
        """
        t = state.time_s
        found: list[tuple[float, str]] = []
        if lead is not None:
            if _ttc_s(lead.gap_m, lead.rel_speed_mps) <= self.critical_ttc_s:
                found.append((t, "now"))  # closing in: no further perception time
            onset = self.decel_perception == "onset"
            trigger = self.brake_light_mps2 if onset else self.decel_trigger_mps2
            if _lead_accel(state, prev, lead) < -trigger:
                # The braking began with the last step; "onset" reacts from there (JRC-FSM,
                # the ECE reference driver), "threshold" perceives 0.4 s first (esmini).
                found.append((t - state.dt_s + (0.0 if onset else self.perception_s), "thw"))
        # Cut-in: lateral motion toward the own lane beyond the wandering threshold.
        # (An object already in the own lane is the leader's case above.)
        for i, o in enumerate(state.objects):
            if not _ahead(o) or (self._wandered_at is None and _in_lane(o, state.lane_width_m)):
                continue
            base = self._lane0.setdefault(i, abs(o.lateral_offset_m))
            moved = base - abs(o.lateral_offset_m)
            if self._wandered_at is None and moved > self.wander_m:
                self._wandered_at = _crossing(prev, i, base, self.wander_m, state)
            if self._wandered_at is None or self._cut_in_seen:
                continue
            if self.perception == "time":
                self._cut_in_seen = True
                found.append((self._wandered_at + self.perception_s, "ttc"))
            elif moved >= self.wander_m + self.perception_dist_m:
                self._cut_in_seen = True
                further = self.wander_m + self.perception_dist_m
                found.append((_crossing(prev, i, base, further, state), "ttc"))
        return found

    # -- AEB ---------------------------------------------------------------------------

    def _update_aeb(self, state: ControllerInput, lead: SensedObject | None) -> None:
        """Arm the AEB once TTC < ``aeb_ttc_s`` with the leader fully in front (esmini's
        full overlap: one body's width covers the other's, within 0.1 m)."""
        if not self.aeb or self._aeb is not None or lead is None:
            return
        full = abs(lead.lateral_offset_m) <= 0.5 * abs(lead.width_m - self.own_width_m) + 0.1
        if full and _ttc_s(lead.gap_m, lead.rel_speed_mps) < self.aeb_ttc_s:
            self._aeb = _Ramp(state.time_s, self.aeb_decel_mps2, self.aeb_ramp_s)


def _lead_accel(state: ControllerInput, prev: ControllerInput | None, lead: SensedObject) -> float:
    """The leader's acceleration over the last step [m/s²] from two readings (0 without)."""
    if prev is None:
        return 0.0
    before = _lead(prev)
    if before is None:
        return 0.0
    v_now = state.speed_mps + lead.rel_speed_mps
    v_before = prev.speed_mps + before.rel_speed_mps
    return (v_now - v_before) / state.dt_s


def _crossing(
    prev: ControllerInput | None, i: int, base: float, threshold: float, state: ControllerInput
) -> float:
    """When the object's lateral motion toward the lane passed ``threshold`` [s]: linear
    between the last two readings (the current reading's time without a previous one)."""
    t = state.time_s
    if prev is None or i >= len(prev.objects):
        return t
    m0 = base - abs(prev.objects[i].lateral_offset_m)
    m1 = base - abs(state.objects[i].lateral_offset_m)
    if m1 <= m0 or m0 >= threshold:
        return t if m0 < threshold else prev.time_s
    return prev.time_s + (threshold - m0) / (m1 - m0) * (t - prev.time_s)


def _check(name: str, value: Any, *, low: float, strict: bool = False) -> None:
    ok = isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)
    if not ok or value < low or (strict and value == low):
        rel = ">" if strict else ">="
        raise ConfigError(
            f"reference driver: {name} must be a finite number {rel} {low:g}, got {value!r}"
        )


# ----------------------------------------------------------------------------- FSM


@dataclass
class FuzzySafetyDriver:
    """JRC's Fuzzy Safety Model (Mattas et al., AAP 148 (2020) 105794), longitudinal.

    Each reading computes the proactive (PFS) and critical (CFS) fuzzy safety of the
    relevant object (the leader, or a cut-in that passes the relevance filter below):

    * PFS: ``d' = d - margin_dist``; ``d_safe = u_r·τ + u_r²/(2·b_r,min) - u_l²/(2·b_l) +
      margin_safe``; ``d_unsafe = u_r·τ + u_r²/(2·b_r,max) - u_l²/(2·b_l)``; 0 above
      ``d_safe``, 1 below ``d_unsafe``, linear between.
    * CFS (closing in only): with ``a_rF = max(a_r, -b_r,min)`` and ``u_new = u_r + τ·a_rF``:
      if ``u_new < u_l``, 1 when ``d < (u_r - u_l)²/(2|a_r|)``, else 0; otherwise
      ``d_safe = (u_r + a_rF·τ/2 - u_l)·τ + (u_r + a_rF·τ - u_l)²/(2·b_r,min)``, ``d_unsafe``
      the same with ``b_r,max``, linear between.
    * Response, ``reaction_s`` after the first unsafe reading: target deceleration
      ``b_r,min + CFS·(b_r,max - b_r,min)`` when CFS > 0, else ``PFS·b_r,min``, reached at
      ``jerk_mps3`` and capped at ``max_decel_mps2`` (0.774 g); back to holding speed once
      both are 0.
    * Relevance of an object in the next lane (JRC ``FSM_check_safety``): ignored while its
      lateral headway (lateral gap / lateral speed toward the lane) exceeds its longitudinal
      gross headway (gap + both lengths, over the closing speed) by more than 0.1 s.
    """

    reaction_s: float = 0.75
    b_r_min_mps2: float = 4.0
    b_r_max_mps2: float = 6.0
    b_l_mps2: float = 7.0
    margin_dist_m: float = 2.0
    margin_safe_m: float = 2.0
    max_decel_mps2: float = 0.774 * G_MPS2
    jerk_mps3: float = 12.65
    own_length_m: float = 5.0
    own_width_m: float = OWN_WIDTH_M
    _unsafe_since: float | None = field(default=None, init=False, repr=False)
    _decel: float = field(default=0.0, init=False, repr=False)

    def __post_init__(self) -> None:
        for name in ("reaction_s", "margin_dist_m", "margin_safe_m"):
            _check(name, getattr(self, name), low=0.0)
        for name in ("b_r_min_mps2", "b_r_max_mps2", "b_l_mps2", "max_decel_mps2", "jerk_mps3"):
            _check(name, getattr(self, name), low=0.0, strict=True)
        if self.b_r_max_mps2 < self.b_r_min_mps2:
            raise ConfigError("fsm: b_r_max_mps2 must be >= b_r_min_mps2")

    def reset(self) -> None:
        self._unsafe_since = None
        self._decel = 0.0

    def pfs(self, gap_m: float, u_r: float, u_l: float) -> float:
        """Proactive fuzzy safety in [0, 1] (1 = unsafe)."""
        tau = self.reaction_s
        d = gap_m - self.margin_dist_m
        common = u_r * tau - u_l**2 / (2.0 * self.b_l_mps2)
        d_safe = common + u_r**2 / (2.0 * self.b_r_min_mps2) + self.margin_safe_m
        d_unsafe = common + u_r**2 / (2.0 * self.b_r_max_mps2)
        return _fuzzy(d, d_safe, d_unsafe)

    def cfs(self, gap_m: float, u_r: float, u_l: float, a_r: float) -> float:
        """Critical fuzzy safety in [0, 1] (1 = unsafe); ``a_r`` own acceleration."""
        if u_r <= u_l:
            return 0.0
        tau = self.reaction_s
        a_rf = max(a_r, -self.b_r_min_mps2)
        u_new = u_r + tau * a_rf
        if u_new < u_l:
            if a_r >= 0.0:
                return 0.0
            return 1.0 if gap_m < (u_r - u_l) ** 2 / (2.0 * abs(a_r)) else 0.0
        first = (u_r + a_rf * tau / 2.0 - u_l) * tau
        d_safe = first + (u_new - u_l) ** 2 / (2.0 * self.b_r_min_mps2)
        d_unsafe = first + (u_new - u_l) ** 2 / (2.0 * self.b_r_max_mps2)
        return _fuzzy(gap_m, d_safe, d_unsafe)

    def _relevant(self, state: ControllerInput) -> SensedObject | None:
        lead = _lead(state)
        best = lead
        for o in state.objects:
            if not _ahead(o) or _in_lane(o, state.lane_width_m):
                continue
            toward = -math.copysign(1.0, o.lateral_offset_m) * o.lateral_speed_mps
            if toward <= 0.0:
                continue
            half = 0.5 * (state.lane_width_m if math.isfinite(state.lane_width_m) else 3.2)
            lat_gap = max(abs(o.lateral_offset_m) - 0.5 * o.width_m - half, 0.0)
            lat_headway = lat_gap / toward
            closing = -o.rel_speed_mps
            gross = o.gap_m + o.length_m + self.own_length_m
            long_headway = gross / closing if closing > 0.0 else math.inf
            if lat_headway > long_headway + 0.1:
                continue
            if best is None or o.gap_m < best.gap_m:
                best = o
        return best

    def acceleration(self, state: ControllerInput) -> float:
        """The jerk-limited response [m/s²] for the coming step."""
        o = self._relevant(state)
        target = 0.0
        if o is not None:
            u_r = state.speed_mps
            u_l = u_r + o.rel_speed_mps
            pfs = self.pfs(o.gap_m, u_r, u_l)
            cfs = self.cfs(o.gap_m, u_r, u_l, -self._decel)
            if pfs > 0.0 or cfs > 0.0:
                if self._unsafe_since is None:
                    self._unsafe_since = state.time_s
                if cfs > 0.0:
                    target = self.b_r_min_mps2 + cfs * (self.b_r_max_mps2 - self.b_r_min_mps2)
                else:
                    target = pfs * self.b_r_min_mps2
            else:
                self._unsafe_since = None
        else:
            self._unsafe_since = None
        t, dt = state.time_s, state.dt_s
        since = self._unsafe_since
        if since is None or t + dt <= since + self.reaction_s:
            target_now, start = 0.0, t
        else:
            # The part of the step before the reaction ends keeps the current deceleration.
            target_now, start = min(target, self.max_decel_mps2), max(t, since + self.reaction_s)
        step = self.jerk_mps3 * max(0.0, t + dt - start)
        new = min(max(target_now, self._decel - step), self._decel + step)
        self._decel = new
        return -new


def _fuzzy(d: float, d_safe: float, d_unsafe: float) -> float:
    """0 above ``d_safe``, 1 below ``d_unsafe``, linear between."""
    if d > d_safe:
        return 0.0
    if d < d_unsafe or d_safe <= d_unsafe:
        return 1.0
    return (d - d_safe) / (d_unsafe - d_safe)


# ----------------------------------------------------------------------------- RSS


def rss_safe_distance_m(
    v_rear_mps: float,
    v_front_mps: float,
    rho_s: float = 1.0,
    a_max_mps2: float = 3.5,
    b_min_mps2: float = 4.0,
    b_max_mps2: float = 8.0,
) -> float:
    """RSS's minimum safe longitudinal distance, same direction [m] (ad-rss-lib's
    ``calculateSafeLongitudinalDistanceSameDirection`` without its speed cap and extra
    margin): ``max(0, v_r·ρ + a_max·ρ²/2 + (v_r + ρ·a_max)²/(2·b_min) - v_f²/(2·b_max))``."""
    v_resp = v_rear_mps + rho_s * a_max_mps2
    d = (
        v_rear_mps * rho_s
        + 0.5 * a_max_mps2 * rho_s**2
        + v_resp**2 / (2.0 * b_min_mps2)
        - v_front_mps**2 / (2.0 * b_max_mps2)
    )
    return max(0.0, d)


def rss_lateral_safe_distance_m(
    v_lat_toward_mps: float,
    rho_s: float = 1.0,
    a_lat_max_mps2: float = 0.2,
    b_lat_min_mps2: float = 0.8,
    mu_m: float = 0.1,
) -> float:
    """RSS's minimum safe lateral distance [m] between the own car (no lateral speed) and an
    object moving toward it at ``v_lat_toward_mps``: each car's stated braking pattern
    (accelerate laterally at ``a_lat_max`` for ρ, then brake at ``b_lat_min``) plus μ."""

    def offset(v: float) -> float:
        v_resp = v + rho_s * a_lat_max_mps2
        return (
            v * rho_s
            + 0.5 * a_lat_max_mps2 * rho_s**2
            + max(v_resp, 0.0) ** 2 / (2.0 * b_lat_min_mps2)
        )

    return mu_m + offset(0.0) + offset(max(v_lat_toward_mps, 0.0))


@dataclass
class RssDriver:
    """RSS's longitudinal proper response as a driver: hold speed while safe; brake at
    ``b_min_mps2`` while an object is closer than RSS's safe distance both longitudinally
    (:func:`rss_safe_distance_m`) and laterally (:func:`rss_lateral_safe_distance_m`, an
    object already reaching into the own lane is laterally unsafe). The response is
    immediate: ρ is the response time RSS *allows* the rear car, built into the distance."""

    rho_s: float = 1.0
    a_max_mps2: float = 3.5
    b_min_mps2: float = 4.0
    b_max_mps2: float = 8.0
    a_lat_max_mps2: float = 0.2
    b_lat_min_mps2: float = 0.8
    mu_m: float = 0.1

    def __post_init__(self) -> None:
        _check("rho_s", self.rho_s, low=0.0)
        _check("mu_m", self.mu_m, low=0.0)
        for name in ("a_max_mps2", "b_min_mps2", "b_max_mps2", "a_lat_max_mps2", "b_lat_min_mps2"):
            _check(name, getattr(self, name), low=0.0, strict=True)

    def reset(self) -> None:
        """Stateless: nothing to forget."""

    def acceleration(self, state: ControllerInput) -> float:
        """``-b_min`` while some object is RSS-unsafe, else 0 [m/s²]."""
        half = 0.5 * (state.lane_width_m if math.isfinite(state.lane_width_m) else 3.2)
        objects = list(state.objects) or ([o] if (o := _lead(state)) else [])
        for o in objects:
            if not _ahead(o):
                continue
            u_r = state.speed_mps
            d_lon = rss_safe_distance_m(
                u_r, u_r + o.rel_speed_mps, self.rho_s, self.a_max_mps2, self.b_min_mps2,
                self.b_max_mps2,
            )  # fmt: skip
            if o.gap_m >= d_lon:
                continue
            if not _in_lane(o, state.lane_width_m):
                toward = -math.copysign(1.0, o.lateral_offset_m) * o.lateral_speed_mps
                lat_gap = abs(o.lateral_offset_m) - 0.5 * o.width_m - (half - 0.5 * OWN_WIDTH_M)
                lat_gap -= 0.5 * OWN_WIDTH_M
                d_lat = rss_lateral_safe_distance_m(
                    toward, self.rho_s, self.a_lat_max_mps2, self.b_lat_min_mps2, self.mu_m
                )
                if lat_gap >= d_lat:
                    continue
            return -self.b_min_mps2
        return 0.0


@dataclass
class FullBraking:
    """Brakes at ``decel_mps2`` (default 0.85 g, the CC driver's AEB) from the first step,
    whatever it sees: the best any driver could do by braking, for the inevitable-collision
    states of :mod:`sumo_ayss.scenarios.inevitable`."""

    decel_mps2: float = 0.85 * G_MPS2

    def __post_init__(self) -> None:
        _check("decel_mps2", self.decel_mps2, low=0.0, strict=True)

    def reset(self) -> None:
        """Stateless."""

    def acceleration(self, state: ControllerInput) -> float:
        del state
        return -self.decel_mps2
