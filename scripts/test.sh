#!/usr/bin/env bash
# The README's second command: install what is missing, build, run the whole ctest suite.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
bash scripts/build.sh
cd build && ctest --output-on-failure -j"$(nproc)"
