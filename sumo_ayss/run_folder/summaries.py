"""``outcome.json`` and ``ayss.json``: the evaluation stages' summaries, one writer and one
reader each.

Both start with the stage header (:class:`StageHeader`) and hold the ``settings`` the stage
ran with (compared when a later evaluation would skip the stage). ``outcome.json``::

    {"stage": "outcome", "run_dir": ..., "case": ..., "vut": ..., "train_seed": 0,
     "spcp_step": 80016, "settings": {"n": 200, "seed": 4242}, "odd": {...},
     "wall_s": 2.7,
     "summary": {"case": "cut_in", "n_episodes": 200,
                 "crash_rate": {"count": 21, "n": 200, "value": 0.105, "lo": 0.07,
                                "hi": 0.155, "level": 0.95},        # a proportion
                 "lane_change_rate": {...} | null,                   # cut-in only
                 "mean_return": {"n": 200, "mean": 8.3, "lo": 7.1, "hi": 9.5,
                                 "level": 0.95},                     # a mean
                 "mean_final_headway_m": {...},                      # m
                 "lc_no_collision_return": {...} | null,             # cut-in only
                 "lc_no_collision_final_headway_m": {...} | null}}   # cut-in only, m

(the summary is ``sumo_ayss.scenarios.outcome.OutcomeSummary.as_dict()``; NaN is written as
``null``). ``ayss.json`` holds the header, ``settings`` (the ``AyssConfig``),
``indicator_name``, ``counts``, ``indicator_mean`` and throughput figures.

Imports neither SUMO nor torch.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sumo_ayss.records.jsonio import json_field, json_number, read_json, write_json

__all__ = [
    "AyssRecord",
    "Estimate",
    "Outcome",
    "OutcomeRecord",
    "OutcomeSubset",
    "StageHeader",
    "read_ayss_json",
    "read_outcome_json",
    "write_ayss_json",
    "write_outcome_json",
]


@dataclass(frozen=True)
class StageHeader:
    """What each evaluation summary says about the run it came from.

    Attributes:
        run_dir: The run folder, relative to the repository where it lies below it.
        case: The case name (:mod:`sumo_ayss.cases`).
        vut: The run's VUT.
        train_seed: The training seed.
        spcp_step: Training step of the evaluated SPCP, None if unknown.
    """

    run_dir: str
    case: str
    vut: str
    train_seed: int
    spcp_step: int | None

    def as_dict(self, stage: str) -> dict[str, Any]:
        """The header's fields and ``stage`` (the file's keys are sorted when written)."""
        return {"stage": stage, **dataclasses.asdict(self)}


@dataclass(frozen=True)
class Estimate:
    """A point estimate with its confidence interval; NaN where unknown.

    Attributes:
        value: Point estimate, in the quantity's unit (rates as fractions).
        lo: Lower confidence bound.
        hi: Upper confidence bound.
    """

    value: float = math.nan
    lo: float = math.nan
    hi: float = math.nan

    @property
    def known(self) -> bool:
        """Whether the point estimate is a finite number."""
        return math.isfinite(self.value)


@dataclass(frozen=True)
class OutcomeSubset:
    """Outcome over a subset of episodes (cut-in: a lane change and no collision).

    Attributes:
        n: Episodes in the subset.
        mean_return: Mean episode reward over the subset.
        mean_final_headway_m: Mean headway at the last step over the subset, m.
    """

    n: int | None
    mean_return: Estimate
    mean_final_headway_m: Estimate


@dataclass(frozen=True)
class Outcome:
    """Summary of the outcome episodes of one SPCP (paper Tables II and III).

    Attributes:
        n: Number of outcome episodes.
        crash_rate: Fraction of episodes with a collision, in [0, 1].
        lane_change_rate: Fraction of episodes with a POV lane change (cut-in), or None.
        mean_return: Mean episode reward over all episodes.
        mean_final_headway_m: Mean headway at the last step over all episodes, m.
        lane_change_no_collision: The same over episodes with a lane change and no
            collision (cut-in), or None.
    """

    n: int | None
    crash_rate: Estimate
    lane_change_rate: Estimate | None
    mean_return: Estimate
    mean_final_headway_m: Estimate
    lane_change_no_collision: OutcomeSubset | None


@dataclass(frozen=True)
class OutcomeRecord:
    """``outcome.json`` as read back.

    Attributes:
        settings: ``{"n": episodes, "seed": scenario seed}`` the stage ran with.
        outcome: The summary.
        spcp_step: Training step of the evaluated SPCP, None if unknown.
    """

    settings: dict[str, Any]
    outcome: Outcome
    spcp_step: int | None


@dataclass(frozen=True)
class AyssRecord:
    """``ayss.json`` as read back.

    Attributes:
        settings: The ``AyssConfig`` the stage ran with, as a dict.
        indicator_name: ``pov_accel_mps2`` or ``delta_v_bar_mps``.
        counts: Samples per filter step.
    """

    settings: dict[str, Any]
    indicator_name: str
    counts: dict[str, Any]


# --------------------------------------------------------------------------- writers


def write_outcome_json(
    path: Path,
    header: StageHeader,
    settings: Mapping[str, Any],
    odd: Mapping[str, Any],
    summary: Mapping[str, Any],
    wall_s: float,
    extra: Mapping[str, Any] | None = None,
) -> None:
    """Write ``outcome.json``.

    Args:
        path: ``<run>/outcome.json``.
        header: The run it came from.
        settings: ``{"n": episodes, "seed": scenario seed}``.
        odd: The run's ODD (``to_dict(EnvConfig.odd)``).
        summary: ``OutcomeSummary.as_dict()``.
        wall_s: Wall time of the rollouts, s.
        extra: Further sections of a case (e.g. ``supporting_pov``); None: none.
    """
    record = {
        **header.as_dict("outcome"),
        "settings": dict(settings),
        "odd": dict(odd),
        "summary": dict(summary),
        "wall_s": round(wall_s, 3),
        **(extra or {}),
    }
    write_json(path, record)


def write_ayss_json(
    path: Path, header: StageHeader, settings: Mapping[str, Any], summary: Mapping[str, Any]
) -> None:
    """Write ``ayss.json``: the header, ``summary`` (``AyssResult.summary()`` without its
    ``config``) and ``settings`` (that config)."""
    write_json(path, {**header.as_dict("ayss"), **summary, "settings": dict(settings)})


# --------------------------------------------------------------------------- readers


def _estimate(data: Mapping[str, Any], key: str, point: str, where: str) -> Estimate:
    """A proportion (``point="value"``) or a mean (``point="mean"``) of the summary."""
    item = json_field(data, key, dict, where)
    at = f"{where}.{key}"
    return Estimate(
        json_number(item, point, at), json_number(item, "lo", at), json_number(item, "hi", at)
    )


def read_outcome_json(path: Path) -> OutcomeRecord:
    """Read ``outcome.json``.

    Raises:
        TableError: The file is missing, not a JSON object, or a field is missing or of the
            wrong type; the message names the file and the dotted field.
    """
    data = read_json(path)
    where = f"{path}: summary"
    summary = json_field(data, "summary", dict, str(path))
    lc = summary.get("lane_change_rate")
    lc_return = summary.get("lc_no_collision_return")
    subset = None
    if lc_return is not None:
        subset = OutcomeSubset(
            n=json_field(
                json_field(summary, "lc_no_collision_return", dict, where), "n", int, where
            ),
            mean_return=_estimate(summary, "lc_no_collision_return", "mean", where),
            mean_final_headway_m=_estimate(
                summary, "lc_no_collision_final_headway_m", "mean", where
            ),
        )
    outcome = Outcome(
        n=json_field(summary, "n_episodes", int, where),
        crash_rate=_estimate(summary, "crash_rate", "value", where),
        lane_change_rate=None
        if lc is None
        else _estimate(summary, "lane_change_rate", "value", where),
        mean_return=_estimate(summary, "mean_return", "mean", where),
        mean_final_headway_m=_estimate(summary, "mean_final_headway_m", "mean", where),
        lane_change_no_collision=subset,
    )
    step = data.get("spcp_step")
    return OutcomeRecord(
        settings=dict(json_field(data, "settings", dict, str(path))),
        outcome=outcome,
        spcp_step=step if isinstance(step, int) and not isinstance(step, bool) else None,
    )


def read_ayss_json(path: Path) -> AyssRecord:
    """Read ``ayss.json``.

    Raises:
        TableError: The file is missing, not a JSON object, or ``settings``,
            ``indicator_name`` or ``counts`` is missing or of the wrong type.
    """
    data = read_json(path)
    name = json_field(data, "indicator_name", str, str(path))
    return AyssRecord(
        settings=dict(json_field(data, "settings", dict, str(path))),
        indicator_name=name,
        counts=dict(json_field(data, "counts", dict, str(path))),
    )
