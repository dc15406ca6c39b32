"""The per-call time budget of a VUT: a call past the deadline stops the run with the VUT
named; a VUT that dominates the wall time is warned about once."""

from __future__ import annotations

import logging
import time
from typing import Any

import pytest

from sumo_ayss.config import EnvConfig
from sumo_ayss.envs import make_env
from sumo_ayss.envs.odd import InitialCondition
from sumo_ayss.util.errors import ControllerError
from sumo_ayss.vuts import call_budget
from sumo_ayss.vuts.call_budget import CallBudget
from sumo_ayss.vuts.catalog import ControllerSpec, VehicleType


class Sleepy:
    """Brakes gently, after sleeping ``sleep_s`` [s] from call ``from_call`` on."""

    def __init__(self, sleep_s: float, from_call: int = 0) -> None:
        self.sleep_s = sleep_s
        self.from_call = from_call
        self.calls = 0

    def acceleration(self, state: Any) -> float:
        self.calls += 1
        if self.calls > self.from_call:
            time.sleep(self.sleep_s)
        return -0.5


def test_a_call_past_the_deadline_is_an_error_naming_the_vut() -> None:
    budget = CallBudget("FMU 'acc.fmu'", 0.1)
    budget.record(time.perf_counter(), 0.05)
    with pytest.raises(
        ControllerError,
        match=r"FMU 'acc\.fmu': one call took 0\.25 s, past its "
        r"deadline call_deadline_s = 0\.1 s \(2 calls, mean 150 ms\)",
    ):
        budget.record(time.perf_counter(), 0.25)
    assert budget.calls == 2 and budget.max_s == 0.25


def test_warns_once_when_the_vut_dominates_the_wall_time(caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.WARNING, logger="sumo_ayss.vuts.call_budget")
    call_budget._WARNED.clear()
    quick = CallBudget("quick", 1.0, window_s=0.1)
    for _ in range(200):  # 1 ms between calls, calls take no time
        time.sleep(0.001)
        start = time.perf_counter()
        quick.record(start, time.perf_counter() - start)
    assert not quick.warned and not caplog.records
    slow = CallBudget("slow", 1.0, window_s=0.1)
    for _ in range(200):  # the calls are all the time there is
        start = time.perf_counter()
        time.sleep(0.001)
        slow.record(start, time.perf_counter() - start)
    assert slow.warned
    again = CallBudget("slow", 1.0, window_s=0.1)  # another pair of the same VUT: no second warning
    for _ in range(200):
        start = time.perf_counter()
        time.sleep(0.001)
        again.record(start, time.perf_counter() - start)
    [record] = caplog.records
    assert record.getMessage().startswith("slow takes ") and "of the wall time" in record.message


@pytest.mark.sumo
def test_a_slow_controller_stops_the_episode_at_its_deadline() -> None:
    spec = ControllerSpec(
        "tests.vuts.test_call_budget:Sleepy",
        3.0,
        6.0,
        params={"sleep_s": 0.2, "from_call": 3},
        call_deadline_s=0.05,
    )
    cfg = EnvConfig(vut="slow", vuts={"slow": VehicleType(controller=spec)})  # type: ignore[arg-type]
    env = make_env(cfg, sumo_seed=0)
    try:
        env.reset(options={"initial_condition": InitialCondition(20.0, 20.0, 30.0)})
        with pytest.raises(
            ControllerError,
            match=r"'tests\.vuts\.test_call_budget:Sleepy': one "
            r"call took 0\.2\d* s, past its deadline call_deadline_s = 0\.05 s",
        ):
            for _ in range(25):
                env.step(10)
    finally:
        env.close()
