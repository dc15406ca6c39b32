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

from sumo_ayss.vuts.reference.careful import CarefulDriver, braking_distance_m
from sumo_ayss.vuts.reference.common import G_MPS2, OWN_WIDTH_M
from sumo_ayss.vuts.reference.fsm import FuzzySafetyDriver
from sumo_ayss.vuts.reference.rss import (
    FullBraking,
    RssDriver,
    rss_lateral_safe_distance_m,
    rss_safe_distance_m,
)

__all__ = [
    "G_MPS2",
    "OWN_WIDTH_M",
    "CarefulDriver",
    "FullBraking",
    "FuzzySafetyDriver",
    "RssDriver",
    "braking_distance_m",
    "rss_lateral_safe_distance_m",
    "rss_safe_distance_m",
]
