"""The time-gap ACC as a Python-backed FMU (FMI 2.0 co-simulation), exported with pythonfmu.

The law is ``examples/acc_controller.py``'s TimeGapACC (same operations in the same order);
its variables are those of the C FMU (``build_fmu.py``), so one ``fmu:`` mapping fits both.
The FMU runs this file inside an embedded Python interpreter, so it imports nothing but
pythonfmu. Build it (from the repository root)::

    python -m examples.fmu.build_fmu --python runs/fmus/

or ``cd examples/fmu && python -m pythonfmu build -f acc_slave.py -d ../../runs/fmus``.
"""

from __future__ import annotations

from typing import Any

from pythonfmu import Boolean, Fmi2Causality, Fmi2Slave, Fmi2Variability, Real


class TimeGapAccPy(Fmi2Slave):
    """Inputs v_ego, gap, v_rel, has_lead; outputs a_cmd, v_cmd; TimeGapACC's parameters."""

    author = "sumo_ayss"
    description = "time-gap ACC (examples/acc_controller.py) as a pythonfmu FMU"

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.v_ego = 0.0
        self.gap = 0.0
        self.v_rel = 0.0
        self.has_lead = False
        self.a_cmd = 0.0
        self.v_cmd = 0.0
        self.time_gap_s = 1.5
        self.standstill_gap_m = 5.0
        self.gap_gain = 0.3
        self.rel_speed_gain = 0.8
        self.set_speed_mps = 30.0
        self.cruise_gain = 0.4
        self.max_accel_mps2 = 3.0
        self.max_decel_mps2 = 6.0
        for name in ("v_ego", "gap", "v_rel"):
            self.register_variable(Real(name, causality=Fmi2Causality.input))
        self.register_variable(
            Boolean("has_lead", causality=Fmi2Causality.input, variability=Fmi2Variability.discrete)
        )
        for name in ("a_cmd", "v_cmd"):
            self.register_variable(Real(name, causality=Fmi2Causality.output))
        for name in (
            "time_gap_s",
            "standstill_gap_m",
            "gap_gain",
            "rel_speed_gain",
            "set_speed_mps",
            "cruise_gain",
            "max_accel_mps2",
            "max_decel_mps2",
        ):
            self.register_variable(
                Real(name, causality=Fmi2Causality.parameter, variability=Fmi2Variability.tunable)
            )

    def do_step(self, current_time: float, step_size: float) -> bool:
        """One evaluation: the outputs from the inputs held over the step."""
        v = self.v_ego
        accel = self.cruise_gain * (self.set_speed_mps - v)
        if self.has_lead:
            spacing_error = self.gap - (self.standstill_gap_m + self.time_gap_s * v)
            accel = min(accel, self.gap_gain * spacing_error + self.rel_speed_gain * self.v_rel)
        self.a_cmd = min(max(accel, -self.max_decel_mps2), self.max_accel_mps2)
        self.v_cmd = v + self.a_cmd * step_size
        return True
