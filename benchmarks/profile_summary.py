"""Where one training job spends its time: a py-spy profile summed into pipeline phases.

Record a short job with py-spy's raw (folded-stack) output, then summarise it:

    py-spy record -r 200 -f raw -o /tmp/job.txt -- \\
        python -m sumo_ayss.train --config configs/car_following.yaml --vut pi1 --seed 0 \\
        --out /tmp/runs --total-timesteps 10000 --eval-every 5000 --no-progress
    python benchmarks/profile_summary.py /tmp/job.txt

Each sample goes to the first phase (in the order of :data:`PHASES`) with a frame on its
stack that matches; a phase's share is its samples over all samples. py-spy samples the
stack at a fixed rate whether or not the process holds a core, so shares are of wall time.
Only the main thread counts (the job's work runs there).
"""

from __future__ import annotations

import argparse
from collections import Counter
from pathlib import Path

#: (phase, frame substrings; a sample belongs to the first phase with a matching frame).
#: Inside the gradient step, the sub-phases come first.
PHASES: list[tuple[str, tuple[str, ...]]] = [
    ("imports (interpreter start, torch, SB3, ...)", ("_find_and_load",)),
    ("candidates: evaluation on the pairs", ("evaluate_on_vec", "run_episodes")),
    (
        "candidates: checkpoint I/O (model.zip, replay.pkl, state, eval.csv)",
        ("atomic_model_save", "save_resume_state", "write_eval_table", "_prune_replays"),
    ),
    ("candidates: cut and restart the pairs", ("PairsCollector.evaluate",)),
    ("selection + spcp.zip", ("Trainer.select",)),
    ("gradient step: PER sample (sum tree, gather, tensors)", ("PrioritizedReplayBuffer.sample",)),
    ("gradient step: PER priority update", ("update_priorities",)),
    ("gradient step: backward", ("backward",)),
    ("gradient step: Adam", ("Adam.step", "Optimizer.zero_grad", "_use_grad")),
    ("gradient step: gradient clipping", ("_clip_grad_norm",)),
    ("gradient step: forward passes + loss + rest", ("AyssDQN.train",)),
    ("collection: action selection (epsilon-greedy, Q forward)", ("_sample_action",)),
    ("collection: env step (SUMO + pairs)", ("step_wait",)),
    ("collection: store transition (replay add)", ("_store_transition",)),
    ("collection: SB3 loop, logging, callbacks", ("collect_rollouts", "dump_logs")),
    ("setup: SUMO start, network, model", ("Trainer.__init__", "new_model", "write_metadata")),
    ("learn(): other", ("OffPolicyAlgorithm.learn",)),
]


def summarise(lines: list[str]) -> tuple[Counter[str], int]:
    """Samples per phase, and the total, from py-spy raw lines ``frame;frame;... count``.

    Only the main thread's samples count (stacks rooted in ``runpy``, or in
    ``multiprocessing``'s ``spawn_main`` for a pipeline worker recorded with ``py-spy record
    -p <pid>``); the tensorboard writer's thread and stack-less samples are left out.
    """
    counts: Counter[str] = Counter()
    total = 0
    for line in lines:
        line = line.strip()
        if not line.startswith("_run_module_as_main") and "spawn_main" not in line[:120]:
            continue
        stack, _, count_text = line.rpartition(" ")
        count = int(count_text)
        total += count
        for phase, needles in PHASES:
            if any(needle in stack for needle in needles):
                counts[phase] += count
                break
        else:
            counts["other"] += count
    return counts, total


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("profile", type=Path, help="py-spy record -f raw output")
    parser.add_argument("--rate", type=float, default=200.0, help="py-spy -r (samples/s)")
    args = parser.parse_args()
    counts, total = summarise(args.profile.read_text().splitlines())
    print(f"{total} samples = {total / args.rate:.1f} s at {args.rate:g} samples/s")
    print(f"{'phase':<66}{'s':>7}{'share':>8}")
    order = [phase for phase, _ in PHASES] + ["other"]
    for phase in order:
        if counts[phase]:
            n = counts[phase]
            print(f"{phase:<66}{n / args.rate:>7.2f}{n / total:>8.1%}")


if __name__ == "__main__":
    main()
