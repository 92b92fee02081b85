#!/usr/bin/env bash
# The README's first command: install what is missing, build, and run the main job on the
# built-in default scenario (`auvdock demo`): simulate it, run the paper's per-frame baseline, the
# causal sliding-window estimator (trajectory, covariance, go/no-go decisions) and the batch
# smoother on it, compute the Cramér-Rao bound of every pose, evaluate the three against the
# ground truth and the bound (accuracy by visibility stage, covariance consistency (NEES), the
# go/no-go audit) and print them side by side, with plots in out/demo/plots/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
# Only what the demo needs (the library and the command line); the tests and benchmarks are
# the second command's (scripts/test.sh).
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)" --target auvdock_cli
out=out/demo
rm -rf "$out"   # the demo's own folder from a previous demo run
# simulate, frontend (the paper's per-frame baseline), run (the causal window), smooth (the batch
# smoother), crlb (the bound), each evaluated; one table side by side; plots of run in
# out/demo/plots/.
build/bin/auvdock demo --out "$out"
