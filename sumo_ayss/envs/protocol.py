"""The episode-phase protocol: an env's ``reset`` and ``step`` cut at their SUMO steps.

A :class:`~sumo_ayss.envs.pair_env.PairEnv` (``CarFollowingEnv``, ``CutInEnv``) builds its
Gymnasium ``reset`` and ``step`` from the phases below, around SUMO steps it runs itself.
:class:`~sumo_ayss.envs.vec_env.PairVecEnv` hosts N such envs in one simulation by calling the
same phases of every member around one *shared* SUMO step, so observation, reward,
termination and the POV's actuator are one piece of code in both. Anything that implements
:class:`EpisodePhases` can be a vec-env member.

Order of calls, per env (the single env and a vec-env member alike)::

    join_shared(pair, sumo_seed)          # once, vec-env members only, before anything else

    # an episode start (reset)
    ic = begin_reset(seed, options)       # seed the env's RNG, choose the initial condition
    <pair.add()>                           # the caller: remove old vehicles, add two fresh ones
    <single env: one SUMO step>            # (inserts them; the vec env places them unstepped)
    values, info = start_episode(ic)      # place the vehicles at ic: first observation

    # a decision (step), decision_period_s = steps_per_decision SUMO steps
    begin_decision(action)                # validate and apply the action
    repeat steps_per_decision times:
        command_pov()                     # command the POV (and a controller VUT) for 1 step
        <one SUMO step>                    # the caller's (shared in the vec env)
        <stop early if the pair collided>
    values, reward, terminated, truncated, info = end_decision(collided)

Units: SUMO steps last ``env.sim.step_length_s`` [s]; a decision ``decision_period_s`` [s];
an episode at most ``episode_s`` [s]. Observation values are plain floats in the env's
observation-space units (speeds [m/s], distances [m]); the reward is dimensionless.
"""

from __future__ import annotations

from typing import Any, Protocol, SupportsInt, runtime_checkable

from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.sim.pair import VehiclePair

#: One decision's result: ``(observation values, reward, terminated, truncated, info)``.
StepResult = tuple[tuple[float, ...], float, bool, bool, dict[str, Any]]


@runtime_checkable
class EpisodePhases(Protocol):
    """The phases of one VUT-POV env, in the order of the module docstring."""

    def join_shared(self, pair: VehiclePair, sumo_seed: int) -> None:
        """Become a member of a vec env: drive ``pair`` in a simulation the env does not own.

        Called once, before the first :meth:`begin_reset`. The env's own ``reset``/``step``
        refuse to run from then on (each would step every pair of the shared simulation).

        Args:
            pair: The member's two vehicles (on its own road) in the shared simulation.
            sumo_seed: The shared simulation's SUMO ``--seed`` (reported in ``info``).
        """
        ...

    def begin_reset(self, seed: int | None, options: dict[str, Any] | None) -> InitialCondition:
        """Seed the env's RNG (``seed``) and choose the episode's initial condition.

        Args:
            seed: Seeds the env's RNG (ODD sampling); None keeps it going.
            options: ``{"initial_condition": InitialCondition}`` to start from a given state
                (not drawn from the RNG), else None.

        Returns:
            The episode's initial condition (gap [m], speeds [m/s], ...).
        """
        ...

    def start_episode(self, ic: InitialCondition) -> tuple[tuple[float, ...], dict[str, Any]]:
        """Place the pair's fresh vehicles at ``ic`` (after they were added).

        Returns:
            The first observation's values and the reset's ``info``.
        """
        ...

    def begin_decision(self, action: SupportsInt) -> None:
        """Validate and apply ``action`` (lane commands, the POV's target speed [m/s]).

        Raises:
            ActionError: The action is outside the action space.
        """
        ...

    def command_pov(self) -> None:
        """Command the POV's speed [m/s] (and a controller VUT's) for the coming SUMO step."""
        ...

    def end_decision(self, collided: bool) -> StepResult:
        """Read SUMO back after the decision's SUMO steps.

        Args:
            collided: The pair collided in the last SUMO step (the decision ended there).

        Returns:
            ``(observation values, reward, terminated, truncated, info)``; terminated at a
            collision, truncated after the episode's last decision.
        """
        ...
