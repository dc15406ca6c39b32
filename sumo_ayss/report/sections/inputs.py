"""Blocks of the inputs section: runs per case and VUT, training budgets, versions."""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping, Sequence
from pathlib import Path

from sumo_ayss.report.blocks import Block, BulletList, Heading, Paragraph, Table
from sumo_ayss.report.sections.common import display_path, seeds_text
from sumo_ayss.run_folder import RunFolder, RunRecord
from sumo_ayss.training.trust import (
    NOISE_SE,
    TRUSTED_TIMESTEPS,
    improving_runs,
    training_status,
)

__all__ = ["inputs_blocks", "training_table"]


def training_table(runs: Sequence[RunRecord]) -> Table:
    rows = []
    for r in runs:
        t = r.training
        rows.append(
            (
                r.case,
                r.label,
                "?" if t.total_timesteps is None else f"{t.total_timesteps:,}",
                "?" if t.eval_every is None else f"{t.eval_every:,}",
                str(t.n_candidates),
                "?" if t.spcp_step is None else f"{t.spcp_step:,}",
                "?" if t.last_step is None else f"{t.last_step:,}",
                training_status(t),
            )
        )
    return Table(
        "Training budget and SPCP per run",
        (
            "case",
            "run",
            "total_timesteps",
            "eval_every",
            "candidates",
            "SPCP step",
            "last candidate step",
            "SPCP",
        ),
        tuple(rows),
        (False, False, True, True, True, True, True, False),
        note=(
            "Budgets in training transitions. SPCP: 'may still improve' when it is the last "
            "candidate; 'plateau' when the last candidate's mean evaluation reward is within "
            f"{NOISE_SE:g} standard errors (SE, the SPCP's std / sqrt(episodes)) of the "
            "SPCP's; 'peaked' when it is further below. Below "
            f"{TRUSTED_TIMESTEPS:,} transitions (the smallest budget that ordered every "
            "validation ladder right, with 4 seeds per VUT) verdicts are not to be trusted."
        ),
    )


def inputs_blocks(
    runs: Sequence[RunRecord], groups: Mapping[str, Mapping[str, list[RunRecord]]], out_dir: Path
) -> list[Block]:
    blocks: list[Block] = [Heading("Inputs", 2, "inputs")]
    rows = []
    for case, by_vut in groups.items():
        for vut, members in by_vut.items():
            desc = next((r.vut_description for r in members if r.vut_description), "")
            complete = sum(1 for r in members if not r.problems)
            rows.append(
                (case, vut, desc or "—", str(len(members)), seeds_text(members), str(complete))
            )
    blocks.append(
        Table(
            "Runs per case and VUT (seeds are pooled per VUT)",
            ("case", "VUT", "VUT definition", "seeds", "seed values", "complete runs"),
            tuple(rows),
            (False, False, False, True, False, True),
        )
    )
    blocks.append(training_table(runs))
    last = improving_runs([(f"{r.case} {r.label}", r.training) for r in runs])
    if last:
        blocks.append(
            BulletList(
                tuple(last),
                f"SPCPs that were the last candidate of their training ({len(last)} of "
                f"{len(runs)})",
            )
        )
    blocks.append(
        BulletList(
            tuple(display_path(r.path, out_dir) for r in runs),
            f"Run folders used ({len(runs)}, relative to this report's folder)",
        )
    )
    versions: dict[str, Counter[str]] = {}
    for run in runs:
        for key, value in run.versions.items():
            versions.setdefault(key, Counter())[value] += 1
    with_versions = sum(1 for r in runs if r.versions)
    if versions:
        v_rows = tuple(
            (key, "; ".join(f"{v} ({n} runs)" if len(c) > 1 else v for v, n in c.most_common()))
            for key, c in sorted(versions.items())
        )
        blocks.append(
            Table(
                f"Versions ({RunFolder.versions.name} of {with_versions} of {len(runs)} runs)",
                ("package", "version"),
                v_rows,
            )
        )
    else:
        blocks.append(Paragraph(f"No run holds a {RunFolder.versions.name}: versions unknown."))
    return blocks
