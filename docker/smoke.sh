#!/usr/bin/env bash
# Smoke test of the image: build docker/Dockerfile with whichever engine runs here (docker,
# else podman), run a tiny pipeline inside it (both cases, pi1 and pi2, one seed, 1,200
# transitions; cross-play and the report included), and check what it wrote.
#
#   bash docker/smoke.sh
#   ENGINE=podman ENGINE_ARGS="--storage-driver vfs" BUILD_ARGS="--network host" \
#       bash docker/smoke.sh        # podman on a machine like the development one
#
# Environment: ENGINE (docker or podman; default the first that answers `info`),
# ENGINE_ARGS (global engine options, e.g. podman's --storage-driver vfs), BUILD_ARGS (extra
# `build` options), IMAGE (tag, default sumo-ayss-smoke), KEEP_IMAGE=1 (keep the image;
# by default it is removed: with podman's vfs driver a build takes over 20 GB of disk).
# Expect minutes for the build and a few minutes for the pipeline on 2 cores.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
image=${IMAGE:-sumo-ayss-smoke}
engine=${ENGINE:-}
if [[ -z "$engine" ]]; then
  for candidate in docker podman; do
    if command -v "$candidate" >/dev/null 2>&1 && "$candidate" info >/dev/null 2>&1; then
      engine=$candidate
      break
    fi
  done
fi
if [[ -z "$engine" ]]; then
  echo "error: neither docker nor podman can run containers here (a docker client without" \
    "an engine does not count); see docker/README.md for podman" >&2
  exit 1
fi
command -v "$engine" >/dev/null 2>&1 || { echo "error: ENGINE=$engine not found" >&2; exit 1; }
read -r -a engine_args <<< "${ENGINE_ARGS:-}"
read -r -a build_args <<< "${BUILD_ARGS:-}"

out=$(mktemp -d)
cleanup() {
  rm -rf "$out"
  if [[ "${KEEP_IMAGE:-0}" != 1 ]]; then
    "$engine" "${engine_args[@]}" rmi -f "$image" >/dev/null 2>&1 || true
  fi
}
trap cleanup EXIT

echo "building $image with $engine" >&2
"$engine" "${engine_args[@]}" build "${build_args[@]}" -f "$root/docker/Dockerfile" \
  -t "$image" "$root"

"$engine" "${engine_args[@]}" run --rm "$image" --help >/dev/null
"$engine" "${engine_args[@]}" run --rm --entrypoint python "$image" -c "import ray" \
  || { echo "error: the image lacks the ray extra" >&2; exit 1; }

"$engine" "${engine_args[@]}" run --rm --user "$(id -u):$(id -g)" -v "$out:/out" "$image" \
  pipeline configs/demo.yaml --out /out/smoke --seeds 0 --workers 2 --no-live \
  --total-timesteps 1200 --eval-every 600 --n-outcome 10 --n-ayss 2000 | tee "$out/stdout.txt"

run="$out/smoke/car_following/pi1/seed_0"
test -s "$out/smoke/report/report.html"
test -f "$run/spcp.json"
test -f "$out/smoke/car_following/crossplay.csv"
grep -q "total_timesteps: 1200" "$run/config.yaml"
grep -q "leaderboard (" "$out/stdout.txt"
[[ $(stat -c %u "$run/spcp.json") == "$(id -u)" ]] \
  || { echo "error: files on the volume are not the caller's" >&2; exit 1; }
echo "docker smoke test ($engine): OK"
