"""What a black-box VUT costs: one law (the time-gap ACC, T = 2 s) as a Python controller, a
C FMU (FMI 2.0 and 3.0), a pythonfmu FMU and a process, against SUMO's own IDM.

Everything runs in this one process, the kinds interleaved round by round (so that a change
of machine load hits every kind alike), on the same scenes:

* ``env``: CarFollowing-v0 steps/s (random POV actions, resets included) and the VUT's mean
  wall time per call (the call budget's own measurement);
* ``resp``: one-step responses/s over the AYSS box (256 pairs in one SUMO, a fresh episode
  per state: what the pipeline's discriminability stage does);
* FMU resets: microseconds per episode start, ``reinstantiate`` vs ``reset``;
* ``--ladder N``: CPU seconds (this process and its children) and wall seconds of a 3-VUT
  ACC ladder (T = 0.6, 1.2, 2.0 s) through the pipeline, N transitions per run, one seed,
  per kind (python, C FMU, process);
* ``--verdict``: the same ladder at the default budget (``verdict`` until session 13:
  20,000 transitions, 4 seeds per VUT, adaptive up to 6), car-following, per kind: CPU and
  wall seconds to the verdict, and the verdict itself (the order against T = 2.0 > 1.2 >
  0.6, Kendall τ, whether the ends differ significantly). ``--keep DIR`` keeps the run folders.

    python benchmarks/vut_kinds.py [--steps 20000] [--repeats 3] [--states 5000] [--ladder 0]
    python benchmarks/vut_kinds.py --verdict [--kinds python,fmu2,process] [--keep DIR]
"""

from __future__ import annotations

import argparse
import resource
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from examples.fmu.build_fmu import build_acc_fmu, build_python_fmu  # noqa: E402
from sumo_ayss.config import EnvConfig  # noqa: E402
from sumo_ayss.envs import make_env  # noqa: E402
from sumo_ayss.vuts.catalog import BUILTIN_VUTS, ControllerSpec, VehicleType  # noqa: E402
from sumo_ayss.vuts.fmu_spec import FmuSpec  # noqa: E402
from sumo_ayss.vuts.process_spec import ProcessSpec  # noqa: E402

INPUTS = {"v_ego": "speed_mps", "gap": "gap_m", "v_rel": "rel_speed_mps", "has_lead": "has_leader"}
SIGNALS = ("speed_mps", "gap_m", "rel_speed_mps", "has_leader")


def kinds(folder: Path, time_gap_s: float = 2.0) -> dict[str, VehicleType]:
    """The same law as every VUT kind (SUMO's IDM pi1 as the reference)."""

    def fmu(path: Path) -> VehicleType:
        return VehicleType(
            controller=FmuSpec(
                max_accel_mps2=3.0,
                max_decel_mps2=6.0,
                path=str(path),
                inputs=INPUTS,
                outputs={"acceleration_mps2": "a_cmd"},
                parameters={"time_gap_s": time_gap_s},
            )
        )

    c2 = folder / "acc2.fmu"
    c3 = folder / "acc3.fmu"
    if not c2.exists():
        build_acc_fmu(c2, 2)
        build_acc_fmu(c3, 3)
    py = next(folder.glob("TimeGapAccPy.fmu"), None) or build_python_fmu(
        ROOT / "examples" / "fmu" / "acc_slave.py", folder
    )
    return {
        "SUMO IDM (pi1)": BUILTIN_VUTS["pi1"],
        "python controller": VehicleType(
            controller=ControllerSpec(
                "examples.acc_controller:TimeGapACC", 3.0, 6.0, params={"time_gap_s": time_gap_s}
            )
        ),
        "C FMU, FMI 2.0": fmu(c2),
        "C FMU, FMI 3.0": fmu(c3),
        "pythonfmu FMU": fmu(py),
        "process": VehicleType(
            controller=ProcessSpec(
                max_accel_mps2=3.0,
                max_decel_mps2=6.0,
                command=(
                    sys.executable,
                    str(ROOT / "examples" / "process_vut.py"),
                    "--time-gap",
                    str(time_gap_s),
                ),
                signals=SIGNALS,
            )
        ),
    }


def bench_env(vut: VehicleType, steps: int) -> tuple[float, float]:
    """(env steps/s, mean wall time per VUT call [µs]; nan for a SUMO model)."""
    env = make_env(EnvConfig(vut="v", vuts={"v": vut}), sumo_seed=0)  # type: ignore[arg-type]
    actions = np.random.default_rng(0).integers(0, env.action_space.n, size=steps)  # type: ignore[attr-defined]
    env.reset(seed=0)
    t0 = time.perf_counter()
    for a in actions:
        _, _, term, trunc, _ = env.step(int(a))
        if term or trunc:
            env.reset()
    dt = time.perf_counter() - t0
    driver = getattr(env._vut_law, "driver", None)  # type: ignore[attr-defined]
    call_us = driver.budget.mean_s * 1e6 if driver is not None else float("nan")
    env.close()
    return steps / dt, call_us


def bench_responses(vut: VehicleType, n: int) -> float:
    """One-step responses per second over random AYSS-box states (256 pairs)."""
    from sumo_ayss.scenarios.responses import measure_responses

    rng = np.random.default_rng(1)
    cfg = EnvConfig(vut="v", vuts={"v": vut})  # type: ignore[arg-type]
    v_pov, v_vut, h = rng.uniform(0, 30, n), rng.uniform(0, 30, n), rng.uniform(0.5, 5, n)
    t0 = time.perf_counter()
    measure_responses(cfg, "v", v_pov, v_vut, h)
    return n / (time.perf_counter() - t0)


def bench_fmu_resets(vut: VehicleType, mode: str, n: int = 2000) -> float:
    """Microseconds per episode start of an FMU in ``mode``."""
    import dataclasses

    spec = vut.controller
    assert isinstance(spec, FmuSpec)
    fmu = dataclasses.replace(spec, reset=mode).build("bench")
    fmu.reset()
    t0 = time.perf_counter()
    for _ in range(n):
        fmu.reset()
    dt = time.perf_counter() - t0
    fmu.close()
    return dt / n * 1e6


def cpu_s() -> float:
    own = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


LADDER_KINDS = {"python": "python controller", "fmu2": "C FMU, FMI 2.0", "process": "process"}
"""``--kinds`` names of the ladder's VUT kinds."""


def bench_ladder(
    folder: Path, kind: str, steps: int | None, out_root: Path | None = None
) -> tuple[float, float, str]:
    """(CPU s, wall s, ranking) of a 3-VUT ACC ladder through the pipeline.

    ``steps`` None runs the default budget (``fast`` since session 13) with its own seeds and
    adaptive seeding, and reads the verdict from ``order_check.json``.
    """
    import json

    import yaml

    from sumo_ayss.commands.pipeline import run_pipeline
    from sumo_ayss.commands.rank import main as rank_main
    from sumo_ayss.pipeline import load_pipeline

    out = (out_root or folder) / f"ladder_{kind.split()[0]}"
    gaps = {"tg06": 0.6, "tg12": 1.2, "tg20": 2.0}
    vuts = {}
    for name, tg in gaps.items():
        vt = kinds(folder, tg)[kind]
        from sumo_ayss.config.mapping import to_dict

        vuts[name] = to_dict(vt)
    exp = yaml.safe_load((ROOT / "configs" / "car_following.yaml").read_text())
    exp["env"]["vuts"] = vuts
    out.mkdir(parents=True, exist_ok=True)
    (out / "cf.yaml").write_text(yaml.safe_dump(exp))
    pipe: dict[str, object] = {
        "grid": {"cases": ["car_following"], "vuts": list(gaps)},
        "experiments": {"car_following": "cf.yaml"},
        "out": "runs",
        "expected_order": ["tg20", "tg12", "tg06"],
    }
    if steps is None:
        pipe["workers"] = 2
    else:
        pipe.update(total_timesteps=steps, eval_every=max(steps // 2, 1), workers=1)
        pipe["grid"] = {"cases": ["car_following"], "vuts": list(gaps), "seeds": [0]}
        del pipe["expected_order"]
    (out / "pipe.yaml").write_text(yaml.safe_dump(pipe))
    c0, w0 = cpu_s(), time.perf_counter()
    if steps is not None:
        statuses, report, *_ = run_pipeline(load_pipeline(out / "pipe.yaml"), live=False)
        states = sorted({s.state for s in statuses})
        return cpu_s() - c0, time.perf_counter() - w0, f"jobs {states}; report {report}"
    # `rank` runs the same pipeline and also writes order_check.json
    try:
        rank_main([str(out / "pipe.yaml"), "--no-live"])
    except SystemExit as e:  # rank exits 0 when every job finished, 1 otherwise
        if e.code not in (0, None):
            raise
    cpu, wall = cpu_s() - c0, time.perf_counter() - w0
    check = json.loads((out / "runs" / "order_check.json").read_text())
    row = next(c for c in check["cases"] if c["mode"] == "crossplay")
    seeds = len({p.name for p in (out / "runs" / "car_following" / "tg06").glob("seed_*")})
    sig = "significant" if row["ends_significant"] else "not significant"
    what = (
        f"seeds {seeds}; order {' > '.join(row['order'])}; tau {row['tau']:.2f}; "
        f"ends p {row['ends_p']:.2g} ({sig})"
    )
    return cpu, wall, what


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=20_000)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--states", type=int, default=5_000)
    parser.add_argument("--ladder", type=int, default=0, help="transitions per ladder run")
    parser.add_argument(
        "--verdict", action="store_true", help="only the ladder, at the default budget"
    )
    parser.add_argument(
        "--kinds", default=",".join(LADDER_KINDS), help=f"ladder kinds, of {list(LADDER_KINDS)}"
    )
    parser.add_argument("--keep", type=Path, default=None, help="keep the ladders' run folders")
    args = parser.parse_args()
    chosen = [k.strip() for k in args.kinds.split(",") if k.strip()]
    unknown = sorted(set(chosen) - set(LADDER_KINDS))
    if unknown:
        parser.error(f"--kinds: unknown {unknown}; choose from {list(LADDER_KINDS)}")
    if args.verdict:
        with tempfile.TemporaryDirectory(prefix="vut_kinds_") as tmp:
            print("3-VUT ACC ladder (T = 2.0 > 1.2 > 0.6 s), car-following, verdict budget:")
            print(f"{'VUT kind':<20}{'CPU s':>8}{'wall s':>8}  verdict")
            for key in chosen:
                name = LADDER_KINDS[key]
                cpu, wall, what = bench_ladder(Path(tmp), name, None, args.keep)
                print(f"{name:<20}{cpu:>8.1f}{wall:>8.1f}  {what}", flush=True)
        return
    with tempfile.TemporaryDirectory(prefix="vut_kinds_") as tmp:
        folder = Path(tmp)
        vuts = kinds(folder)
        env: dict[str, list[tuple[float, float]]] = {k: [] for k in vuts}
        resp: dict[str, list[float]] = {k: [] for k in vuts}
        for _ in range(args.repeats):  # interleaved rounds
            for name, vut in vuts.items():
                env[name].append(bench_env(vut, args.steps))
                if args.states:
                    resp[name].append(bench_responses(vut, args.states))
        ref = statistics.median(r for r, _ in env["python controller"])
        print(f"{'VUT kind':<20}{'env steps/s':>13}{'min':>9}{'max':>9}{'vs python':>11}"
              f"{'call µs':>9}{'resp/s':>9}")  # fmt: skip
        for name, runs in env.items():
            rates = [r for r, _ in runs]
            med = statistics.median(rates)
            call = statistics.median(c for _, c in runs)
            rs = f"{statistics.median(resp[name]):>9,.0f}" if resp[name] else f"{'-':>9}"
            print(
                f"{name:<20}{med:>13,.0f}{min(rates):>9,.0f}{max(rates):>9,.0f}"
                f"{med / ref:>11.0%}{call:>9.1f}{rs}"
            )
        print()
        print(f"{'FMU episode start':<20}{'reinstantiate µs':>18}{'reset µs':>10}")
        for name in ("C FMU, FMI 2.0", "C FMU, FMI 3.0", "pythonfmu FMU"):
            re_us = bench_fmu_resets(vuts[name], "reinstantiate")
            rs_us = bench_fmu_resets(vuts[name], "reset")
            print(f"{name:<20}{re_us:>18.1f}{rs_us:>10.1f}")
        if args.ladder:
            print()
            print(f"3-VUT ACC ladder, {args.ladder} transitions per run, 1 seed:")
            print(f"{'VUT kind':<20}{'CPU s':>8}{'wall s':>8}  jobs")
            for name in ("python controller", "C FMU, FMI 2.0", "process"):
                cpu, wall, what = bench_ladder(folder, name, args.ladder)
                print(f"{name:<20}{cpu:>8.1f}{wall:>8.1f}  {what}")


if __name__ == "__main__":
    main()
