#!/usr/bin/env bash
# Re-rank every committed study in results/ with the current scores, from its committed
# run folders and cross-play tables (no training, no cross-play run: rank --no-run).
# Writes each study's ranking.csv, ranking.md and, with a known order, order_check.json.
set -euo pipefail
cd "$(dirname "$0")/.."
# Each study through scripts/rank_no_run.sh: an incomplete grid passes, a crash or a refusal
# stops this script.
rank() { scripts/rank_no_run.sh "$@" || exit 1; }
rank configs/ladders/min_gap.yaml --out results/ladders/min_gap_a
rank configs/ladders/min_gap.yaml --seeds 100 101 102 --out results/ladders/min_gap_b
rank configs/ladders/time_headway.yaml --out results/ladders/time_headway_a
rank configs/ladders/time_headway.yaml --seeds 100 101 102 --out results/ladders/time_headway_b
for study in braking reaction acc_time_gap; do
  for run in a b; do
    if [ -d "results/ladders/${study}_${run}" ]; then
      seeds=(201 202 203); [ "$run" = b ] && seeds=(301 302 303)
      rank "configs/ladders/${study}.yaml" --seeds "${seeds[@]}" --out "results/ladders/${study}_${run}"
    fi
  done
done
# The paper pair's studies also hold paper-mode rows, which need ayss.csv (not committed):
# they are carried over from the previous ranking.csv (scripts/keep_paper_rows.py).
paper_study() {
  local config=$1 study=$2 previous
  previous=$(mktemp)
  cp "$study/ranking.csv" "$previous"
  rank "$config" --out "$study"
  ${PYTHON:-.venv/bin/python} scripts/keep_paper_rows.py "$study" "$previous"
  rm -f "$previous"
}
paper_study configs/paper.yaml results/paper
paper_study configs/paper_fidelity.yaml results/paper_fidelity
paper_study configs/fidelity_ablation/sumo_vut.yaml results/fidelity_ablation/sumo_vut
paper_study configs/fidelity_ablation/clipped_pov.yaml results/fidelity_ablation/clipped_pov
rank configs/overbraking.yaml --out results/overbraking  # issue 33
# issue 33: the default-budget ladders re-run with the follower (results/follower_ladders/README.md)
for study in braking reaction acc_time_gap min_gap; do
  if [ -d "results/follower_ladders/$study" ]; then
    rank "configs/ladders/$study.yaml" --budget verdict --seeds 401 402 403 404 --max-seeds 4 \
      --out "results/follower_ladders/$study"
  fi
done
rank configs/ladders/braking_lead_and_cut_in.yaml --out results/ladders/braking_lead_and_cut_in_a  # issue 39
rank configs/ladders/braking_lead_and_cut_in_safe.yaml --out results/ladders/braking_lead_and_cut_in_b  # issue 39, session 11
rank configs/ladders/acc_time_gap_lead_and_cut_in.yaml --out results/ladders/acc_time_gap_lead_and_cut_in_a  # issue 39, session 11
