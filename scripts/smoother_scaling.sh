#!/usr/bin/env bash
# The batch smoother's time against the length of the log:
#   bash scripts/smoother_scaling.sh [--minutes "1 5 20"] [--out DIR]
# Per length T: a scenario in which the vehicle approaches the default T-shaped dock as in the
# default scenario, then holds its hover point in sight of the lights until 18 s before the end,
# and lands (the states of a batch are the frames with an estimate: a log of T minutes with the
# lights in view gives ~600 T states); simulated with synthetic detections (no images, so the
# figure is the estimator's own), then `smooth --detections`, timed whole (it runs the causal
# window first, as always). Prints the wall time, the speed as a multiple of real time and the
# time per state. Needs a built tree (scripts/build.sh); AUVDOCK_BIN=path/to/auvdock runs another.
set -euo pipefail
cd "$(dirname "$0")/.."
minutes="1 5 20"
out=out/smoother_scaling
while [[ $# -gt 0 ]]; do
  case "$1" in
    --minutes) minutes="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    *) echo "smoother_scaling.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
bin=${AUVDOCK_BIN:-build/bin/auvdock}
[[ -x "$bin" ]] || { echo "smoother_scaling.sh: $bin not found: run scripts/build.sh" >&2; exit 2; }
rm -rf "$out"
mkdir -p "$out"
dock=$(realpath data/docks/t_shape.yaml)
printf '%8s %8s %12s %14s %14s\n' "minutes" "states" "smooth [s]" "x real time" "ms per state"
for m in $minutes; do
  T=$((m * 60))
  cat > "$out/hover_${m}min.yaml" <<YAML
name: hover_${m}min
duration_s: $T
dock: $dock
trajectory:
  approach_end_s: 24.0
  descent_start_s: $((T - 18))
  touchdown_s: $((T - 2))
YAML
  "$bin" simulate --scenario "$out/hover_${m}min.yaml" --out "$out/data_${m}min" \
    --detections-only --quiet > /dev/null
  start=$(date +%s.%N)
  "$bin" smooth --dataset "$out/data_${m}min" --detections "$out/data_${m}min/detections.csv" \
    --out "$out/smooth_${m}min" --quiet > /dev/null
  end=$(date +%s.%N)
  states=$(( $(wc -l < "$out/smooth_${m}min/trajectory.tum") - 1 ))
  awk -v m="$m" -v n="$states" -v s="$start" -v e="$end" -v T="$T" 'BEGIN {
    w = e - s; printf "%8s %8d %12.1f %14.1f %14.2f\n", m, n, w, T / w, 1000 * w / n }'
done
