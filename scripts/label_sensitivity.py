"""How much do the careful human's open choices move the crash labels, and what do they cost?

    python scripts/label_sensitivity.py runs/ladders/careful_human_a [out.md]

For every case of a study whose runs still hold their SPCPs, the cross-play episodes are
driven again exactly as the cross-play stage drives them (every opponent of the pool
against every VUT, the outcome scenarios, SUMO seed = the opponent's training seed), and
every crash is labelled with each variant below. Per variant and VUT: the crashes labelled
preventable. Also the wall time of the rollouts against that of one labelling pass (the
labels' cost), measured in this process.

Variants (``sumo_ayss.vuts.reference.CarefulDriver`` parameters; fsm and rss as references):
the default; ``decel_perception: threshold`` (esmini's 5 m/s² + 0.4 s); no foot-off
deceleration; AEB at TTC 1.4 s; no AEB; 0.4 s time-mode perception of cut-ins; FSM; RSS.
"""

from __future__ import annotations

import sys
import time
from collections import defaultdict
from pathlib import Path
from typing import Any

from sumo_ayss.agents.weights import load_spcp
from sumo_ayss.envs import make_env
from sumo_ayss.envs.odd import scenario_set
from sumo_ayss.run_folder import read_crossplay_json, read_run
from sumo_ayss.scenarios.preventability import label_crashes
from sumo_ayss.scenarios.rollout import run_episodes
from sumo_ayss.util.atomic import atomic_write_text
from sumo_ayss.vuts.catalog import controller_imports

VARIANTS: dict[str, tuple[str, dict[str, Any]]] = {
    "cc_driver (default)": ("cc_driver", {}),
    "decel threshold 5 m/s² + 0.4 s": ("cc_driver", {"decel_perception": "threshold"}),
    "no foot-off": ("cc_driver", {"release_decel_mps2": 0.0}),
    "AEB at TTC 1.4 s": ("cc_driver", {"aeb_ttc_s": 1.4}),
    "no AEB": ("cc_driver", {"aeb": False}),
    "cut-in perception 0.4 s (time)": ("cc_driver", {"perception": "time"}),
    "fsm": ("fsm", {}),
    "rss": ("rss", {}),
}


def case_rows(
    case_dir: Path,
) -> tuple[list[str], dict[str, dict[str, int]], dict[str, int], float, float]:
    record = read_crossplay_json(case_dir / "crossplay.json")
    runs = [read_run(p) for p in sorted(case_dir.glob("*/seed_*")) if (p / "spcp.zip").is_file()]
    vuts = sorted({r.experiment.env.vut for r in runs})
    envs = {r.experiment.env.vut: r.experiment.env for r in runs}
    counts: dict[str, dict[str, int]] = defaultdict(lambda: defaultdict(int))
    crashes: dict[str, int] = defaultdict(int)
    t_roll = t_label = 0.0
    policies = {}
    for vut in vuts:
        cfg = envs[vut]
        scenarios = scenario_set(cfg, record.n, record.seed)
        for opp in runs:
            t0 = time.perf_counter()
            env = make_env(cfg, sumo_seed=opp.config_seed)
            try:
                key = (opp.experiment.env.vut, opp.config_seed)
                if key not in policies:
                    policies[key] = load_spcp(opp, env)
                episodes = run_episodes(env, policies[key], scenarios)
            finally:
                env.close()
            t_roll += time.perf_counter() - t0
            collided = [e.collided for e in episodes]
            actions = [e.actions for e in episodes]
            crashes[vut] += sum(collided)
            for name, (ref, params) in VARIANTS.items():
                t1 = time.perf_counter()
                labels = label_crashes(
                    cfg, scenarios, collided, actions, sumo_seed=opp.config_seed,
                    reference=ref, params=params,
                )  # fmt: skip
                if name == "cc_driver (default)":
                    t_label += time.perf_counter() - t1
                counts[name][vut] += int((labels == 1.0).sum())
    return vuts, counts, crashes, t_roll, t_label


def main(study: Path, out: Path) -> None:
    lines = [
        f"# Crash labels under the careful human's open choices: {study.name}",
        "",
        f"Written by `python scripts/label_sensitivity.py {study}`: the study's cross-play "
        "episodes driven again, every crash replayed with each reference variant. Cells: "
        "crashes labelled preventable (of all the VUT's crashes).",
    ]
    with controller_imports(True):
        for case_dir in sorted(p for p in study.iterdir() if (p / "crossplay.json").is_file()):
            vuts, counts, crashes, t_roll, t_label = case_rows(case_dir)
            lines += [
                "",
                f"## {case_dir.name}",
                "",
                "| variant | " + " | ".join(vuts) + " |",
                "|---|" + "---:|" * len(vuts),
            ]
            for name in VARIANTS:
                cells = [f"{counts[name][v]} of {crashes[v]}" for v in vuts]
                lines.append(f"| {name} | " + " | ".join(cells) + " |")
            lines += [
                "",
                f"Rollouts {t_roll:.1f} s, one labelling pass (default reference) "
                f"{t_label:.1f} s: the labels cost {100 * t_label / t_roll:.1f} % of the "
                "cross-play rollouts' wall time here.",
            ]
            print("\n".join(lines[-len(VARIANTS) - 6 :]), flush=True)
    atomic_write_text(out, "\n".join(lines) + "\n")
    print(f"wrote {out}")


if __name__ == "__main__":
    args = sys.argv[1:]
    if not args or args[0] in ("-h", "--help"):
        print(__doc__)
        sys.exit(0 if args else 2)
    main(Path(args[0]), Path(args[1]) if len(args) > 1 else Path(args[0]) / "label_sensitivity.md")
