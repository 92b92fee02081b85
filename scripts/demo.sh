#!/usr/bin/env bash
# The README's first command: install what is missing, build, and run the main job on the
# built-in default scenario. For now: simulate it and evaluate the ground truth against itself
# (the full estimator demo arrives with the estimator).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
bash scripts/build.sh
out=out/demo
rm -rf "$out"   # the demo's own folder from a previous demo run
mkdir -p out
build/bin/auvdock simulate --scenario data/scenarios/default.yaml --out "$out"
build/bin/auvdock evaluate --dataset "$out" --estimate "$out/groundtruth.tum"
