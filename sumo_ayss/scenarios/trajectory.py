"""Record an episode's trajectory from the env's step infos, for its safety measures.

:func:`~sumo_ayss.scenarios.rollout.run_episode` hands the reset's info and every step's
info to :func:`trajectory_from_infos`, which builds the
:class:`~sumo_ayss.analysis.safety_measures.PairTrajectory` that
:func:`~sumo_ayss.analysis.safety_measures.episode_measures` reduces to one row of
measures. Nothing extra is read from SUMO: the env's infos already carry the front-bumper
positions and speeds (:class:`~sumo_ayss.envs.pair_env.PairEnv`), and in cut-in the
lateral positions and speeds and the boundary of the VUT's lane
(:class:`~sumo_ayss.envs.cut_in.CutInEnv`). In car-following both vehicles stay on the one
lane's centre line (lateral position 0, no lateral speed).

Sample ``k`` is the state after ``k`` decisions, at ``k · decision_period_s`` (0 = the
reset). With several SUMO steps per decision (``sim.step_length_s`` below the decision
period) a collision ends its decision early, at a SUMO step the infos do not name: the last
sample's time is then the decision's end, up to one decision late (the default, one SUMO
step per decision, is exact).

Body widths come from the vehicle types, SUMO's default 1.8 m where a type gives none
(SUMO's vType ``width`` default for passenger cars; a test checks it against SUMO).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from typing import Any, NamedTuple

import numpy as np

from sumo_ayss.analysis.hazards import FollowerTrack, HazardMeasures, episode_hazards
from sumo_ayss.analysis.safety_measures import EpisodeMeasures, PairTrajectory, episode_measures
from sumo_ayss.config import EnvConfig
from sumo_ayss.vuts.catalog import VehicleType

__all__ = [
    "SUMO_DEFAULT_WIDTH_M",
    "body_width_m",
    "follower_of",
    "hazards_of",
    "measures_of",
    "trajectory_from_infos",
]

#: SUMO's default vType width [m] (passenger class), used when a type gives none.
SUMO_DEFAULT_WIDTH_M = 1.8


def body_width_m(vtype: VehicleType) -> float:
    """The body width [m] SUMO gives a vehicle of ``vtype``."""
    return float(vtype.params.get("width", SUMO_DEFAULT_WIDTH_M))


def trajectory_from_infos(
    config: EnvConfig, reset_info: Mapping[str, Any], infos: Sequence[Mapping[str, Any]]
) -> PairTrajectory:
    """The trajectory of one episode of an env of ``config``.

    Args:
        config: The env's configuration (decision period, vehicle types).
        reset_info: The info returned by ``reset``.
        infos: The info of each step, in order.
    """
    samples = [reset_info, *infos]
    n = len(samples)

    def col(key: str, default: float | None = None) -> np.ndarray:
        if default is not None and key not in reset_info:
            return np.full(n, default)
        return np.array([float(s[key]) for s in samples])

    edge = reset_info.get("vut_lane_edge_y_m")
    return PairTrajectory(
        time_s=np.arange(n, dtype=np.float64) * config.decision_period_s,
        vut_x_m=col("vut_pos_m"),
        pov_x_m=col("pov_pos_m"),
        vut_y_m=col("vut_y_m", 0.0),
        pov_y_m=col("pov_y_m", 0.0),
        vut_speed_mps=col("vut_speed_mps"),
        pov_speed_mps=col("pov_speed_mps"),
        vut_lat_speed_mps=col("vut_lateral_speed_mps", 0.0),
        pov_lat_speed_mps=col("pov_lateral_speed_mps", 0.0),
        collided=bool(infos[-1]["collision"]) if infos else False,
        vut_length_m=config.vut_type.length_m,
        pov_length_m=config.pov.length_m,
        vut_width_m=body_width_m(config.vut_type),
        pov_width_m=body_width_m(config.pov),
        vut_lane_edge_y_m=None if edge is None else float(edge),
    )


def measures_of(
    config: EnvConfig, reset_info: Mapping[str, Any], infos: Sequence[Mapping[str, Any]]
) -> EpisodeMeasures:
    """The safety measures of one episode (:func:`trajectory_from_infos`, then
    :func:`~sumo_ayss.analysis.safety_measures.episode_measures`)."""
    return episode_measures(trajectory_from_infos(config, reset_info, infos))


def follower_of(
    reset_info: Mapping[str, Any], infos: Sequence[Mapping[str, Any]]
) -> FollowerTrack | None:
    """The follower's samples of one episode, or None when it had none."""
    if "follower_pos_m" not in reset_info:
        return None
    samples = [reset_info, *infos]
    return FollowerTrack(
        x_m=np.array([float(s["follower_pos_m"]) for s in samples]),
        speed_mps=np.array([float(s["follower_speed_mps"]) for s in samples]),
        rear_end=bool(samples[-1]["rear_end"]),
    )


def hazards_of(
    config: EnvConfig, reset_info: Mapping[str, Any], infos: Sequence[Mapping[str, Any]]
) -> HazardMeasures:
    """The hazards the VUT caused in one episode
    (:func:`~sumo_ayss.analysis.hazards.episode_hazards`)."""
    tr = trajectory_from_infos(config, reset_info, infos)
    support = support_trajectory(config, reset_info, infos)
    others = () if support is None else (support,)
    return episode_hazards(tr, follower_of(reset_info, infos), others)


class SecondPovTrack(NamedTuple):
    """A second POV's samples over one episode (case ``lead_and_cut_in``): front-bumper
    lane position [m], world y of the front bumper's centre [m], speed [m/s]."""

    x_m: np.ndarray
    y_m: np.ndarray
    speed_mps: np.ndarray


def second_pov_of(
    reset_info: Mapping[str, Any], infos: Sequence[Mapping[str, Any]]
) -> SecondPovTrack | None:
    """The second (supporting) POV's samples of one episode, or None when it had none."""
    if "support_pos_m" not in reset_info:
        return None
    samples = [reset_info, *infos]

    def col(key: str) -> np.ndarray:
        return np.array([float(s[key]) for s in samples])

    return SecondPovTrack(col("support_pos_m"), col("support_y_m"), col("support_speed_mps"))


def support_measures_of(
    config: EnvConfig, reset_info: Mapping[str, Any], infos: Sequence[Mapping[str, Any]]
) -> EpisodeMeasures | None:
    """The safety measures of the VUT against the supporting POV (the case's second POV,
    in the POV's body), or None in a case with one POV: the measures per POV (issue 39)."""
    tr = support_trajectory(config, reset_info, infos)
    return None if tr is None else episode_measures(tr)


def support_trajectory(
    config: EnvConfig, reset_info: Mapping[str, Any], infos: Sequence[Mapping[str, Any]]
) -> PairTrajectory | None:
    """The episode as a pair of the VUT and the supporting POV (in the POV's fields), or
    None in a case with one POV."""
    track = second_pov_of(reset_info, infos)
    if track is None:
        return None
    samples = [reset_info, *infos]
    lateral = np.array([float(s.get("support_lateral_speed_mps", 0.0)) for s in samples])
    return dataclasses.replace(
        trajectory_from_infos(config, reset_info, infos),
        pov_x_m=track.x_m,
        pov_y_m=track.y_m,
        pov_speed_mps=track.speed_mps,
        pov_lat_speed_mps=lateral,
        collided=bool(infos[-1].get("support_vut_contact", False)) if infos else False,
    )
