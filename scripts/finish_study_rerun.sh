#!/usr/bin/env bash
# Bring a re-run of a committed study into results/, the way issue 35 re-ran the paper pair:
#
#   bash scripts/finish_study_rerun.sh <finished run folder> <results/study> <config>
#   e.g. bash scripts/finish_study_rerun.sh /tmp/s11h35-run/runs/paper results/paper configs/paper.yaml
#
# 1. writes ayss_bins.csv beside every ayss.csv of the re-run that lacks one
#    (scripts/ayss_bins_from_csv.py: the evaluate stage's own reduction);
# 2. copies over the files git holds for the study today (the same names, nothing new: no
#    ayss.csv, checkpoints or policies), plus every run's ayss_bins.csv;
# 3. takes the re-run's ranking.csv/.md (with its paper-mode rows, drawn from the samples;
#    the pipeline writes none, so they are first ranked there: rank --no-run on the re-run)
#    and re-ranks as scripts/rerank_results.sh does (rank --no-run, paper rows carried over);
#    a crashing or refusing rank stops the script (exit 1, an incomplete grid, is fine);
# 4. regenerates the report as scripts/regenerate_reports.sh does (from the committed files:
#    the AYSS figures and the paper section now read ayss_bins.csv).
# Prints the files that are new to git.
set -euo pipefail
src=$(cd "$1" && pwd); study=${2%/}; config=$3
cd "$(dirname "$0")/.."
PY="${PYTHON:-.venv/bin/python}"
rank() { scripts/rank_no_run.sh "$@" || exit 1; }  # exit 1 (incomplete grid) passes
for b in $(cd "$src" && find . -name ayss.csv | sort); do
  [ -f "$src/$(dirname "$b")/ayss_bins.csv" ] || $PY scripts/ayss_bins_from_csv.py "$src/$(dirname "$b")" > /dev/null
done
git ls-files "$study" | grep -v "/report/" | while read -r f; do
  rel=${f#"$study"/}
  if [ -f "$src/$rel" ]; then cp "$src/$rel" "$f"; else echo "not in the re-run (kept as committed): $rel"; fi
done
for b in $(cd "$src" && find . -name ayss_bins.csv | sort); do
  mkdir -p "$study/$(dirname "$b")"
  cp "$src/$b" "$study/$b"
done
[ -f "$src/ranking.csv" ] || rank "$config" --out "$src"
cp "$src/ranking.csv" "$src/ranking.md" "$study/"
previous=$(mktemp)
cp "$study/ranking.csv" "$previous"
rank "$config" --out "$study"
$PY scripts/keep_paper_rows.py "$study" "$previous"
rm -f "$previous"
report=$study/report
title=$(head -1 "$report/summary.md" | sed 's/^# //')
rm -f "$report"/*.png "$report/report.html" "$report/summary.md"
$PY -m sumo_ayss.report "$study" --out "$report" --title "$title" > /dev/null
git status --short "$study" | grep -v '^ M' || true
