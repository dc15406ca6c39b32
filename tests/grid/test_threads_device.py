"""Thread settings for pool workers and the learner's device option (train.device)."""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path

import pytest
import torch as th

from sumo_ayss.config import TrainConfig, load_experiment
from sumo_ayss.grid.threads import THREAD_ENV_VARS, set_torch_threads, single_thread_env
from sumo_ayss.training.trainer import check_device, train
from sumo_ayss.util.errors import ConfigError
from tests.training.test_train import tiny_config


def test_single_thread_env_sets_only_unset_variables(monkeypatch: pytest.MonkeyPatch) -> None:
    for name in THREAD_ENV_VARS:
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("MKL_NUM_THREADS", "3")  # the user's choice stays
    changed = single_thread_env()
    assert "MKL_NUM_THREADS" not in changed
    assert set(changed) == set(THREAD_ENV_VARS) - {"MKL_NUM_THREADS"}
    assert os.environ["MKL_NUM_THREADS"] == "3"
    assert all(os.environ[name] == "1" for name in changed)


def test_set_torch_threads() -> None:
    before = th.get_num_threads()
    try:
        set_torch_threads(1)
        assert th.get_num_threads() == 1
    finally:
        th.set_num_threads(before)


@pytest.mark.parametrize("device", ["cpu", "cuda", "cuda:1"])
def test_train_device_accepts(device: str) -> None:
    assert TrainConfig(device=device).device == device


@pytest.mark.parametrize("device", ["gpu", "CUDA", "cuda:", "cuda:x", "mps", 0])
def test_train_device_rejects(device: object) -> None:
    with pytest.raises(ConfigError, match=r"train\.device must be 'cpu', 'cuda' or 'cuda:<index>'"):
        TrainConfig(device=device)  # type: ignore[arg-type]


def test_check_device_cpu() -> None:
    assert check_device("cpu") == "cpu"


@pytest.mark.skipif(th.cuda.is_available(), reason="this machine has CUDA")
def test_check_device_without_cuda_says_so() -> None:
    with pytest.raises(ConfigError, match=r"train\.device is 'cuda' but torch .* sees no CUDA"):
        check_device("cuda")


@pytest.mark.skipif(not th.cuda.is_available(), reason="needs CUDA")
def test_check_device_index_beyond_the_gpus() -> None:
    with pytest.raises(ConfigError, match="CUDA device"):
        check_device(f"cuda:{th.cuda.device_count()}")


@pytest.mark.sumo
@pytest.mark.slow
@pytest.mark.skipif(not th.cuda.is_available(), reason="needs CUDA")
def test_training_on_cuda_end_to_end(tmp_path: Path) -> None:
    """train.device: cuda trains and evaluates candidates; its SPCP loads on the CPU."""
    from sumo_ayss.agents import AyssDQN
    from sumo_ayss.agents.greedy import GreedyPolicy

    cfg = load_experiment(tiny_config(tmp_path, 600, 200))
    cfg = dataclasses.replace(cfg, train=dataclasses.replace(cfg.train, n_envs=4, device="cuda"))
    run = train(cfg, seed=0, out=tmp_path / "runs")
    model = AyssDQN.load(run / "spcp.zip", device="cpu")
    assert next(model.q_net.parameters()).device.type == "cpu"
    obs = model.observation_space.sample()[None, :]
    assert GreedyPolicy(model)(obs).shape == (1,)


def _worker_threads() -> tuple[str | None, int]:
    import torch

    return os.environ.get("OMP_NUM_THREADS"), torch.get_num_threads()


@pytest.mark.slow
def test_pipeline_workers_start_torch_with_one_thread(monkeypatch: pytest.MonkeyPatch) -> None:
    """A spawned pipeline worker imports torch after its initializer: one intra-op thread."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    from sumo_ayss.grid.workers import worker_init

    for name in THREAD_ENV_VARS:
        monkeypatch.delenv(name, raising=False)
    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=1, mp_context=ctx, initializer=worker_init) as pool:
        assert pool.submit(_worker_threads).result(timeout=120) == ("1", 1)


@pytest.mark.skipif(th.cuda.is_available(), reason="this machine has CUDA")
def test_training_on_missing_cuda_fails_before_writing(tmp_path: Path) -> None:
    cfg = load_experiment(tiny_config(tmp_path, 600, 200))
    cfg = dataclasses.replace(cfg, train=dataclasses.replace(cfg.train, device="cuda"))
    with pytest.raises(ConfigError, match=r"train\.device is 'cuda'"):
        train(cfg, seed=0, out=tmp_path / "runs")
    assert not (tmp_path / "runs").exists()
