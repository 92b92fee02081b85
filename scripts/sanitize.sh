#!/usr/bin/env bash
# The unit tests under AddressSanitizer + UndefinedBehaviorSanitizer (CI runs this after
# scripts/test.sh): install what is missing, build into ./build-sanitize with
# AUVDOCK_SANITIZE=ON (-O1, line tables, no benchmarks), run `ctest -L unit`. Any sanitizer report
# aborts its test, so the run fails. Extra arguments go to ctest (e.g. -R Pnp).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" -DAUVDOCK_SANITIZE=ON \
  -DAUVDOCK_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build-sanitize -j"$(nproc)"
# halt_on_error: the first report ends the test (UBSan is already -fno-sanitize-recover).
export ASAN_OPTIONS="halt_on_error=1:detect_stack_use_after_return=1:strict_string_checks=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
cd build-sanitize && ctest -L unit --output-on-failure -j"$(nproc)" "$@"
