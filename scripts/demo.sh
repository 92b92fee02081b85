#!/usr/bin/env bash
# The README's first command: install what is missing, build, and run the main job on the
# built-in default scenario: simulate it, run the causal sliding-window estimator on it
# (trajectory, covariance, go/no-go decisions) and evaluate the result against the ground truth:
# accuracy by visibility stage, covariance consistency (NEES) and the go/no-go audit, with plots
# in out/demo/plots/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
# Only what the demo needs (the library and the command line); the tests and benchmarks are
# the second command's (scripts/test.sh).
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)" --target auvdock_cli
out=out/demo
rm -rf "$out"   # the demo's own folder from a previous demo run
mkdir -p "$out"
build/bin/auvdock simulate --scenario data/scenarios/default.yaml --out "$out/dataset"
build/bin/auvdock run --dataset "$out/dataset" --out "$out/run"
build/bin/auvdock evaluate --dataset "$out/dataset" --estimate "$out/run/trajectory.tum" \
  --covariance "$out/run/covariance.csv" --decisions "$out/run/decisions.csv" --plots "$out/plots"
