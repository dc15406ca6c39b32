"""The cut-in criterion of UN Regulation No. 157 (ALKS): which cut-ins must be handled.

UN R157 (Automated Lane Keeping Systems), paragraph 5.2.5.2, requires the system to avoid
a collision with a vehicle cutting in when the time to collision at the moment of the
lane intrusion exceeds a bound set by the relative speed:

    TTC_LaneIntrusion > v_rel / (2 · 6 m/s²) + 0.35 s

with ``v_rel`` the relative speed, positive when the ALKS vehicle is faster than the
cutting-in vehicle, and TTC_LaneIntrusion read when the cutting-in vehicle's front wheel
nearest the lane marking is 0.3 m beyond it, inside the ALKS vehicle's lane.

Source, and its limits: the regulation's own text could not be retrieved here. The formula
and the 0.3 m intrusion point are taken from two independent implementations of the
regulation that cite it: esmini's R157 controller
(``esmini/esmini``, ``EnvironmentSimulator/Modules/Controllers/ControllerALKS_R157SM.cpp``,
written with IDIADA: "TTCLaneIntrusion > vrel / (2 x 6 ms^2) + 0.35s" and "front wheel has
moved 0.3 meter inside own vehicle's lane") and the European Commission JRC's
``ec-jrc/JRC-FSM`` (``utility/models.py``, model "Reg157", citing "Reg 157 5.2.5.2": TTC >
dv / (2 · Reg157_max_deceleration) + Reg157_rt, with ``Reg157_max_deceleration = 6`` and
``Reg157_rt = 0.35`` in ``utility/vehicle.py``; one version of its check adds a further
0.1 s margin). The constant term is a parameter (``report.r157_time_s``): the default is
the regulation's 0.35 s as the implementations' comments quote it; the report also shows
the share with :data:`R157_TIME_MARGIN_S` (0.45 s = 0.35 + 0.1, as esmini's
``ControllerALKS_R157SM.cpp`` critical check and JRC-FSM's ``Reg157_check_safety_cut_in``
compute it). What is applied:

* the intrusion point is the POV's body side 0.3 m inside the VUT's lane (the body side
  stands in for the outside of the front tyre, which our rectangles do not model);
* a cut-in "must be avoided" when the VUT closes in at that moment (``v_rel > 0``) and its
  TTC exceeds the bound;
* the regulation's further conditions on the cut-in (e.g. on the cutting-in vehicle's
  speed after the cut-in; its lateral motion) are *not* applied, since their text was not
  available: our POV may brake after cutting in, which the regulation's cut-in may not
  allow, so a cut-in counted here as "must be handled" can be harder than the
  regulation's. Read the share as "handled among those R157's TTC condition says must be
  handled", nothing more.

Imports neither SUMO nor torch; reads no file.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

__all__ = [
    "R157_DECEL_MPS2",
    "R157_INTRUSION_DEPTH_M",
    "R157_TIME_MARGIN_S",
    "R157_TIME_S",
    "R157Share",
    "must_avoid",
    "must_avoid_column",
    "r157_share",
    "required_ttc_s",
]

#: Depth [m] of the intrusion at which TTC_LaneIntrusion is read (front wheel 0.3 m inside).
R157_INTRUSION_DEPTH_M = 0.3
#: Deceleration [m/s²] in the bound's relative-speed term, v_rel / (2 · 6 m/s²).
R157_DECEL_MPS2 = 6.0
#: Constant term [s] of the bound (0.35 s).
R157_TIME_S = 0.35
#: The constant with the implementations' further 0.1 s margin (esmini, JRC-FSM).
R157_TIME_MARGIN_S = 0.45


def required_ttc_s(v_rel_mps: float, time_s: float = R157_TIME_S) -> float:
    """The bound ``v_rel / (2 · 6 m/s²) + time_s`` [s] for a relative speed [m/s] > 0."""
    return v_rel_mps / (2.0 * R157_DECEL_MPS2) + time_s


def must_avoid(ttc_lane_intrusion_s: float, v_rel_mps: float, time_s: float = R157_TIME_S) -> float:
    """Whether R157's TTC condition says this cut-in's collision must be avoided.

    Args:
        ttc_lane_intrusion_s: TTC [s] at the 0.3 m intrusion (NaN: no such intrusion).
        v_rel_mps: ``v_vut - v_pov`` [m/s] then, > 0 when the VUT is faster.
        time_s: The bound's constant term [s] (0.35; 0.45 with the implementations' margin).

    Returns:
        1.0 (must be avoided), 0.0 (the condition does not hold: not closing in, or the
        TTC is at or below the bound), NaN without an intrusion.
    """
    if math.isnan(ttc_lane_intrusion_s) or math.isnan(v_rel_mps):
        return math.nan
    if v_rel_mps <= 0.0:
        return 0.0
    return 1.0 if ttc_lane_intrusion_s > required_ttc_s(v_rel_mps, time_s) else 0.0


def must_avoid_column(
    ttc_s: ArrayLike, closing_mps: ArrayLike, stored: ArrayLike, time_s: float = R157_TIME_S
) -> np.ndarray:
    """``must_avoid`` of every episode with the constant ``time_s``, from the TTC and the
    closing speed at the intrusion; where the closing speed was not recorded (tables
    written before ``r157_closing_mps``) the ``stored`` value (made with 0.35 s) is kept
    when ``time_s`` is 0.35 s, else NaN (not known)."""
    ttc = np.asarray(ttc_s, dtype=float)
    closing = np.asarray(closing_mps, dtype=float)
    old = np.asarray(stored, dtype=float)
    out = np.array([must_avoid(t, c, time_s) for t, c in zip(ttc, closing, strict=True)])
    unknown = np.isnan(closing) & ~np.isnan(ttc)
    fallback = old if time_s == R157_TIME_S else np.full(old.shape, math.nan)
    out[unknown] = fallback[unknown]
    return out


@dataclass(frozen=True)
class R157Share:
    """Cut-ins R157 says must be handled, and how many of them ended without a collision.

    Attributes:
        n_required: Episodes with ``r157_must_avoid == 1``.
        n_handled: Of those, episodes without a collision.
        share: ``n_handled / n_required`` (NaN when none was required).
    """

    n_required: int
    n_handled: int

    @property
    def share(self) -> float:
        return self.n_handled / self.n_required if self.n_required else math.nan


def r157_share(must: ArrayLike, collided: ArrayLike) -> R157Share:
    """The :class:`R157Share` of a set of episodes (``must`` may hold NaN: not counted)."""
    m = np.asarray(must, dtype=float)
    c = np.asarray(collided, dtype=bool)
    required = m == 1.0
    return R157Share(int(required.sum()), int((required & ~c).sum()))
