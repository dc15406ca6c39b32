#!/usr/bin/env bash
# `python -m sumo_ayss.rank ARGS --no-run --no-live`, checked as the re-rank scripts need it
# (scripts/rerank_results.sh, scripts/finish_study_rerun.sh): exit status 1 with the ranking
# written is an incomplete grid (fine); a traceback, an "error:" line (rank refused its
# input) or any other status fails with exit 1, naming the call, so that a crashing rank
# never passes for a byte-identical re-rank (its old files would stay in place).
# Paths are relative to the repository root; PYTHON (default .venv/bin/python) runs it.
set -uo pipefail
cd "$(dirname "$0")/.."
err=$(mktemp)
rc=0
"${PYTHON:-.venv/bin/python}" -m sumo_ayss.rank "$@" --no-run --no-live > /dev/null 2> "$err" || rc=$?
cat "$err" >&2
if [ "$rc" -gt 1 ] || grep -q -e '^Traceback' -e '^error:' "$err"; then
  rm -f "$err"
  echo "rank $* failed (exit $rc)" >&2
  exit 1
fi
rm -f "$err"
