"""The environment's sections: ``env`` and its ``sim``, ``actuator``, ``odd`` and ``reward``.

Every section is a frozen dataclass checked in ``__post_init__``; a bad value raises
:class:`~sumo_ayss.util.errors.ConfigError` naming the dotted field and the allowed values.

Units: lengths m, speeds m/s, accelerations m/s², times s. Sign convention: accelerations
are positive forward, braking is negative (the POV actuator bounds are ``[-6, 6]`` m/s²).
"""

from __future__ import annotations

import dataclasses
import typing
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar, Literal

from sumo_ayss.cases import DEFAULT_CASE, ROAD_EDGE, case_names, get_case
from sumo_ayss.config.follower import FollowerConfig
from sumo_ayss.util.errors import ConfigError
from sumo_ayss.util.frozen import FrozenMap
from sumo_ayss.util.validation import check_choice, check_range, check_sumo_network, require
from sumo_ayss.vuts.catalog import BUILTIN_VUTS, POV_TYPE, VehicleType

#: A registered case name (:mod:`sumo_ayss.cases`); checked against the registry.
Case = str
ShapeKind = Literal["linear", "quadratic", "exponential"]

#: Repository root (holds networks/, configs/, routes/) when running from a checkout.
PROJECT_ROOT = Path(__file__).resolve().parents[2]


#: SUMO options that sumo_ayss sets itself (sim/session.py), and where to change them.
MANAGED_SUMO_OPTIONS: dict[str, str] = {
    "net-file": "env.network",
    "n": "env.network",
    "additional-files": "env.vuts / env.pov",
    "a": "env.vuts / env.pov",
    "step-length": "env.sim.step_length_s",
    "seed": "the run's seed",
    "collision.action": "always warn: a collision ends the episode",
    "collision.mingap-factor": "env.sim.collision_mingap_factor",
    "lanechange.duration": "env.sim.lanechange_duration_s",
    "begin": "always 0",
    "default.action-step-length": (
        "env.vuts.<name>.params.actionStepLength (per VUT; the POV acts every step)"
    ),
    "step-method.ballistic": "env.sim.step_method",
}

StepMethod = Literal["auto", "euler", "ballistic"]

#: Field metadata key: :func:`~sumo_ayss.config.mapping.to_dict` leaves the field out while
#: it holds its default (an option added after runs were stored keeps their files and
#: identities as they were).
OMIT_DEFAULT = "omit_default"


def repr_omitting_defaults(obj: Any) -> str:
    """The dataclass ``repr`` of ``obj`` without its :data:`OMIT_DEFAULT` fields at their
    defaults: reprs key stored cross-play cells, which stay as they were before the field."""
    parts = [
        f"{f.name}={getattr(obj, f.name)!r}"
        for f in dataclasses.fields(obj)
        if f.repr and not (f.metadata.get(OMIT_DEFAULT) and getattr(obj, f.name) == f.default)
    ]
    return f"{type(obj).__qualname__}({', '.join(parts)})"


@dataclass(frozen=True)
class SimConfig:
    """How SUMO runs. Section ``env.sim``."""

    SECTION: ClassVar[str] = "env.sim"

    step_length_s: float = 0.2
    """SUMO step [s]; the policy acts every ``env.decision_period_s``."""
    lanechange_duration_s: float = 1.0
    """Duration of a POV lane change [s] (continuous lateral motion, ``--lanechange.duration``)."""
    lateral_resolution_m: float | None = None
    """SUMO's sublane model (``--lateral-resolution``) [m], or None (off). Needed by the
    highway-env POV in cut-in (free lateral positions); SUMO then ignores
    ``lanechange_duration_s`` (the two options exclude each other)."""
    collision_mingap_factor: float = 0.0
    """0: only physical overlap counts as a collision (SUMO's default flags a 0.3 m gap)."""
    extra_args: tuple[str, ...] = ()
    """Extra SUMO command-line arguments, appended verbatim."""
    step_method: StepMethod = "auto"
    """How SUMO integrates positions, for every vehicle of the simulation (a global of SUMO,
    ``--step-method.ballistic``): ``euler`` (SUMO's default, semi-implicit Euler),
    ``ballistic``, or ``auto``: ballistic exactly when a vehicle type the simulation loads has
    an ``actionStepLength`` other than the step, else Euler (:func:`integration_method`).

    ``auto`` is what SUMO itself does when the option is not given (SUMO 1.28,
    ``MSVehicleType.cpp``: a type whose action step differs from the step switches the whole
    simulation to ballistic "to avoid collisions"), so runs written before this option keep
    their numbers; the testbed now passes the resolved method explicitly, and a run's
    identity records it (:mod:`sumo_ayss.config.identity`): a catalog holding one VUT
    with a longer action step moves *every* vehicle of its studies ballistically."""

    def __post_init__(self) -> None:
        s = self.SECTION
        check_choice(f"{s}.step_method", self.step_method, typing.get_args(StepMethod))
        require(self.step_length_s > 0, f"{s}.step_length_s must be > 0, got {self.step_length_s}")
        require(
            self.lanechange_duration_s > 0,
            f"{s}.lanechange_duration_s must be > 0, got {self.lanechange_duration_s}",
        )
        require(
            self.lateral_resolution_m is None or self.lateral_resolution_m > 0,
            f"{s}.lateral_resolution_m must be > 0 or null, got {self.lateral_resolution_m}",
        )
        require(
            0 <= self.collision_mingap_factor <= 1,
            f"{s}.collision_mingap_factor must be in [0, 1], got {self.collision_mingap_factor}",
        )
        args = self.extra_args
        require(
            not args or str(args[0]).startswith("-"),
            f"{s}.extra_args must start with a SUMO option ('--name'), got {list(args)}",
        )
        for arg in args:
            name = str(arg).lstrip("-").split("=", 1)[0]
            if str(arg).startswith("-") and name in MANAGED_SUMO_OPTIONS:
                raise ConfigError(
                    f"{s}.extra_args: {arg!r} is set by sumo_ayss itself "
                    f"({MANAGED_SUMO_OPTIONS[name]}); remove it"
                )


def integration_method(sim: SimConfig, vtypes: Iterable[VehicleType]) -> str:
    """``"euler"`` or ``"ballistic"``: how SUMO moves every vehicle of a simulation that
    loads ``vtypes`` under ``sim`` (:attr:`SimConfig.step_method`; ``auto`` follows SUMO's
    own rule: ballistic when any loaded type's ``actionStepLength`` [s] differs from
    ``sim.step_length_s``)."""
    if sim.step_method != "auto":
        return sim.step_method
    dt = sim.step_length_s
    for vt in vtypes:
        length = vt.params.get("actionStepLength")
        if length is not None and abs(float(length) - dt) > 1e-9:
            return "ballistic"
    return "euler"


ActuatorMode = Literal["clipped", "highway_env"]


@dataclass(frozen=True)
class ActuatorConfig:
    """The POV's controller. Section ``env.actuator``.

    ``mode: clipped`` (default): ``a = clip((v_target - v) / time_constant_s, min, max)``,
    evaluated once per SUMO step; lane changes are SUMO's (constant lateral speed over
    ``env.sim.lanechange_duration_s``).

    ``mode: highway_env``: highway-env 1.8.2's ControlledVehicle (the paper's POV,
    :mod:`sumo_ayss.laws.hwenv`): ``a = (v_target - v) / time_constant_s`` **unclipped**,
    re-evaluated at each of ``substeps`` explicit-Euler sub-steps per SUMO step (3 per
    0.2 s = highway-env's 15 Hz), and its lane-centring steering loop on a kinematic
    bicycle for the cut-in (the lateral speed rises and decays smoothly, so Δv̄ depends
    on it as in highway-env). The POV's state is integrated in Python and put into SUMO
    exactly (``moveToXY``; cut-in needs SUMO's sublane model, ``env.sim.
    lateral_resolution_m``). ``accel_min_mps2``/``accel_max_mps2`` must keep their
    defaults there (highway-env does not clip); ``max_speed_mps`` is highway-env's
    ``MAX_SPEED`` soft cap.
    """

    SECTION: ClassVar[str] = "env.actuator"

    time_constant_s: float = 0.6
    """Speed-law time constant [s] (highway-env's ``TAU_ACC``)."""
    accel_min_mps2: float = -6.0
    accel_max_mps2: float = 6.0
    max_speed_mps: float = 40.0
    mode: ActuatorMode = "clipped"
    """``clipped`` (ours, default) or ``highway_env`` (highway-env's ControlledVehicle)."""
    substeps: int = 3
    """Euler sub-steps per SUMO step of highway-env's laws (POV in mode ``highway_env``,
    and any highway-env IDM VUT): 3 with a 0.2 s step = highway-env's 15 Hz."""
    tau_lateral_s: float = 0.6
    """highway-env ``TAU_LATERAL`` [s] (mode ``highway_env``)."""
    tau_heading_s: float = 0.2
    """highway-env ``TAU_HEADING`` [s] (mode ``highway_env``)."""
    lane_change_done_m: float = 0.1
    """Mode ``highway_env``: the POV counts as changing lanes (cut-in reward phase) until
    its centre is within this distance [m] of its target lane's centre line (highway-env's
    lateral loop approaches the centre line only asymptotically)."""

    def __post_init__(self) -> None:
        s = self.SECTION
        require(
            self.time_constant_s > 0, f"{s}.time_constant_s must be > 0, got {self.time_constant_s}"
        )
        require(
            self.accel_min_mps2 < 0 < self.accel_max_mps2,
            f"{s}.accel_min_mps2 must be < 0 < accel_max_mps2, got "
            f"[{self.accel_min_mps2}, {self.accel_max_mps2}]",
        )
        require(self.max_speed_mps > 0, f"{s}.max_speed_mps must be > 0, got {self.max_speed_mps}")
        check_choice(f"{s}.mode", self.mode, typing.get_args(ActuatorMode))
        require(
            isinstance(self.substeps, int) and self.substeps >= 1,
            f"{s}.substeps must be an integer >= 1, got {self.substeps!r}",
        )
        for name in ("tau_lateral_s", "tau_heading_s", "lane_change_done_m"):
            value = getattr(self, name)
            require(value > 0, f"{s}.{name} must be > 0, got {value}")
        if self.mode == "highway_env":
            require(
                (self.accel_min_mps2, self.accel_max_mps2) == (-6.0, 6.0),
                f"{s}.accel_min_mps2/accel_max_mps2 are not used in mode highway_env "
                "(highway-env's ControlledVehicle does not clip); remove them, got "
                f"[{self.accel_min_mps2}, {self.accel_max_mps2}]",
            )

    @property
    def highway_env(self) -> bool:
        """Whether the POV runs highway-env's ControlledVehicle."""
        return self.mode == "highway_env"


@dataclass(frozen=True)
class OddConfig:
    """Initial conditions are drawn uniformly from these ranges. Section ``env.odd``.

    Defaults: both speeds in [10, 30] m/s (30 m/s = the speed limit) and a bumper-to-bumper
    gap in [2, 25] m, so that most episodes start where the adversarial reward (zero beyond
    20 m) can be earned within the 5 s episode.
    """

    SECTION: ClassVar[str] = "env.odd"

    pov_speed_mps: tuple[float, float] = (10.0, 30.0)
    vut_speed_mps: tuple[float, float] = (10.0, 30.0)
    gap_m: tuple[float, float] = (2.0, 25.0)
    """Longitudinal gap POV rear bumper - VUT front bumper [m]."""
    exclude_inevitable: bool = field(default=False, metadata={OMIT_DEFAULT: True})
    """Draw again every start that is an inevitable collision (the case's own conservative
    check, :attr:`~sumo_ayss.cases.Case.start_filter`; ``lead_and_cut_in`` only). Stored
    only when true, so runs written before the option keep their ``config.yaml``/identity."""

    def __post_init__(self) -> None:
        for name in ("pov_speed_mps", "vut_speed_mps", "gap_m"):
            value = check_range(f"{self.SECTION}.{name}", getattr(self, name), low=0.0)
            object.__setattr__(self, name, value)
        require(
            isinstance(self.exclude_inevitable, bool),
            f"{self.SECTION}.exclude_inevitable must be true or false, "
            f"got {self.exclude_inevitable!r}",
        )

    __repr__ = repr_omitting_defaults


@dataclass(frozen=True)
class RewardShape:
    """Adversarial reward R_A as a function of headway h [m], 0 <= R_A <= 1.

    ``R_A(peak_m) = 1``; for ``h >= zero_m`` it is 0; between the two it falls as
    ``1 - u`` (linear), ``(1 - u)²`` (quadratic) or ``exp(-3u)`` rescaled to reach 0 at
    ``u = 1`` (exponential), with ``u = (h - peak_m) / (zero_m - peak_m)``. Below the peak it
    rises linearly from ``value_at_contact`` at h = 0 to 1 at the peak. The paper shows these
    curves only as figures; the defaults are ours and are drawn in ``docs/reward_shapes.png``.
    """

    kind: ShapeKind = "linear"
    peak_m: float = 0.25
    zero_m: float = 20.0
    value_at_contact: float = 0.5

    def validate(self, where: str) -> None:
        check_choice(f"{where}.kind", self.kind, typing.get_args(ShapeKind))
        require(self.peak_m >= 0, f"{where}.peak_m must be >= 0, got {self.peak_m}")
        require(
            self.zero_m > self.peak_m,
            f"{where}.zero_m must be > peak_m ({self.peak_m}), got {self.zero_m}",
        )
        require(
            0 <= self.value_at_contact <= 1,
            f"{where}.value_at_contact must be in [0, 1], got {self.value_at_contact}",
        )


@dataclass(frozen=True)
class RewardConfig:
    """R = alpha_adversarial·R_A + alpha_collision·R_C with R_C = -1 on a collision, else 0.

    A collision therefore gets the minimum reward ``-alpha_collision`` (R_A is 0 then) and
    ends the episode. Section ``env.reward``.
    """

    SECTION: ClassVar[str] = "env.reward"

    alpha_adversarial: float = 1.0
    alpha_collision: float = 10.0
    same_lane: RewardShape = field(default_factory=RewardShape)
    """R_A while POV and VUT share a lane (car-following, and cut-in after the change)."""
    lane_change: RewardShape = field(
        default_factory=lambda: RewardShape(peak_m=1.0, zero_m=5.0, value_at_contact=0.5)
    )
    """R_A while the POV changes lanes (cut-in only)."""
    pov_failure_penalty: float = field(default=0.0, metadata={OMIT_DEFAULT: True})
    """A case with two POVs (``lead_and_cut_in``): the further cost of a forbidden contact
    (the POVs' failure), in units of ``alpha_collision``, on top of the POVs' safe terms.
    Stored only when not 0 (runs written before it keep their identity)."""

    __repr__ = repr_omitting_defaults

    def __post_init__(self) -> None:
        s = self.SECTION
        require(
            self.pov_failure_penalty >= 0,
            f"{s}.pov_failure_penalty must be >= 0, got {self.pov_failure_penalty}",
        )
        require(
            self.alpha_adversarial > 0,
            f"{s}.alpha_adversarial must be > 0, got {self.alpha_adversarial}",
        )
        require(
            self.alpha_collision > 0, f"{s}.alpha_collision must be > 0, got {self.alpha_collision}"
        )
        self.same_lane.validate(f"{s}.same_lane")
        self.lane_change.validate(f"{s}.lane_change")

    @property
    def min_reward(self) -> float:
        """The reward of a collision step (the smallest reward there is)."""
        return -self.alpha_collision

    @property
    def max_reward(self) -> float:
        return self.alpha_adversarial


@dataclass(frozen=True)
class EnvConfig:
    """One testing environment: case, VUT, timing, ODD, reward, actuator and SUMO options."""

    SECTION: ClassVar[str] = "env"

    case: Case = DEFAULT_CASE
    """A registered case (:func:`sumo_ayss.cases.case_names`)."""
    vut: str = "pi1"
    """Name of the VUT in ``vuts`` (built-ins: pi1, pi2)."""
    vuts: Mapping[str, VehicleType] = field(default_factory=lambda: dict(BUILTIN_VUTS))
    """VUT catalog: the built-ins plus any defined in YAML."""
    pov: VehicleType = POV_TYPE
    episode_s: float = 5.0
    decision_period_s: float = 0.2
    """Policy period [s] (5 Hz in the paper); a multiple of ``sim.step_length_s``."""
    network: Path | None = None
    """SUMO .net.xml; None = the built-in network of the case."""
    odd: OddConfig = field(default_factory=OddConfig)
    reward: RewardConfig = field(default_factory=RewardConfig)
    actuator: ActuatorConfig = field(default_factory=ActuatorConfig)
    sim: SimConfig = field(default_factory=SimConfig)
    follower: FollowerConfig = field(default_factory=FollowerConfig)
    """A SUMO-driven follower behind the VUT (off by default: :mod:`~sumo_ayss.config.
    follower`)."""

    def __post_init__(self) -> None:
        s = self.SECTION
        check_choice(f"{s}.case", self.case, case_names())
        object.__setattr__(self, "vuts", FrozenMap(self.vuts))
        for name, vt in self.vuts.items():
            vt.validate(f"{s}.vuts.{name}")
        self.pov.validate(f"{s}.pov")
        self._check_action_steps()
        check_choice(f"{s}.vut", self.vut, sorted(self.vuts))
        require(self.episode_s > 0, f"{s}.episode_s must be > 0, got {self.episode_s}")
        ratio = self.decision_period_s / self.sim.step_length_s
        require(
            self.decision_period_s > 0 and abs(ratio - round(ratio)) < 1e-9 and round(ratio) >= 1,
            f"{s}.decision_period_s must be a positive multiple of sim.step_length_s "
            f"({self.sim.step_length_s}), got {self.decision_period_s}",
        )
        require(
            not self.actuator.highway_env or round(ratio) == 1,
            f"{s}.decision_period_s must equal sim.step_length_s with env.actuator.mode "
            f"highway_env (one SUMO step per decision, {self.actuator.substeps} highway-env "
            f"sub-steps inside it: actuator.substeps), got {self.decision_period_s} and "
            f"{self.sim.step_length_s}",
        )
        require(
            not (
                self.actuator.highway_env
                and get_case(self.case).lane_change
                and self.sim.lateral_resolution_m is None
            ),
            f"{s}.sim.lateral_resolution_m must be set (e.g. 0.1) with env.actuator.mode "
            f"highway_env in {self.case}: the POV's free lateral position needs SUMO's "
            "sublane model",
        )
        if self.network is not None:
            path = Path(self.network)
            object.__setattr__(self, "network", path)
            require(path.is_file(), f"{s}.network: file not found: {path}")
            lanes = get_case(self.case).lanes
            check_sumo_network(path, f"{s}.network", ROAD_EDGE, lanes, self.case)
        require(
            not self.reward.pov_failure_penalty or get_case(self.case).povs > 1,
            f"{s}.reward.pov_failure_penalty: case {self.case!r} has one POV (no forbidden "
            "contact to penalise)",
        )
        require(
            not self.odd.exclude_inevitable or bool(get_case(self.case).start_filter),
            f"{s}.odd.exclude_inevitable: case {self.case!r} has no inevitable-start check "
            f"(cases with one: {[c for c in case_names() if get_case(c).start_filter]})",
        )
        top = self.actuator.max_speed_mps
        require(
            self.odd.pov_speed_mps[1] <= top,
            f"{s}.odd.pov_speed_mps max ({self.odd.pov_speed_mps[1]}) must be <= "
            f"env.actuator.max_speed_mps ({top}): the POV could not drive its initial speed",
        )

    def _check_action_steps(self) -> None:
        """SUMO's ``actionStepLength`` only as a whole number of steps, and not for the POV.

        SUMO rounds an action step that is not a multiple of the step length (a warning the
        testbed's SUMO never prints) and drives a vehicle with ``actionStepLength`` below
        the step at the step length; the POV is moved by the testbed's actuator every step.
        A VUT is refused here rather than simulated with another action step than it names.
        """
        s, dt = self.SECTION, self.sim.step_length_s
        for name, vt in self.vuts.items():
            length = vt.params.get("actionStepLength")
            if length is None:
                continue
            ratio = float(length) / dt
            require(
                abs(ratio - round(ratio)) < 1e-9 and round(ratio) >= 1,
                f"{s}.vuts.{name}.params.actionStepLength must be a whole multiple of "
                f"env.sim.step_length_s ({dt} s: {dt}, {2 * dt:g}, {3 * dt:g}, ...), got "
                f"{length} (SUMO would round it without a word)",
            )
        require(
            "actionStepLength" not in self.pov.params,
            f"{s}.pov.params.actionStepLength is not allowed: the POV is driven by the "
            "testbed's actuator every SUMO step (env.actuator), not by SUMO's driver model",
        )

    @property
    def vut_type(self) -> VehicleType:
        return self.vuts[self.vut]

    @property
    def integration(self) -> str:
        """``"euler"`` or ``"ballistic"``: how SUMO moves every vehicle of a simulation of
        this env, which loads the whole catalog and the POV (:func:`integration_method`;
        the follower may not set an action step)."""
        return integration_method(self.sim, [*self.vuts.values(), self.pov])

    def sim_key(self, own: Iterable[VehicleType]) -> dict[str, Any]:
        """``env.sim`` as a fingerprint over the types ``own`` records it: ``step_method``
        resolved (:attr:`integration`), and recorded, as ``integration``, only where it is
        not what ``own`` and the POV alone imply under ``auto``. So a record whose own
        types set the method (a VUT with a longer action step) reads as it was written
        before the option, and a catalog that moves a run's VUT otherwise than it alone
        would (pi1 beside a reaction VUT) is part of the key."""
        data = dataclasses.asdict(self.sim)
        data.pop("step_method")
        auto = SimConfig(step_length_s=self.sim.step_length_s)
        implied = integration_method(auto, [*own, self.pov])
        if self.integration != implied:
            data["integration"] = self.integration
        return data

    @property
    def steps_per_decision(self) -> int:
        return round(self.decision_period_s / self.sim.step_length_s)

    @property
    def max_decisions(self) -> int:
        """Decisions per episode (25 for 5 s at 5 Hz)."""
        return round(self.episode_s / self.decision_period_s)


def decisions_of(env: Mapping[str, Any]) -> int:
    """Decisions per episode of a stored env section (a run's ``config.yaml``):
    ``episode_s / decision_period_s`` rounded (:class:`EnvConfig`'s defaults where unset).

    Raises:
        ConfigError: If the timing gives no decision.
    """
    episode_s = float(env.get("episode_s", EnvConfig.episode_s))
    period_s = float(env.get("decision_period_s", EnvConfig.decision_period_s))
    decisions = round(episode_s / period_s)
    if decisions < 1:
        raise ConfigError(f"env: {episode_s} s episodes of {period_s} s decisions: no decision")
    return decisions
