#!/usr/bin/env bash
# Regenerate every committed study's report (results/**/report/) with the current renderer,
# from its committed run folders and cross-play tables (no training, no cross-play run), each
# under its own title. The AYSS samples (ayss.csv) are not committed, so the paper mode's
# sections say that there are none. Old figures are removed first: a figure the current
# report does not draw must not stay beside it.
set -euo pipefail
cd "$(dirname "$0")/.."
PY="${PYTHON:-.venv/bin/python}"
find results -path '*/report/summary.md' | sort | while read -r summary; do
  report=$(dirname "$summary")
  study=$(dirname "$report")
  title=$(head -1 "$summary" | sed 's/^# //')
  rm -f "$report"/*.png "$report/report.html" "$report/summary.md"
  $PY -m sumo_ayss.report "$study" --out "$report" --title "$title" > /dev/null
  echo "$report"
done
