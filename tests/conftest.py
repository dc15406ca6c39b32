"""Shared fixtures. libsumo holds one simulation per process: every env fixture closes."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from hypothesis import settings

from sumo_ayss.envs.car_following import CarFollowingEnv

# No wall-clock deadline per example: on a loaded 2-core machine a 200 ms deadline fails
# property tests at random (seen in session 10); speed lives in benchmarks/, not in tests.
settings.register_profile("sumo_ayss", deadline=None)
settings.load_profile("sumo_ayss")


@pytest.fixture
def cf_env() -> Iterator[CarFollowingEnv]:
    env = CarFollowingEnv()
    try:
        yield env
    finally:
        env.close()


# ------------------------------------------------------------------ FMUs built from source


@pytest.fixture(scope="session")
def fmu_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A folder for the FMUs the tests build (once per session)."""
    return tmp_path_factory.mktemp("fmus")


@pytest.fixture(scope="session")
def c_fmu(fmu_dir: Path) -> Callable[[int], Path]:
    """``c_fmu(version)``: the time-gap ACC compiled from ``examples/fmu`` (FMI 2 or 3)."""
    from examples.fmu.build_fmu import build_acc_fmu, compiler

    if compiler() is None:
        pytest.skip("no C compiler (cc, gcc or clang): the C FMU cannot be built here")
    built: dict[int, Path] = {}

    def get(version: int) -> Path:
        if version not in built:
            built[version] = build_acc_fmu(fmu_dir / f"acc_fmi{version}.fmu", version)
        return built[version]

    return get


@pytest.fixture(scope="session")
def py_fmu(fmu_dir: Path) -> Callable[[str], Path]:
    """``py_fmu(name)``: ``acc`` (examples/fmu/acc_slave.py) or ``probe``
    (tests/data/fmu/probe_slave.py) exported with pythonfmu."""
    from examples.fmu.build_fmu import build_python_fmu
    from sumo_ayss.config import PROJECT_ROOT

    scripts = {
        "acc": PROJECT_ROOT / "examples" / "fmu" / "acc_slave.py",
        "probe": PROJECT_ROOT / "tests" / "data" / "fmu" / "probe_slave.py",
    }
    built: dict[str, Path] = {}

    def get(name: str) -> Path:
        if name not in built:
            built[name] = build_python_fmu(scripts[name], fmu_dir / name)
        return built[name]

    return get
