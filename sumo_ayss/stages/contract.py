"""One contract for every stage: inputs → fingerprint → outputs → done marker.

A stage (train, evaluate and its outcome and AYSS parts, cross-play, discriminability) is
done when its outputs exist and its done marker records the fingerprint of the inputs asked
for now (:func:`is_done`). The fingerprint is one function for all stages
(:func:`fingerprint`: SHA-256 over the inputs' JSON, sorted keys; a file among the inputs
counts by its bytes). Each stage names its inputs, outputs and marker in one class here
(:class:`Stage`):

=====================  ===============================  ======================================
stage                  done marker (what it records)    inputs
=====================  ===============================  ======================================
train                  ``config.yaml`` (the inputs      the run's identity: experiment,
                       themselves) + ``spcp.json``      seed, its own VUT's definition
evaluate (pipeline)    ``evaluate.done.json``           ``spcp.zip``'s bytes, the outcome
                       (the fingerprint)                episodes, the AYSS settings
outcome / ayss (CLI)   ``outcome.json`` / ``ayss.json``  their settings
                       (the settings)
cross-play             ``crossplay.json`` (the          scenarios, seed, the opponents'
                       inputs, with the diagonal)       SPCP SHA-256, how they are driven
discriminability       ``discriminability.json``        vehicle types, case, SUMO options,
                       (the fingerprint)                decision period, grid, threshold
=====================  ===============================  ======================================

Every marker is read as it has always been written, so run folders written before this
module keep being recognised as done where their inputs are the same: the fingerprint is
byte for byte the one ``evaluate.done.json`` and ``discriminability.json`` already held,
and the markers that record the inputs themselves are fingerprinted when read. Imports
neither SUMO nor torch.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

from sumo_ayss.config import AyssConfig, EnvConfig, ExperimentConfig, to_dict
from sumo_ayss.config.identity import run_identity
from sumo_ayss.run_folder import (
    CaseFolder,
    CrossplayRecord,
    RunFolder,
    read_ayss_json,
    read_crossplay_json,
    read_discriminability_json,
    read_done_marker,
    read_outcome_json,
    stored_experiment,
    write_done_marker,
)
from sumo_ayss.stages.crossplay_cells import crossplay_inputs, same_vuts
from sumo_ayss.util.errors import TableError
from sumo_ayss.util.fingerprint import fingerprint

__all__ = [
    "AyssStage",
    "CrossplayStage",
    "DiscriminabilityStage",
    "EvaluateStage",
    "OutcomeStage",
    "Stage",
    "TrainStage",
    "fingerprint",
    "is_done",
]


class Stage(Protocol):
    """What every stage declares: its outputs, the fingerprint of the inputs asked for
    now, and the fingerprint its done marker records."""

    @property
    def name(self) -> str:
        """The stage's name (``train``, ``evaluate``, ...)."""
        ...

    @property
    def outputs(self) -> tuple[Path, ...]:
        """The files the stage writes; all exist once it is done."""
        ...

    def key(self) -> str:
        """:func:`fingerprint` of the inputs asked for now."""
        ...

    def recorded(self) -> str | None:
        """:func:`fingerprint` of the inputs the outputs on disk were made from, as the done
        marker says; None without a marker."""
        ...


def is_done(stage: Stage) -> bool:
    """Whether ``stage`` is done with the inputs asked for now: every output exists and the
    done marker records the same fingerprint.

    Raises:
        AyssError: The done marker exists but cannot be read (the stage says which file).
    """
    return all(p.is_file() for p in stage.outputs) and stage.recorded() == stage.key()


# --------------------------------------------------------------------------- train


@dataclass(frozen=True)
class TrainStage:
    """Training and SPCP selection of one (case, VUT, seed).

    Its marker is ``config.yaml`` (written when the run starts: the inputs themselves) with
    ``spcp.json`` (written last). Both sides are read as the run's identity
    (:func:`~sumo_ayss.config.identity.run_identity`: its own VUT's definition, not the
    study's catalog nor the VUT's name): a run whose identity differs is not done, and may
    not be resumed either (:func:`sumo_ayss.training.config_check.
    check_same_config` names the fields).
    """

    folder: RunFolder
    experiment: ExperimentConfig
    seed: int
    name: str = "train"

    @property
    def outputs(self) -> tuple[Path, ...]:
        return (self.folder.spcp_zip, self.folder.spcp_json)

    def key(self) -> str:
        return fingerprint(run_identity(self.experiment, self.seed))

    def recorded(self) -> str | None:
        """Raises :class:`CheckpointError` if ``config.yaml`` exists but is unreadable."""
        if not self.folder.config.is_file():
            return None
        return fingerprint(run_identity(*stored_experiment(self.folder)))


# --------------------------------------------------------------------------- evaluate


def _ayss_key(ayss: AyssConfig) -> list[Any]:
    """What of ``ayss`` the evaluation marker records: the draws, plus every other setting
    when one differs from its default (so markers written before ``evaluate.ayss`` existed
    stay valid)."""
    if ayss == AyssConfig(n_samples=ayss.n_samples):
        return [ayss.n_samples]
    return [ayss.n_samples, ayss.to_dict()]


@dataclass(frozen=True)
class EvaluateStage:
    """The pipeline's evaluation of a run's SPCP: outcome episodes (the default outcome
    seed) and the AYSS Monte Carlo, marked by ``evaluate.done.json``."""

    folder: RunFolder
    n_outcome: int
    ayss: AyssConfig
    name: str = "evaluate"

    @property
    def outputs(self) -> tuple[Path, ...]:
        f = self.folder
        return (f.outcome_csv, f.outcome_json, f.ayss_csv, f.ayss_bins, f.ayss_json)

    def key(self) -> str:
        """Raises :class:`OSError` without ``spcp.zip``."""
        return fingerprint(self.folder.spcp_zip, self.n_outcome, *_ayss_key(self.ayss))

    def recorded(self) -> str | None:
        return read_done_marker(self.folder.evaluate_done)

    def mark_done(self) -> None:
        """Write ``evaluate.done.json`` with :meth:`key`."""
        write_done_marker(self.folder.evaluate_done, self.key())


def _settings(data: Mapping[str, Any]) -> Any:
    return json.loads(json.dumps(data))  # tuples -> lists, as stored


class _SettingsStage:
    """A stage whose done marker is the settings its output file records: done when they
    are the settings asked for now (``settings()`` against ``stored()``)."""

    def settings(self) -> Any:
        raise NotImplementedError

    def stored(self) -> Any:
        raise NotImplementedError

    def key(self) -> str:
        return fingerprint(self.settings())

    def recorded(self) -> str | None:
        stored = self.stored()
        return None if stored is None else fingerprint(stored)


@dataclass(frozen=True)
class OutcomeStage(_SettingsStage):
    """The outcome episodes alone (``python -m sumo_ayss.evaluate``): ``outcome.json``
    records its settings, ``{"n": episodes, "seed": scenario seed}``."""

    folder: RunFolder
    n: int
    seed: int
    name: str = "outcome"

    @property
    def outputs(self) -> tuple[Path, ...]:
        return (self.folder.outcome_csv, self.folder.outcome_json)

    def settings(self) -> Any:
        """The settings asked for now, as stored."""
        return _settings({"n": self.n, "seed": self.seed})

    def stored(self) -> Any:
        """The settings ``outcome.json`` records, None without it.

        Raises:
            TableError: The file exists but is unreadable (naming it).
        """
        path = self.folder.outcome_json
        return read_outcome_json(path).settings if path.is_file() else None


@dataclass(frozen=True)
class AyssStage(_SettingsStage):
    """The AYSS Monte Carlo alone (``python -m sumo_ayss.evaluate``): ``ayss.json`` records
    its settings (the :class:`~sumo_ayss.config.AyssConfig`)."""

    folder: RunFolder
    ayss: AyssConfig
    name: str = "ayss"

    @property
    def outputs(self) -> tuple[Path, ...]:
        return (self.folder.ayss_csv, self.folder.ayss_bins, self.folder.ayss_json)

    def settings(self) -> Any:
        """The settings asked for now, as stored."""
        return _settings(self.ayss.to_dict())

    def stored(self) -> Any:
        """The settings ``ayss.json`` records, None without it.

        Raises:
            TableError: The file exists but is unreadable (naming it).
        """
        path = self.folder.ayss_json
        return read_ayss_json(path).settings if path.is_file() else None


# --------------------------------------------------------------------------- case stages


@dataclass(frozen=True)
class CrossplayStage:
    """Every SPCP of a case against every VUT. ``crossplay.json`` records the inputs (the
    scenario set, the opponents with their SPCP's SHA-256, how they were driven); a record
    without the diagonal check (written before it), or of other VUTs (other names, or, where
    it names them, other definitions), is not done."""

    folder: CaseFolder
    requested: CrossplayRecord
    name: str = "crossplay"

    @property
    def outputs(self) -> tuple[Path, ...]:
        return (self.folder.crossplay_csv, self.folder.crossplay_json)

    def key(self) -> str:
        return fingerprint(crossplay_inputs(self.requested))

    def recorded(self) -> str | None:
        """Raises :class:`TableError` if ``crossplay.json`` exists but is unreadable."""
        if not self.folder.crossplay_json.is_file():
            return None
        done = read_crossplay_json(self.folder.crossplay_json)
        fresh = done.diagonal and same_vuts(done, self.requested)
        return fingerprint(crossplay_inputs(done)) if fresh else None


@dataclass(frozen=True)
class DiscriminabilityStage:
    """The VUTs' one-step responses over the AYSS box. ``discriminability.json`` records
    the fingerprint of everything a result depends on (vehicle types, case, POV, SUMO
    options, decision period, the grid and threshold in ``settings``); an unreadable
    record is not done."""

    folder: CaseFolder
    env: EnvConfig
    vuts: Sequence[str]
    settings: Mapping[str, Any]
    name: str = "discriminability"

    @property
    def outputs(self) -> tuple[Path, ...]:
        return (self.folder.discriminability_json, self.folder.discriminability_csv)

    def key(self) -> str:
        env = self.env
        return fingerprint(
            {
                "case": env.case,
                "vuts": {v: to_dict(env.vuts[v]) for v in self.vuts},
                "pov": to_dict(env.pov),
                "sim": env.sim_key(env.vuts[v] for v in self.vuts),
                "decision_period_s": env.decision_period_s,
                "settings": dict(self.settings),
            }
        )

    def recorded(self) -> str | None:
        try:
            found = read_discriminability_json(self.folder.discriminability_json)
        except TableError:  # missing or unreadable: measured again
            return None
        value = found.get("fingerprint")
        return value if isinstance(value, str) else None
