"""Replayable scenarios: an AYSS sample or an outcome episode of a run, as SUMO files.

    python -m sumo_ayss.replay export runs/cut_in/pi1/seed_0 --ayss-row 12 --out scen/ayss12
    python -m sumo_ayss.replay export runs/cut_in/pi1/seed_0 --outcome-row 3 --out scen/ep3
    python -m sumo_ayss.replay scen/ayss12              # sumo-gui (needs a display)
    python -m sumo_ayss.replay scen/ayss12 --headless   # sumo; writes and checks replayed.fcd.xml

**Export** re-runs the scenario in the run's own env (its ``config.yaml``: case, VUT, ODD,
actuator, SUMO options; SUMO seed = the run's seed, as in evaluation) with the run's SPCP
(``spcp.zip``, greedy), records both vehicles at every SUMO step, and writes into ``--out``:

======================  ====================================================================
``network.net.xml``     copy of the run's road network
``vtypes.add.xml``      vehicle types: the run's VUT (``vut_<name>``) and the POV (``pov``)
``trajectory.fcd.xml``  the recorded trajectory in SUMO's FCD format (vehicles ``vut``,
                        ``pov``); file time ``t = τ + dt`` (see below)
``scenario.sumocfg``    replays the trajectory with SUMO's fcd-replay device
``gui.settings.xml``    sumo-gui's view (centred on the scenario) and real-time delay
``scenario.json``       where it came from (run, table row), the initial condition, the
                        SPCP's actions, rewards and headways per decision, and whether the
                        re-run reproduced the row (action, return, collision)
``README.md``           how to replay
======================  ====================================================================

Which scenario: ``--ayss-row K`` is data row ``K`` (0-based) of the run's ``ayss.csv``: the
sampled observation ``(v_pov_mps, v_vut_mps, h_m)`` is the initial condition and the
scenario is the AYSS's ``d = 1`` decision (``--decisions N`` continues with the SPCP for up
to ``N`` decisions). ``--outcome-row K`` is data row ``K`` of ``outcome.csv``: the initial
condition ``(v_pov0_mps, v_vut0_mps, gap0_m)`` and the whole episode.

**Replay mechanism**: SUMO's native fcd-replay device (:mod:`sumo_ayss.sim.export`), so
the scenario plays in an unmodified ``sumo-gui -c scenario.sumocfg``, with no Python. Its
first record only inserts the vehicles (upstream, standing, as the env does); the
scenario's initial state is at ``t = dt`` and scenario time ``τ`` is file time ``τ + dt``.
In the replay both vehicles follow the recording exactly: positions and speeds match it
within :data:`POSITION_TOL_M` and :data:`SPEED_TOL_MPS` (what ``--headless`` checks).
Neither vehicle's model acts in a replay: it shows what happened, it does not re-simulate.
No routes file is written: the device builds each vehicle's route from the trajectory, and
a routes file defining the same vehicle ids is refused by SUMO ("Another vehicle with the
id 'pov' exists").
"""

from __future__ import annotations

from sumo_ayss.replay.cli import main
from sumo_ayss.replay.playback import (
    POSITION_TOL_M,
    SPEED_TOL_MPS,
    ReplayCheck,
    compare_trajectories,
    has_display,
    replay_headless,
    replay_in_gui,
)
from sumo_ayss.replay.record import ExportResult, export_scenario

__all__ = [
    "POSITION_TOL_M",
    "SPEED_TOL_MPS",
    "ExportResult",
    "ReplayCheck",
    "compare_trajectories",
    "export_scenario",
    "has_display",
    "main",
    "replay_headless",
    "replay_in_gui",
]
