"""Shared fixtures. libsumo holds one simulation per process: every env fixture closes."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from sumo_ayss.envs.car_following import CarFollowingEnv


@pytest.fixture
def cf_env() -> Iterator[CarFollowingEnv]:
    env = CarFollowingEnv()
    try:
        yield env
    finally:
        env.close()
