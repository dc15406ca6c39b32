#!/usr/bin/env bash
# Check the Dockerfile's install steps without a Docker engine: run them, in the same
# order, in a fresh virtual environment, then run the image's entry point on a tiny job,
# and lint the Dockerfile with hadolint. Usage: bash docker/check_install.sh
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
python3 -m venv "$work/venv"
pip="$work/venv/bin/pip"
# The image takes torch from PyTorch's CPU index; this machine has the same build on disk.
"$pip" install --quiet torch==2.13.0
mkdir -p "$work/src"
cp "$root/pyproject.toml" "$root/README.md" "$work/src/"
(cd "$work/src" && mkdir sumo_ayss && touch sumo_ayss/__init__.py \
  && "$pip" install --quiet . && "$pip" uninstall --quiet -y sumo_ayss \
  && rm -rf sumo_ayss build ./*.egg-info)
cp -r "$root/sumo_ayss" "$root/configs" "$root/networks" "$root/routes" "$work/src/"
(cd "$work/src" && "$pip" install --quiet --no-deps -e .)
export MPLBACKEND=Agg
cd "$work"
"$work/venv/bin/sumo-ayss" --help
"$work/venv/bin/sumo-ayss" train --config "$work/src/configs/car_following.yaml" \
  --vut pi2 --seed 0 --out "$work/results" --total-timesteps 1200 --eval-every 600 --no-progress
test -f "$work/results/car_following/pi2/seed_0/spcp.json"
"$root/.venv/bin/hadolint" "$root/docker/Dockerfile"
echo "docker install steps: OK"
