"""A pythonfmu test FMU that misbehaves on request: a failing doStep, a NaN output, and its
own clock and call count as outputs (to see how the testbed steps and resets it)."""

from __future__ import annotations

from typing import Any

from pythonfmu import Boolean, Fmi2Causality, Fmi2Slave, Fmi2Variability, Integer, Real


class Probe(Fmi2Slave):
    """Input v; outputs a (0, or NaN at call nan_at_call), fmu_time (end of the last step),
    calls (steps since instantiation), flag (a Boolean output); doStep fails at fail_at_call."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.v = 0.0
        self.a = 0.0
        self.fmu_time = -1.0
        self.calls = 0
        self.flag = False
        self.fail_at_call = -1
        self.nan_at_call = -1
        self.register_variable(Real("v", causality=Fmi2Causality.input))
        self.register_variable(Real("a", causality=Fmi2Causality.output))
        self.register_variable(Real("fmu_time", causality=Fmi2Causality.output))
        self.register_variable(
            Integer("calls", causality=Fmi2Causality.output, variability=Fmi2Variability.discrete)
        )
        self.register_variable(
            Boolean("flag", causality=Fmi2Causality.output, variability=Fmi2Variability.discrete)
        )
        for name in ("fail_at_call", "nan_at_call"):
            self.register_variable(
                Integer(
                    name, causality=Fmi2Causality.parameter, variability=Fmi2Variability.tunable
                )
            )

    def do_step(self, current_time: float, step_size: float) -> bool:
        self.calls += 1
        self.fmu_time = current_time + step_size
        self.a = float("nan") if self.calls == self.nan_at_call else 0.0
        return self.calls != self.fail_at_call
