"""A run's identity: what made it, and nothing about the study around it.

A run (case, VUT, seed) is made from its experiment (``env``, ``agent``, ``train``), its
seed and **its own VUT's definition**. The other VUTs of the study's catalog
(``env.vuts``, which every ``config.yaml`` stores whole: the built-ins plus the study's own)
enter its simulation's dynamics in one way only: SUMO moves every vehicle ballistically
when any loaded type has an ``actionStepLength`` other than the step
(``env.sim.step_method``, :func:`~sumo_ayss.config.integration_method`). Otherwise the
VUT's *name* is a label: a study that adds, drops, redefines or renames another VUT, or
renames this one without changing it, asks for the same run, as long as the resolved
integration method stays. :func:`run_identity` is that view of an experiment, as flat
dotted fields:

* ``env.vut`` and ``env.vuts`` are left out, and ``env.follower`` (evaluation only);
* ``env.sim.step_method`` enters resolved, as ``env.sim.integration``, and only where it is
  not what the run's own VUT implies (:meth:`~sumo_ayss.config.EnvConfig.sim_key`): pi1
  beside a reaction VUT holds ``ballistic``; every run folder written before the option
  keeps its identity;
* the run's own VUT's definition (model, parameters, controller; its ``description`` is
  display only) enters under :data:`OWN_VUT` (``env.vuts[env.vut].params.minGap``);
* display options (:data:`DISPLAY_FIELDS`, e.g. the progress bar) are left out.

The training stage's fingerprint (:class:`~sumo_ayss.stages.contract.TrainStage`) and the
resume check (:mod:`sumo_ayss.training.config_check`) both read it, from the requested
experiment and from the stored ``config.yaml`` alike, so run folders written before this
module (whose ``config.yaml`` holds the whole catalog of their study) keep matching: their
stored catalog is ignored, nothing on disk changes. :func:`vut_key` fingerprints a VUT's
definition on its own (the cross-play record's and adaptive seeding's record of which
vehicle each VUT name stood for).

Imports neither SUMO nor torch.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any

from sumo_ayss.config.experiment import ExperimentConfig
from sumo_ayss.config.mapping import to_dict
from sumo_ayss.util.fingerprint import fingerprint
from sumo_ayss.vuts.catalog import VehicleType
from sumo_ayss.vuts.controller_spec import identity_target

__all__ = [
    "DISPLAY_FIELDS",
    "OWN_VUT",
    "VUT_DISPLAY_FIELDS",
    "config_key",
    "flat_config",
    "identity_differences",
    "is_redefinition",
    "run_identity",
    "vut_definition",
    "vut_key",
]

#: Fields that change what a run shows, never what it computes: a resume may differ in them.
DISPLAY_FIELDS = ("train.progress_bar",)

#: Fields of a VUT's definition that only reports show (never what the vehicle does).
VUT_DISPLAY_FIELDS = ("description",)

#: The prefix under which a run's identity holds its own VUT's definition.
OWN_VUT = "env.vuts[env.vut]"


def flat_config(data: Any, prefix: str = "") -> dict[str, Any]:
    """``{"train.total_timesteps": 100000, ...}``: nested mappings as dotted keys."""
    if isinstance(data, dict):
        out: dict[str, Any] = {}
        for key, value in data.items():
            out.update(flat_config(value, f"{prefix}{key}."))
        return out
    return {prefix[:-1]: data}


def vut_definition(vt: VehicleType) -> dict[str, Any]:
    """What a VUT is, as plain data: model, parameters and controller (its description
    aside); a registered controller by the form its records were first keyed by
    (:func:`~sumo_ayss.vuts.controller_spec.identity_target`), so that run folders written
    before the registered names keep their identity and definition key."""
    data: dict[str, Any] = to_dict(vt)
    controller = data.get("controller")
    if isinstance(controller, dict) and isinstance(controller.get("target"), str):
        controller["target"] = identity_target(controller["target"])
    return {k: v for k, v in data.items() if k not in VUT_DISPLAY_FIELDS}


def vut_key(vt: VehicleType) -> str:
    """:func:`~sumo_ayss.util.fingerprint.fingerprint` of :func:`vut_definition`: equal for
    two names of one vehicle, different for a redefined one."""
    return fingerprint(vut_definition(vt))


def run_identity(cfg: ExperimentConfig, seed: int) -> dict[str, Any]:
    """The flat dotted fields a run is made from (see the module docstring), with ``seed``."""
    data: dict[str, Any] = to_dict(cfg)
    env = data["env"]
    env.pop("vut")
    env.pop("vuts")
    # The follower behind the VUT is in the evaluation episodes only (it never changes a
    # training episode: sumo_ayss.envs.follower), and run folders before it have none.
    env.pop("follower", None)
    # The catalog does enter through one SUMO global: how every vehicle is moved. Recorded
    # resolved, and only where the run's own VUT does not imply it, so that the identities
    # of runs written before the option are unchanged.
    env["sim"] = cfg.env.sim_key([cfg.env.vut_type])
    flat = flat_config(data)
    flat.update(flat_config(vut_definition(cfg.env.vut_type), f"{OWN_VUT}."))
    return {"seed": seed, **{k: v for k, v in flat.items() if k not in DISPLAY_FIELDS}}


def identity_differences(
    stored: ExperimentConfig, stored_seed: int, requested: ExperimentConfig, seed: int
) -> list[str]:
    """The fields in which two runs' identities differ, each as
    ``"field: stored -> requested"`` (the seed first, then the fields sorted)."""
    a, b = run_identity(stored, stored_seed), run_identity(requested, seed)
    keys = ["seed", *sorted((set(a) | set(b)) - {"seed"})]
    return [
        f"{key}: {a.get(key, '(absent)')!r} -> {b.get(key, '(absent)')!r}"
        for key in keys
        if a.get(key) != b.get(key)
    ]


def is_redefinition(differences: list[str]) -> bool:
    """Whether every difference (:func:`identity_differences`) lies in the run's own VUT's
    definition: the same study asks for a redefined VUT, whose run is trained again."""
    return bool(differences) and all(d.startswith(f"{OWN_VUT}.") for d in differences)


#: Entries of a stored ``config.yaml`` that may differ between runs pooled in one report: the
#: run's own VUT and seed, the VUT catalog (a leaderboard adds VUTs), and display-only
#: settings (:func:`config_key`).
POOL_IGNORED = (("seed",), ("vut",), ("env", "vut"), ("env", "vuts"), ("train", "progress_bar"))


def config_key(config: Mapping[str, Any]) -> str:
    """12 hex digits of :func:`~sumo_ayss.util.fingerprint.fingerprint` of a resolved
    ``config.yaml`` without :data:`POOL_IGNORED`: runs with different keys in one case must
    not be pooled (:func:`sumo_ayss.training.trust.mixing_problems`)."""
    data = json.loads(json.dumps(config, default=str))
    for key in POOL_IGNORED:
        node: Any = data
        for part in key[:-1]:
            node = node.get(part) if isinstance(node, Mapping) else None
        if isinstance(node, dict):
            node.pop(key[-1], None)
    return fingerprint(data)[:12]
