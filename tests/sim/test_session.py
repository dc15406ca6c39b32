"""One libsumo simulation per process: a second one is a clear error, not a crash."""

from __future__ import annotations

from pathlib import Path

import pytest

from sumo_ayss.config import EnvConfig
from sumo_ayss.envs.car_following import CarFollowingEnv
from sumo_ayss.util.errors import ConfigError, SimulationError

pytestmark = pytest.mark.sumo


def test_second_live_simulation_raises_our_error() -> None:
    first, second = CarFollowingEnv(), CarFollowingEnv()
    try:
        first.reset(seed=0)
        with pytest.raises(SimulationError, match="one simulation per process"):
            second.reset(seed=0)
        first.close()
        second.reset(seed=0)  # after the first closes, the second may start
        second.step(2)
    finally:
        first.close()
        second.close()
        second.close()  # close() twice is safe


def test_missing_network_is_a_clear_error(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match=r"env\.network: file not found"):
        EnvConfig(network=tmp_path / "gone.net.xml")
