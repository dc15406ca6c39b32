"""The grid's jobs: one per (case, VUT, seed), each with its case's resolved experiment.

Each case's experiment file is parsed once here; a job receives that frozen record with its
VUT set (workers never parse it again). Bad grids are refused before any job runs.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from sumo_ayss.config import ExperimentConfig, PipelineConfig, load_experiment
from sumo_ayss.grid.jobs import JobSpec
from sumo_ayss.util.errors import ConfigError
from sumo_ayss.util.validation import suggest
from sumo_ayss.vuts.reference_types import OVERBRAKER_VUT, REFERENCE_VUTS

__all__ = ["case_experiment", "plan_jobs", "plan_seed"]


def plan_jobs(cfg: PipelineConfig) -> list[JobSpec]:
    """Resolve every job's experiment; bad grids are refused here, before any job runs.

    Each case's experiment file is parsed once; a job receives that frozen record with its
    VUT set (workers never parse it again). A case's seeds are ``grid.seeds`` plus those
    adaptive seeding already added (:func:`sumo_ayss.grid.adaptive.case_seeds`).
    """
    from sumo_ayss.grid.adaptive import case_seeds

    jobs = []
    for case in cfg.grid.cases:
        exp = case_experiment(cfg, case)
        for vut in cfg.grid.vuts:
            for seed in case_seeds(cfg, case):
                jobs.append(_job(cfg, exp, case, vut, seed))
    return jobs


def plan_seed(cfg: PipelineConfig, case: str, seed: int) -> list[JobSpec]:
    """One seed's jobs of one case, every VUT (adaptive seeding adds them)."""
    exp = case_experiment(cfg, case)
    return [_job(cfg, exp, case, vut, seed) for vut in cfg.grid.vuts]


def _job(cfg: PipelineConfig, exp: ExperimentConfig, case: str, vut: str, seed: int) -> JobSpec:
    return JobSpec(
        case=case,
        vut=vut,
        seed=int(seed),
        experiment=exp.with_vut(vut),
        out=str(cfg.out),
        n_outcome=cfg.evaluate.n_outcome,
        ayss=cfg.evaluate.ayss,
        reference=cfg.evaluate.reference,
    )


def case_experiment(cfg: PipelineConfig, case: str) -> ExperimentConfig:
    """The case's experiment with the pipeline's overrides; its VUTs checked."""
    exp = load_experiment(cfg.experiments[case])
    if exp.env.case != case:
        raise ConfigError(
            f"experiments.{case}: {cfg.experiments[case]} is a {exp.env.case!r} experiment"
        )
    overrides: dict[str, Any] = {"progress_bar": False}
    if cfg.total_timesteps is not None:
        overrides["total_timesteps"] = cfg.total_timesteps
    if cfg.eval_every is not None:
        overrides["eval_every"] = cfg.eval_every
    if cfg.early_stop_patience is not None:
        overrides["early_stop_patience"] = cfg.early_stop_patience
    if cfg.early_stop_margin_se is not None:
        overrides["early_stop_margin_se"] = cfg.early_stop_margin_se
    exp = dataclasses.replace(exp, train=dataclasses.replace(exp.train, **overrides))
    if cfg.learning_rate is not None:
        agent = dataclasses.replace(exp.agent, learning_rate=cfg.learning_rate)
        exp = dataclasses.replace(exp, agent=agent)
    if cfg.follower is not None:
        follower = dataclasses.replace(exp.env.follower, enabled=cfg.follower)
        exp = dataclasses.replace(exp, env=dataclasses.replace(exp.env, follower=follower))
    if cfg.vuts:
        exp = dataclasses.replace(
            exp, env=dataclasses.replace(exp.env, vuts={**exp.env.vuts, **cfg.vuts})
        )
    named = {**REFERENCE_VUTS, "overbraker": OVERBRAKER_VUT}
    refs = {v: named[v] for v in cfg.grid.vuts if v in named}
    refs = {v: vt for v, vt in refs.items() if v not in exp.env.vuts}
    if refs:  # a reference driver (or the over-braker) named in the grid: a built-in VUT
        exp = dataclasses.replace(
            exp, env=dataclasses.replace(exp.env, vuts={**exp.env.vuts, **refs})
        )
    for vut in cfg.grid.vuts:
        if vut not in exp.env.vuts:
            raise ConfigError(
                f"grid.vuts: {vut!r} is not a VUT of the {case} experiment"
                f"{suggest(vut, exp.env.vuts)}; allowed: {sorted(exp.env.vuts)}"
            )
    return exp
