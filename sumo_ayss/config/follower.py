"""The follower behind the VUT: section ``env.follower`` (issue 33).

A non-adversarial car driven by SUMO behind the VUT in its lane, so that what the VUT does
to the traffic behind it (hard braking, a rear-end collision) can be measured. It is part of
the *scenario*: its start is drawn with the scenario set (:func:`~sumo_ayss.envs.odd.
with_followers`), the same for every VUT on the same scenario, and it never changes the
VUT-POV episode (the VUT's and the POV's laws do not look behind; a rear-end collision is
recorded, not a VUT-POV crash; ``tests/envs/test_follower.py`` checks both).

Default driver, a careful-but-ordinary human in SUMO's terms (each number's source):

* SUMO's Extended IDM (EIDM: Salles, Kaufmann, Reuss (2020), *Extending the Intelligent
  Driver Model in SUMO and Verifying the Drive Off Trajectories with Aerial Measurements*,
  SUMO User Conference), the IDM (Treiber, Hennecke, Helbing 2000) with a reaction time;
* ``reaction_s`` = 1.0 s, written as EIDM's ``treaction``: the issue's "reaction time near
  1 s", between the R157 careful driver's 0.75 s and its 1.15 s with risk perception
  (``../shared/research/reference-drivers.md`` §1.1). Measured: behind a VUT that brakes at
  6 m/s² from the first step it held its acceleration for 0.4 s and braked from the third
  step (IDM without it: from the first);
* ``tau`` 1.5 s (IDM's desired time headway T for car drivers on a motorway, Treiber et al.
  2000), ``delta`` 4, ``accel`` 2.6, ``decel`` 4.5 (its comfortable braking b),
  ``emergencyDecel`` 9.0 m/s², ``minGap`` 2.5 m, length 5 m: SUMO's passenger-car defaults;
* no randomness (EIDM's ``sigmaleader``, ``sigmagap``, ``sigmaerror`` and ``speedDev`` 0):
  the follower is the same vehicle for every VUT, and it draws nothing from SUMO's random
  streams. Measured on SUMO 1.28: a Krauss follower (which draws even at ``sigma`` 0)
  shifted a stochastic VUT's draws, and any vehicle with an ``actionStepLength`` above the
  SUMO step changed how SUMO moved the VUT and the POV (0.12 m in the first step); EIDM's
  ``treaction`` does neither (``tests/envs/test_follower.py``).

Its start (the follower ODD): the VUT's initial speed (it was following it) at a time
headway drawn uniformly from ``time_headway_s`` = [1.0, 2.0] s behind the VUT's rear bumper:
1 s is a short but common motorway headway, 2 s the "two-second rule" and about the UN R157
minimum following time gap at 100 km/h (1.0 + v[km/h]/100 s, reference-drivers.md §1.3).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

from sumo_ayss.util.errors import ConfigError
from sumo_ayss.util.validation import check_range, require
from sumo_ayss.vuts.catalog import VehicleType

__all__ = ["FOLLOWER_TYPE", "REACTION_PARAM", "FollowerConfig"]

#: The default follower's vehicle type (without its reaction time: ``reaction_s``).
FOLLOWER_TYPE = VehicleType(
    model="EIDM",
    params={
        "length": 5.0,
        "minGap": 2.5,
        "accel": 2.6,
        "decel": 4.5,
        "emergencyDecel": 9.0,
        "tau": 1.5,
        "delta": 4.0,
        "sigmaleader": 0.0,
        "sigmagap": 0.0,
        "sigmaerror": 0.0,
        "speedDev": 0.0,
    },
    description="follower: SUMO EIDM, a human-like driver with a 1 s reaction",
)

#: The SUMO parameter that holds a model's reaction time (``reaction_s``).
REACTION_PARAM: dict[str, str] = {"EIDM": "treaction"}


@dataclass(frozen=True)
class FollowerConfig:
    """A SUMO-driven follower behind the VUT. Section ``env.follower``.

    Off by default in code, so every run folder written before it reads as it ran ("no
    follower"); the shipped configs turn it on for new studies (``configs/*.yaml``).
    """

    SECTION: ClassVar[str] = "env.follower"

    enabled: bool = False
    """Put a follower behind the VUT in the evaluation episodes (outcome, cross-play)."""
    vtype: VehicleType = field(default_factory=lambda: FOLLOWER_TYPE)
    """Its SUMO vehicle type: any SUMO car-following model (not a controller)."""
    reaction_s: float = 1.0
    """Its reaction time [s], written as the model's reaction parameter
    (:data:`REACTION_PARAM`: EIDM's ``treaction``)."""
    time_headway_s: tuple[float, float] = (1.0, 2.0)
    """Its initial time headway to the VUT [s], drawn uniformly: gap = headway × the VUT's
    initial speed (VUT rear bumper minus follower front bumper); both > 0."""

    def __post_init__(self) -> None:
        s = self.SECTION
        if not isinstance(self.enabled, bool):
            raise ConfigError(f"{s}.enabled must be true or false, got {self.enabled!r}")
        if not isinstance(self.vtype, VehicleType):
            raise ConfigError(f"{s}.vtype must be a vehicle type, got {self.vtype!r}")
        require(
            self.vtype.controller is None,
            f"{s}.vtype must be a SUMO car-following model (model + params), not a "
            "controller: the follower is SUMO's human-like driver",
        )
        require(
            self.vtype.model in REACTION_PARAM,
            f"{s}.vtype.model must be one of {sorted(REACTION_PARAM)} (a SUMO model with a "
            f"reaction time, {s}.reaction_s), got {self.vtype.model!r}",
        )
        self.vtype.validate(f"{s}.vtype")
        for name in (REACTION_PARAM[self.vtype.model], "actionStepLength"):
            require(
                name not in self.vtype.params,
                f"{s}.vtype.params.{name}: give the reaction time as {s}.reaction_s (an "
                "action step longer than the SUMO step changes how SUMO moves the others)",
            )
        r = self.reaction_s
        ok = isinstance(r, int | float) and not isinstance(r, bool)
        require(ok and r > 0, f"{s}.reaction_s must be a number > 0 [s], got {r!r}")
        thw = check_range(f"{s}.time_headway_s", self.time_headway_s)
        require(
            thw[0] > 0,
            f"{s}.time_headway_s must be > 0 s (0 or less starts the follower inside the "
            f"VUT), got {list(thw)}",
        )
        object.__setattr__(self, "time_headway_s", thw)

    @property
    def sumo_type(self) -> VehicleType:
        """The vehicle type SUMO loads: :attr:`vtype` with its reaction parameter set to
        :attr:`reaction_s`."""
        params = {**self.vtype.params, REACTION_PARAM[self.vtype.model]: float(self.reaction_s)}
        return VehicleType(self.vtype.model, params, self.vtype.description)

    def key(self) -> dict[str, object]:
        """What of the follower an evaluation's result depends on (its stage fingerprint)."""
        return {
            "model": self.vtype.model,
            "params": dict(sorted(self.vtype.params.items())),
            "reaction_s": float(self.reaction_s),
            "time_headway_s": list(self.time_headway_s),
        }
