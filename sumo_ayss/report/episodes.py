"""Read a case's episodes as harm: the runs' outcome tables and the case's cross-play table.

The harm score (:mod:`sumo_ayss.analysis.harm`) needs each run's reward and episode length
(its :class:`~sumo_ayss.analysis.harm.HarmScale`, from ``config.yaml``) and each episode's
near-miss pay, collision and mobility. :func:`read_episode_stats` reduces a run's
``outcome.csv`` (the exposure mode), :func:`load_crossplay` reads a case's ``crossplay.csv``
with the diagonal check of its ``crossplay.json`` (the cross-play mode). Tables written
before ``near_miss_pay`` existed derive it from the return (a collision step pays
``-alpha_collision`` and no R_A). Imports neither SUMO nor torch.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from sumo_ayss.analysis.crossplay import CrossplayInput, CrossplayMatrix, crossplay_matrix
from sumo_ayss.analysis.harm import EpisodeStats, HarmScale, episode_harm
from sumo_ayss.config import EnvConfig, RewardConfig
from sumo_ayss.errors import ConfigError, TableError
from sumo_ayss.run_folder import (
    CROSSPLAY_SCHEMA,
    OUTCOME_SCHEMA,
    CaseFolder,
    read_crossplay_json,
    read_table,
)

if TYPE_CHECKING:
    from sumo_ayss.report.load import Run

__all__ = ["harm_scale_of", "load_crossplay", "read_crossplay_matrix", "read_episode_stats"]


def harm_scale_of(reward: RewardConfig, env: Mapping[str, Any]) -> HarmScale:
    """The harm scale of a run: ``alpha_A ·`` decisions per episode, and ``alpha_C``
    (decisions = ``env.episode_s / env.decision_period_s``, the env's defaults if unset)."""
    episode_s = float(env.get("episode_s", EnvConfig.episode_s))
    period_s = float(env.get("decision_period_s", EnvConfig.decision_period_s))
    decisions = round(episode_s / period_s)
    return HarmScale(reward.alpha_adversarial * decisions, reward.alpha_collision)


def read_episode_stats(path: Path, scale: HarmScale) -> EpisodeStats:
    """A run's ``outcome.csv`` reduced to harm, crashes and mobility (:mod:`~sumo_ayss.
    analysis.harm`; a table written before ``near_miss_pay`` existed derives it)."""
    c = read_table(path, OUTCOME_SCHEMA).columns
    pay = scale.near_miss_pay(c["near_miss_pay"], c["episode_return"], c["collided"])
    harm = episode_harm(pay, c["collided"], scale.max_episode_pay)
    return EpisodeStats.of(harm, c["collided"], c["vut_mean_speed_mps"])


def read_crossplay_matrix(path: Path, scale: HarmScale) -> CrossplayMatrix:
    """The :class:`~sumo_ayss.analysis.crossplay.CrossplayMatrix` of a case folder's
    ``crossplay.csv`` (read against :data:`~sumo_ayss.run_folder.CROSSPLAY_SCHEMA`), each
    episode's harm on ``scale`` (a table written before ``near_miss_pay`` existed derives it
    from the return).

    Raises:
        TableError: If the file is missing or does not follow the schema.
        ConfigError: If the design is not complete and balanced
            (:func:`~sumo_ayss.analysis.crossplay.crossplay_matrix`), or a pay does not fit
            the scale.
    """
    c = read_table(path, CROSSPLAY_SCHEMA).columns
    pay = scale.near_miss_pay(c["near_miss_pay"], c["episode_return"], c["collided"])
    return crossplay_matrix(
        c["vut"],
        c["opponent_vut"],
        c["opponent_seed"],
        episode_harm(pay, c["collided"], scale.max_episode_pay),
        c["collided"],
        episode_return=c["episode_return"],
        mobility=c["vut_mean_speed_mps"],
    )


def load_crossplay(runs: Mapping[str, Sequence[Run]]) -> CrossplayInput:
    """The cross-play table of one case's runs: ``crossplay.csv`` of the case folder they lie
    in (the parent of the VUT folders), read against
    :data:`~sumo_ayss.run_folder.CROSSPLAY_SCHEMA`, with its record's diagonal check
    (``crossplay.json``); never raises.

    Args:
        runs: ``{vut: runs}`` of one case.

    Returns:
        The :class:`~sumo_ayss.analysis.crossplay.CrossplayInput`: the matrix, its path and
        its diagonal check, or why there is none (no table, runs in several case folders or
        on different harm scales, an unreadable table or one whose design is not complete
        and balanced, or a table whose diagonal did not reproduce the outcome tables).
    """
    case_dirs = sorted({Path(r.path).parent.parent for rs in runs.values() for r in rs})
    if len(case_dirs) != 1:
        folders = ", ".join(map(str, case_dirs))
        return CrossplayInput(
            missing=f"no cross-play table: the runs lie in several case folders ({folders})"
        )
    folder = CaseFolder(case_dirs[0])
    path = folder.crossplay_csv
    if not path.is_file():
        return CrossplayInput()
    scales = {r.harm_scale for rs in runs.values() for r in rs}
    if len(scales) != 1 or None in scales:
        return CrossplayInput(
            path=path,
            missing="the cross-play table cannot be scored: the runs' config.yaml files do "
            "not give one reward and episode length for all (harm scale)",
        )
    scale = next(iter(scales))
    assert scale is not None
    diagonal: tuple[tuple[str, int, int, int], ...] = ()
    if folder.crossplay_json.is_file():
        try:
            record = read_crossplay_json(folder.crossplay_json)
        except TableError as exc:
            return CrossplayInput(
                path=path,
                missing=f"the cross-play record is unreadable ({exc})",
                problem=str(exc),  # names the file
            )
        diagonal = tuple((d.vut, d.seed, d.n, d.n_equal) for d in record.diagonal)
        bad = [d for d in record.diagonal if not d.ok]
        if bad:
            names = ", ".join(f"{d.vut} (seed {d.seed}: {d.n - d.n_equal}/{d.n})" for d in bad)
            why = (
                "the cross-play table is refused: its diagonal did not reproduce the outcome "
                f"tables of {names}; it would rank another vehicle than the one the opponents "
                "were trained against"
            )
            return CrossplayInput(
                path=path, missing=why, problem=f"{path}: {why}", diagonal=diagonal
            )
    try:
        matrix = read_crossplay_matrix(path, scale)
    except (TableError, ConfigError) as exc:
        text = str(exc)  # a TableError names the file already
        return CrossplayInput(
            path=path,
            missing=f"the cross-play table is unreadable ({exc})",
            problem=text if text.startswith(str(path)) else f"{path}: {text}",
        )
    return CrossplayInput(matrix, path, diagonal=diagonal)
