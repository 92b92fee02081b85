#!/usr/bin/env bash
# Fuzzes every parser of outside input with libFuzzer (fuzz/*_fuzzer.cc), each target for SECONDS:
#   bash scripts/fuzz.sh SECONDS [TARGET ...]      (TARGET: e.g. scenario, sensor_csv; default all)
# Installs what is missing (clang for libFuzzer), builds the library and the targets out of tree
# in ./build-fuzz with AUVDOCK_FUZZ=ON (-fsanitize=fuzzer-no-link,address,undefined, -O1), and runs
# each target on its corpus, build-fuzz/corpus/TARGET, seeded from fuzz/seeds/TARGET, data/ and
# tests/data/ (kept between calls: each call goes on where the last one stopped).
# A finding (a crash, a sanitizer report, an exception other than InputError, a hang of more than
# 10 s or more than 2 GB) is saved as build-fuzz/findings/TARGET/crash-* (or timeout-*, oom-*) and
# fails the script; replay one with build-fuzz/bin/TARGET_fuzzer FILE. Prints one line per target:
# executions, executions per second, coverage (edges) and features, corpus size, findings.
set -euo pipefail
cd "$(dirname "$0")/.."
usage="usage: bash scripts/fuzz.sh SECONDS [TARGET ...]"
[[ $# -ge 1 && "$1" =~ ^[0-9]+$ && "$1" -gt 0 ]] || { echo "fuzz.sh: $usage" >&2; exit 2; }
seconds=$1
shift
all=(scenario run_config calibration camera_file dock sensor_csv euroc_sensor_yaml tum detections
     pose_covariance decisions rejections light_labels)
targets=("$@")
[[ ${#targets[@]} -gt 0 ]] || targets=("${all[@]}")
for t in "${targets[@]}"; do
  [[ " ${all[*]} " == *" $t "* ]] || { echo "fuzz.sh: no target '$t' (one of: ${all[*]})" >&2; exit 2; }
done

bash scripts/install_deps.sh
if ! command -v clang++ >/dev/null; then
  echo "fuzz.sh: installing clang (libFuzzer)"
  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends clang >/dev/null
fi
cmake -S . -B build-fuzz -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" -DAUVDOCK_FUZZ=ON \
  -DAUVDOCK_BUILD_TESTS=OFF -DAUVDOCK_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build-fuzz -j"$(nproc)" --target "${targets[@]/%/_fuzzer}"

# Seeds beyond fuzz/seeds/TARGET: the shipped files of each format, and the EuRoC sensor.yaml
# files with the byte that selects them (even: camera, odd: IMU).
seed_dirs() {
  case "$1" in
    scenario) echo data/scenarios ;;
    run_config) echo data/estimator ;;
    dock) echo data/docks ;;
  esac
}
prepare_corpus() {
  local t=$1 corpus=build-fuzz/corpus/$1
  mkdir -p "$corpus"
  if [[ $t == euroc_sensor_yaml ]]; then
    { printf '\x00'; cat tests/data/euroc_mini/mav0/cam0/sensor.yaml; } > "$corpus/seed_cam0"
    { printf '\x01'; cat tests/data/euroc_mini/mav0/imu0/sensor.yaml; } > "$corpus/seed_imu0"
  fi
}

# The parsers' scratch files (fuzz_parsers.h) stay in the build folder.
export TMPDIR="$PWD/build-fuzz/tmp"
mkdir -p "$TMPDIR"
export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
failed=0
summary=()
for t in "${targets[@]}"; do
  prepare_corpus "$t"
  findings=build-fuzz/findings/$t
  rm -rf "$findings"   # the last call's findings (its log says what they were)
  mkdir -p "$findings"
  log=build-fuzz/findings/$t.log
  dirs=("build-fuzz/corpus/$t")
  [[ -d fuzz/seeds/$t ]] && dirs+=("fuzz/seeds/$t")
  for d in $(seed_dirs "$t"); do dirs+=("$d"); done
  echo "fuzz.sh: $t for $seconds s"
  status=0
  "build-fuzz/bin/${t}_fuzzer" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$findings/" "${dirs[@]}" > "$log" 2>&1 || status=$?
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | cut -d' ' -f2)
  ft=$(grep -o 'ft: [0-9]*' "$log" | tail -1 | cut -d' ' -f2)
  corpus_size=$(find "build-fuzz/corpus/$t" -type f | wc -l)
  found=$(find "$findings" -type f | wc -l)
  line=$(printf '%-18s %10s runs %7s/s  cov %5s  ft %6s  corpus %5s  findings %s' \
    "$t" "${runs:-?}" "${rate:-?}" "${cov:-?}" "${ft:-?}" "$corpus_size" "$found")
  summary+=("$line")
  if [[ $status -ne 0 || $found -gt 0 ]]; then
    failed=1
    echo "fuzz.sh: $t: FINDING (exit $status), see $log and $findings/" >&2
    grep -m3 -E "ERROR|SUMMARY|auvdock fuzz" "$log" >&2 || true
  fi
done
echo
printf '%s\n' "${summary[@]}"
exit $failed
