#!/usr/bin/env bash
# Render a report HTML file (or one of its figures, as the browser shows it) to a PNG with
# headless Chromium (Debian package `chromium`).
#
#   scripts/screenshot_report.sh REPORT.html OUT.png [WIDTHxHEIGHT]
#   scripts/screenshot_report.sh REPORT_DIR/car_following_indicator_vs_headway.png OUT.png 1200x680
#
# docs/report_first_screen.png and docs/report_aggressiveness.png were made this way (see
# docs/report_screenshots.md).
#
# Installs Chromium with apt-get when it is missing (needs root and Debian package access).
# The page is rendered offline: the report is self-contained, and networking features of
# Chromium are switched off. The optional third argument sets the window size in pixels
# (default 1280x4000); everything below the window height is cut off.
set -euo pipefail

usage() {
    echo "usage: $0 REPORT.html OUT.png [WIDTHxHEIGHT]" >&2
    exit 2
}

[[ $# -ge 2 && $# -le 3 ]] || usage
report=$1
out=$2
size=${3:-1280x4000}
[[ -f "$report" ]] || { echo "error: no such file: $report" >&2; exit 1; }
[[ "$size" =~ ^[0-9]+x[0-9]+$ ]] || { echo "error: size must be WIDTHxHEIGHT, got $size" >&2; exit 2; }

if ! command -v chromium >/dev/null 2>&1; then
    echo "chromium not found: installing the Debian package" >&2
    if [[ $(id -u) -ne 0 ]]; then
        echo "error: installing chromium needs root; run: apt-get install -y chromium" >&2
        exit 1
    fi
    export DEBIAN_FRONTEND=noninteractive
    if ! apt-get install -y --no-install-recommends chromium >&2; then
        apt-get update >&2
        apt-get install -y --no-install-recommends chromium >&2
    fi
fi

report_abs=$(realpath "$report")
out_dir=$(dirname "$out")
mkdir -p "$out_dir"
out_abs=$(realpath "$out_dir")/$(basename "$out")
profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT

chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
    --disable-background-networking --disable-component-update --disable-sync \
    --hide-scrollbars --user-data-dir="$profile" --window-size="${size/x/,}" \
    --screenshot="$out_abs" "file://$report_abs" >&2
[[ -s "$out_abs" ]] || { echo "error: chromium wrote no screenshot to $out_abs" >&2; exit 1; }
echo "$out_abs"
