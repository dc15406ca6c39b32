"""An experiment = environment + learner + training schedule, loaded from one YAML file.

    env:   {case: car_following, vut: pi1, odd: {...}, reward: {...}, ...}   # EnvConfig
    agent: {gamma: 0.8, learning_rate: 1.0e-5, ...}                         # DQNHyperParams
    train: {total_timesteps: 200000, eval_every: 10000, ...}                # TrainConfig

Every key is optional (defaults in code); unknown keys are rejected with a suggestion.
"""

from __future__ import annotations

import dataclasses
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

from sumo_ayss.agents.hparams import DQNHyperParams
from sumo_ayss.cases import case_info
from sumo_ayss.config.env import EnvConfig
from sumo_ayss.config.mapping import build, to_dict
from sumo_ayss.config.yaml_io import read_yaml
from sumo_ayss.training.selection import CRITERIA
from sumo_ayss.util.validation import check_choice, check_int, check_number, check_seed, require


@dataclass(frozen=True)
class TrainConfig:
    """Training schedule and candidate evaluation. Section ``train``."""

    SECTION: ClassVar[str] = "train"

    total_timesteps: int = 200_000
    """Environment steps (transitions) per run."""
    eval_every: int = 10_000
    """Steps between SPCP candidates (paper: 10,000). Each is saved and evaluated."""
    n_eval_scenarios: int = 100
    """Fixed scenarios each candidate is evaluated on (paper: 100)."""
    eval_seed: int = 2024
    """Seed of the evaluation scenarios: the same for every VUT and training seed."""
    selection: str = "mean_reward"
    """SPCP criterion, one of :data:`sumo_ayss.training.selection.CRITERIA`."""
    torch_threads: int = 1
    """PyTorch intra-op threads; 1 lets parallel runs share cores without contention."""
    progress_bar: bool = True
    device: str = "cpu"
    """Torch device of the learner: ``"cpu"`` or ``"cuda"`` (``"cuda:<index>"`` for one GPU of
    several). SUMO, the replay buffer's storage and candidate evaluation stay on the CPU; the
    networks, the minibatches and the gradient steps run on ``device``. A CUDA device that
    torch cannot see fails the run at its start
    (:func:`sumo_ayss.training.trainer.check_device`)."""
    n_envs: int = 1
    """VUT-POV pairs collecting transitions side by side. 1: one env (SB3 ``DummyVecEnv``);
    > 1: that many pairs in the process's one SUMO simulation
    (:class:`~sumo_ayss.envs.vec_env.PairVecEnv`), each step adding ``n_envs`` transitions.
    SB3 counts ``agent.train_freq`` in such steps, so the trainer rescales ``train_freq`` and
    ``gradient_steps`` to keep ``agent.update_to_data_ratio`` gradient steps per transition.
    Candidates are then evaluated on all pairs at once, right at ``eval_every``; the pairs'
    running episodes are cut there (stored as time-limit truncations) and restarted."""
    early_stop_patience: int | None = None
    """Stop the run once this many consecutive candidates have not beaten the best candidate
    before them by more than ``early_stop_margin_se`` standard errors of its evaluation mean
    (:mod:`sumo_ayss.training.early_stop`); ``total_timesteps`` is then a cap. None (the
    default): train to ``total_timesteps``."""
    early_stop_margin_se: float = 1.0
    """The improvement that counts for ``early_stop_patience``, in standard errors of the
    best earlier candidate's mean evaluation return (``std_return / sqrt(n_episodes)``)."""

    def __post_init__(self) -> None:
        s = self.SECTION
        for name in (
            "total_timesteps",
            "eval_every",
            "n_eval_scenarios",
            "torch_threads",
            "n_envs",
        ):
            value = getattr(self, name)
            require(value >= 1, f"{s}.{name} must be >= 1, got {value}")
        check_seed(self.eval_seed, f"{s}.eval_seed")
        require(
            self.eval_every <= self.total_timesteps,
            f"{s}.eval_every ({self.eval_every}) must be <= total_timesteps "
            f"({self.total_timesteps})",
        )
        require(
            isinstance(self.device, str)
            and re.fullmatch(r"cpu|cuda(:[0-9]+)?", self.device) is not None,
            f"{s}.device must be 'cpu', 'cuda' or 'cuda:<index>', got {self.device!r}",
        )
        check_choice(f"{s}.selection", self.selection, sorted(CRITERIA))
        # the rule itself: sumo_ayss.analysis.early_stop (not imported here: it needs scipy)
        check_int(f"{s}.early_stop_patience", self.early_stop_patience, 1, none_ok=True)
        check_number(f"{s}.early_stop_margin_se", self.early_stop_margin_se, 0.0)


@dataclass(frozen=True)
class ExperimentConfig:
    """The whole resolved configuration of one training run (minus VUT name and seed)."""

    env: EnvConfig = field(default_factory=EnvConfig)
    agent: DQNHyperParams = field(default_factory=DQNHyperParams)
    train: TrainConfig = field(default_factory=TrainConfig)

    def __post_init__(self) -> None:
        a, t = self.agent, self.train
        require(
            a.learning_starts < t.total_timesteps,
            f"agent.learning_starts ({a.learning_starts}) must be < train.total_timesteps "
            f"({t.total_timesteps}): otherwise the run never learns",
        )
        require(
            t.n_envs == 1 or case_info(self.env.case).vec_env,
            f"train.n_envs must be 1 for case {self.env.case!r} (its env cannot share a "
            f"simulation with other pairs), got {t.n_envs}",
        )

    def with_vut(self, vut: str | None) -> ExperimentConfig:
        if vut is None:
            return self
        return dataclasses.replace(self, env=dataclasses.replace(self.env, vut=vut))

    def to_dict(self) -> dict[str, Any]:
        data: dict[str, Any] = to_dict(self)
        return data


def load_experiment(path: str | Path | None) -> ExperimentConfig:
    """Defaults, overridden by the YAML file at ``path`` (``None``: defaults only)."""
    if path is None:
        return ExperimentConfig()
    path = Path(path)
    return build(ExperimentConfig, read_yaml(path), "", path.resolve().parent)


def experiment_from_dict(data: dict[str, Any], base_dir: Path) -> ExperimentConfig:
    return build(ExperimentConfig, data, "", base_dir)
