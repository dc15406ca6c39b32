"""Typed, validated configuration: defaults in code, YAML holds overrides.

Every section is a frozen dataclass checked in ``__post_init__``; a bad value raises
:class:`~sumo_ayss.util.errors.ConfigError` naming the dotted field and the allowed values
(the idiom of :mod:`sumo_ayss.util.validation`). YAML files are merged over the defaults by
:func:`build`; unknown keys are rejected with a suggestion, relative paths resolve against
the YAML file's folder.

Sections and their modules:

* ``env`` (:class:`EnvConfig` and its ``sim``, ``actuator``, ``odd``, ``reward``):
  :mod:`sumo_ayss.config.env`;
* an experiment, ``env`` + ``agent`` + ``train`` (:class:`ExperimentConfig`):
  :mod:`sumo_ayss.config.experiment`;
* the AYSS Monte Carlo (:class:`AyssConfig`): :mod:`sumo_ayss.config.ayss`;
* the report's statistical settings and analysis mode (:class:`ReportOptions`):
  :mod:`sumo_ayss.config.report`;
* a pipeline, ``grid``, ``experiments``, ``evaluate``, ``report``, ... (:class:`PipelineConfig`):
  :mod:`sumo_ayss.config.pipeline`.

A configuration is parsed once and then travels as is (it pickles: worker processes and Ray
tasks receive the frozen record). Importing this package imports neither torch, libsumo nor
stable-baselines3, and reading a config runs no user code: a controller VUT is imported when
an env that drives it is built.

Units: lengths m, speeds m/s, accelerations m/s², times s. Sign convention: accelerations
are positive forward, braking is negative (the POV actuator bounds are ``[-6, 6]`` m/s²).
"""

from __future__ import annotations

from sumo_ayss.config.ayss import DEFAULT_AYSS_SEED, AyssConfig
from sumo_ayss.config.env import (
    MANAGED_SUMO_OPTIONS,
    PROJECT_ROOT,
    ActuatorConfig,
    ActuatorMode,
    Case,
    EnvConfig,
    OddConfig,
    RewardConfig,
    RewardShape,
    ShapeKind,
    SimConfig,
    StepMethod,
    integration_method,
)
from sumo_ayss.config.experiment import (
    ExperimentConfig,
    TrainConfig,
    experiment_from_dict,
    load_experiment,
)
from sumo_ayss.config.follower import FOLLOWER_TYPE, FollowerConfig
from sumo_ayss.config.mapping import build, env_config_from_mapping, to_dict
from sumo_ayss.config.pipeline import (
    EvaluateConfig,
    GridConfig,
    PipelineConfig,
    load_pipeline,
)
from sumo_ayss.config.report import ReportOptions
from sumo_ayss.config.yaml_io import read_yaml, safe_load_yaml, write_yaml
from sumo_ayss.util.validation import SEED_MAX, check_out_dir, check_seed, check_sumo_network

__all__ = [
    "DEFAULT_AYSS_SEED",
    "FOLLOWER_TYPE",
    "MANAGED_SUMO_OPTIONS",
    "PROJECT_ROOT",
    "SEED_MAX",
    "ActuatorConfig",
    "ActuatorMode",
    "AyssConfig",
    "Case",
    "EnvConfig",
    "EvaluateConfig",
    "ExperimentConfig",
    "FollowerConfig",
    "GridConfig",
    "OddConfig",
    "PipelineConfig",
    "ReportOptions",
    "RewardConfig",
    "RewardShape",
    "ShapeKind",
    "SimConfig",
    "StepMethod",
    "TrainConfig",
    "build",
    "check_out_dir",
    "check_seed",
    "check_sumo_network",
    "env_config_from_mapping",
    "experiment_from_dict",
    "integration_method",
    "load_experiment",
    "load_pipeline",
    "read_yaml",
    "safe_load_yaml",
    "to_dict",
    "write_yaml",
]
