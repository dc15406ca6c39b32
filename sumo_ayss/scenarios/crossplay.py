"""Cross-play: every SPCP of a case against every VUT of that case, on common scenarios.

A VUT's own SPCP is one draw from a noisy search: two training seeds against the same VUT
can settle on different strategies (on a cut-in ladder, one seed's SPCP extracted 12.3
reward per episode and the other two 9.6 and 9.9 from the same VUT). Scoring each VUT by its
own SPCPs alone mixes that search noise into the comparison. Cross-play instead lets the
whole *pool* of SPCPs trained in a case (every VUT, every seed) drive against every VUT,
on the same outcome scenarios. Each SPCP is then a block: the difference between two VUTs
is read within one opponent (same network, same scenarios), which removes the opponent's
own quality from the comparison (:mod:`sumo_ayss.analysis.crossplay`).

:func:`run_crossplay` rolls each opponent greedily over the ``n`` initial conditions of
``seed`` (by default those of the outcome stage, so the diagonal "own SPCP vs own VUT" is
the outcome table), ``n_envs`` episodes at a time in one SUMO simulation
(:class:`~sumo_ayss.envs.vec_env.PairVecEnv`, bit-identical per pair to the single env).
One row per (VUT, opponent, scenario) goes to
:data:`~sumo_ayss.run_folder.CROSSPLAY_SCHEMA`.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from sumo_ayss.config import EnvConfig
from sumo_ayss.envs.odd import sample_initial_conditions
from sumo_ayss.envs.pair_env import PairEnv
from sumo_ayss.errors import ConfigError
from sumo_ayss.run_folder import CROSSPLAY_SCHEMA, Table
from sumo_ayss.scenarios.rollout import Policy

__all__ = ["Opponent", "run_crossplay"]


@dataclass(frozen=True)
class Opponent:
    """One SPCP of the pool.

    Attributes:
        vut: The VUT it was trained against.
        seed: Its training seed.
        load: Builds its greedy policy for an env's spaces (called once per VUT faced).
    """

    vut: str
    seed: int
    load: Callable[[PairEnv], Policy]


def _same_but_vut(envs: Mapping[str, EnvConfig]) -> None:
    """Refuses a pool whose VUT env configs differ in anything but the VUT."""
    items = list(envs.items())
    ref_name, ref = items[0]
    for name, cfg in items[1:]:
        if dataclasses.replace(cfg, vut=ref.vut) != ref:
            raise ConfigError(
                f"cross-play: the env configs of {ref_name!r} and {name!r} differ in more "
                "than the VUT (case, ODD, reward, actuator or timing); cross-play needs one "
                "world for all"
            )


def run_crossplay(
    envs: Mapping[str, EnvConfig],
    opponents: Sequence[Opponent],
    *,
    n: int,
    seed: int,
    n_envs: int = 50,
    progress: Callable[[str], None] | None = None,
) -> Table:
    """Every opponent against every VUT on ``n`` common scenarios.

    Args:
        envs: VUT name -> its env config (identical but for the VUT).
        opponents: The SPCP pool.
        n: Scenarios per (VUT, opponent), >= 1.
        seed: Seed of :func:`~sumo_ayss.envs.odd.sample_initial_conditions`.
        n_envs: Pairs simulated at once, >= 1.
        progress: Called with one line per (VUT, opponent) done.

    Returns:
        The cross-play table, VUTs in the given order, then opponents, then scenarios.
    """
    from sumo_ayss.envs.vec_env import PairVecEnv

    if not envs or not opponents:
        raise ConfigError("cross-play needs at least one VUT and one opponent SPCP")
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise ConfigError(f"n: expected an integer >= 1, got {n!r}")
    _same_but_vut(envs)
    cols: dict[str, list[object]] = {c.name: [] for c in CROSSPLAY_SCHEMA.columns}
    for vut, cfg in envs.items():
        scenarios = sample_initial_conditions(cfg.odd, n, seed)
        venv = PairVecEnv(cfg, n_envs=min(n_envs, n), sumo_seed=seed)
        try:
            for opp in opponents:
                t0 = time.perf_counter()
                policy = opp.load(venv.envs[0])
                traces = venv.run_scenarios(policy, scenarios)
                for j, tr in enumerate(traces):
                    last = tr.infos[-1]
                    cols["vut"].append(vut)
                    cols["opponent_vut"].append(opp.vut)
                    cols["opponent_seed"].append(opp.seed)
                    cols["scenario"].append(j)
                    total = 0.0
                    for r in tr.rewards:  # summed as run_episode does: diagonal == outcome
                        total += float(r)
                    cols["episode_return"].append(total)
                    cols["collided"].append(bool(last["collision"]))
                    cols["final_headway_m"].append(float(last["headway_m"]))
                    cols["n_steps"].append(len(tr.rewards))
                if progress is not None:
                    mean = float(np.mean(cols["episode_return"][-n:]))  # type: ignore[arg-type]
                    progress(
                        f"{vut} vs SPCP {opp.vut}/seed_{opp.seed}: mean return {mean:.2f} "
                        f"({time.perf_counter() - t0:.1f} s)"
                    )
        finally:
            venv.close()
    return Table(
        CROSSPLAY_SCHEMA,
        {
            **{k: cols[k] for k in ("vut", "opponent_vut", "episode_return", "final_headway_m")},
            "opponent_seed": np.array(cols["opponent_seed"], dtype=np.int64),
            "scenario": np.array(cols["scenario"], dtype=np.int64),
            "collided": np.array(cols["collided"], dtype=bool),
            "n_steps": np.array(cols["n_steps"], dtype=np.int64),
        },
    )
