"""Which scenario of a run to export, and its parts: the table row, the initial condition and
the policy (shared by the SUMO export, :mod:`sumo_ayss.replay.record`, and the OpenSCENARIO
export, :mod:`sumo_ayss.replay.xosc`)."""

from __future__ import annotations

from typing import Any, Literal

from sumo_ayss.cases import get_case
from sumo_ayss.envs import make_env
from sumo_ayss.envs.odd import InitialCondition, with_follower_at
from sumo_ayss.records.table import read_table
from sumo_ayss.run_folder import AYSS_SCHEMA, OUTCOME_SCHEMA, RunFolder, RunRecord
from sumo_ayss.scenarios.rollout import Policy
from sumo_ayss.util.errors import CheckpointError, ConfigError

__all__ = ["Kind", "initial_condition", "load_policy", "read_row", "select_row"]

#: The table a scenario comes from: ``ayss.csv`` (a sample) or ``outcome.csv`` (an episode).
Kind = Literal["ayss", "outcome"]


def select_row(
    ayss_row: int | None, outcome_row: int | None, decisions: int | None
) -> tuple[Kind, int]:
    """The table and row asked for (exactly one of the two rows), ``decisions`` checked.

    Raises:
        ConfigError: If both or neither row is given, or ``decisions`` is not an int >= 1.
    """
    if (ayss_row is None) == (outcome_row is None):
        raise ConfigError(
            "give exactly one of ayss_row (--ayss-row) or outcome_row (--outcome-row)"
        )
    if decisions is not None and (
        isinstance(decisions, bool) or not isinstance(decisions, int) or decisions < 1
    ):
        raise ConfigError(f"decisions must be an integer >= 1, got {decisions!r}")
    if ayss_row is not None:
        return "ayss", ayss_row
    assert outcome_row is not None
    return "outcome", outcome_row


def read_row(folder: RunFolder, kind: Kind, index: int) -> dict[str, Any]:
    """Data row ``index`` (0-based) of the run's ``ayss.csv`` or ``outcome.csv``.

    Raises:
        CheckpointError: If the table is missing (the run was not evaluated).
        ConfigError: If ``index`` is not a data row of it.
    """
    path, schema = (
        (folder.ayss_csv, AYSS_SCHEMA) if kind == "ayss" else (folder.outcome_csv, OUTCOME_SCHEMA)
    )
    if not path.is_file():
        raise CheckpointError(
            f"{folder.path}: no {path.name} (run `python -m sumo_ayss.evaluate` first)"
        )
    table = read_table(path, schema)
    if isinstance(index, bool) or not isinstance(index, int) or not 0 <= index < len(table):
        raise ConfigError(
            f"--{kind}-row must be an integer in [0, {len(table) - 1}] (data rows of {path}), "
            f"got {index!r}"
        )
    return dict(list(table.rows())[index])


def initial_condition(
    kind: Kind, row: dict[str, Any], run: RunRecord | None = None
) -> InitialCondition:
    """The scenario's initial state: the sampled observation of an AYSS row, the episode
    start of an outcome row; an outcome row of a ``run`` with a follower (issue 33) gets the
    follower its episode had (scenario index and seed of the outcome stage)."""
    if kind == "ayss":
        sample = InitialCondition(row["v_pov_mps"], row["v_vut_mps"], row["h_m"])
        if run is None:
            return sample
        start: InitialCondition = get_case(run.experiment.env.case).env_class().ayss_start(sample)
        return start
    ic = InitialCondition(row["v_pov0_mps"], row["v_vut0_mps"], row["gap0_m"])
    if run is None or not run.experiment.env.follower.enabled:
        return ic
    from sumo_ayss.scenarios.outcome import DEFAULT_OUTCOME_SEED

    rec = run.outcome_record
    seed = int(rec.settings.get("seed", DEFAULT_OUTCOME_SEED)) if rec else DEFAULT_OUTCOME_SEED
    return with_follower_at(ic, run.experiment.env.follower, seed, int(row["scenario"]))


def load_policy(run: RunRecord) -> Policy:
    """The run's SPCP, weights only (never unpickled: see "Trust model" in the README)."""
    from sumo_ayss.agents.weights import load_spcp  # torch: only when a policy is needed

    return load_spcp(run, make_env(run.experiment.env))
