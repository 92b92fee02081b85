#!/usr/bin/env bash
# Which sensor buys what: `auvdock run` on the full image pipeline over several seeds with the
# navigation sensors switched on one group at a time, then with faults and with noisier sensors:
#   bash scripts/ablation.sh [--seeds "1 2 3 4 5"] [--out DIR] [--reuse-datasets]
#                            [--commands "run smooth"]
# Rows:
#   vision+IMU             depth, DVL, USBL and SBL off (estimator `use_*: false`)
#   +depth, +DVL, +acoustic  vision + IMU + that one group (acoustic: USBL and SBL)
#   all                    every sensor (the default options)
#   all, faults            data/scenarios/sensor_faults.yaml (DVL spikes and biases, depth bias,
#                          USBL outliers and latency, IMU errors the estimator does not model)
#   all, 3x noise, adapt   the default datasets with depth and DVL three times noisier than the
#                          calibration says (its sigma_m and sigma_mps divided by 3), adaptation on
#   all, 3x noise, fixed   the same with adaptive_depth_noise and adaptive_dvl_noise off
# Per row, the means over the seeds of the position RMSE and the largest position error (any
# axis, over the seeds) by visibility stage, the same for the attitude, the mean NEES of the
# whole run, and the unsafe GO count. Needs a built tree (scripts/build.sh); each dataset is
# simulated once into OUT/<scenario>/seed_N/dataset (--reuse-datasets keeps existing ones).
set -euo pipefail
cd "$(dirname "$0")/.."
seeds="1 2 3 4 5"
out=out/ablation
reuse=0
commands="run"
while [[ $# -gt 0 ]]; do
  case "$1" in
    --seeds) seeds="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --reuse-datasets) reuse=1; shift ;;
    --commands) commands="$2"; shift 2 ;;
    *) echo "ablation.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
bin=${AUVDOCK_BIN:-build/bin/auvdock}
[[ -x "$bin" ]] || { echo "ablation.sh: $bin not found: run scripts/build.sh" >&2; exit 2; }
mkdir -p "$out/configs"

write_config() {  # name, then estimator keys
  local name="$1"; shift
  { echo "estimator:"; for key in "$@"; do echo "  $key"; done; } > "$out/configs/$name.yaml"
}
write_config vision_imu "use_depth: false" "use_dvl: false" "use_usbl: false" "use_sbl: false"
write_config plus_depth "use_dvl: false" "use_usbl: false" "use_sbl: false"
write_config plus_dvl "use_depth: false" "use_usbl: false" "use_sbl: false"
write_config plus_acoustic "use_depth: false" "use_dvl: false"
write_config all "window_size: 10"
write_config fixed_noise "adaptive_depth_noise: false" "adaptive_dvl_noise: false"

simulate() {  # scenario name, seed
  local dir="$out/$1/seed_$2/dataset"
  if [[ $reuse == 1 && -f "$dir/groundtruth.tum" ]]; then return; fi
  rm -rf "$dir"
  "$bin" simulate --scenario "data/scenarios/$1.yaml" --seed "$2" --out "$dir" --quiet > /dev/null
}

# A copy of a dataset (links to its files) whose calibration says depth and DVL are 3x less
# noisy than they are.
understated_noise() {  # source dataset, target dataset
  rm -rf "$2"
  mkdir -p "$2"
  for entry in "$1"/*; do
    [[ "$(basename "$entry")" == calibration.yaml ]] || ln -s "$(realpath "$entry")" "$2/"
  done
  /usr/bin/python3 - "$1/calibration.yaml" "$2/calibration.yaml" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
def third(match):
    return f"{match.group(1)}{float(match.group(2)) / 3.0!r}"
text, n = re.subn(r"^(\s+sigma_(?:m|mps):\s*)([0-9.eE+-]+)", third, text, flags=re.M)
if n != 2:
    sys.exit(f"ablation.sh: expected the depth sigma_m and the DVL sigma_mps in {sys.argv[1]}, found {n}")
open(sys.argv[2], "w").write(text)
PY
}

run_row() {  # row name, dataset, config
  local row="$1" dataset="$2" config="$3"
  for command in $commands; do
    local result="$out/rows/$row/$(basename "$(dirname "$dataset")")/$command"
    rm -rf "$result"
    mkdir -p "$(dirname "$result")"
    "$bin" "$command" --dataset "$dataset" --out "$result" --config "$out/configs/$config.yaml" \
      --quiet > /dev/null
    "$bin" evaluate --dataset "$dataset" --estimate "$result/trajectory.tum" \
      --covariance "$result/covariance.csv" --decisions "$result/decisions.csv" \
      --json > "$result/evaluation.json"
  done
}

for seed in $seeds; do
  simulate default "$seed"
  simulate sensor_faults "$seed"
  base="$out/default/seed_$seed/dataset"
  noisy="$out/default_3x_noise/seed_$seed/dataset"
  understated_noise "$base" "$noisy"
  run_row vision_imu "$base" vision_imu
  run_row plus_depth "$base" plus_depth
  run_row plus_dvl "$base" plus_dvl
  run_row plus_acoustic "$base" plus_acoustic
  run_row all "$base" all
  run_row all_faults "$out/sensor_faults/seed_$seed/dataset" all
  run_row all_3x_noise_adapt "$noisy" all
  run_row all_3x_noise_fixed "$noisy" fixed_noise
done

/usr/bin/python3 - "$out" $commands -- $seeds <<'PY'
import json, sys
out = sys.argv[1]
split = sys.argv.index("--")
commands, seeds = sys.argv[2:split], sys.argv[split + 1:]
rows = ["vision_imu", "plus_depth", "plus_dvl", "plus_acoustic", "all", "all_faults",
        "all_3x_noise_adapt", "all_3x_noise_fixed"]
stages = ["stereo_only", "both", "mono_only", "neither"]
for command in commands:
    for quantity, unit, scale, rmse_key, max_key in [
            ("position", "mm", 1e3, "pos_rmse_m", "pos_max_abs_m"),
            ("attitude", "mrad", 1e3, "att_rmse_rad", "att_max_abs_rad")]:
        print(f"\n{command}: {quantity} RMSE / max [{unit}] by stage (mean RMSE over seeds {' '.join(seeds)}, "
              f"max over seeds and axes); mean NEES; unsafe GO")
        print(f"{'row':>20} " + " ".join(f"{s:>15}" for s in stages) + f" {'NEES':>6} {'unsafe':>6}")
        for row in rows:
            cells, nees, unsafe = [], [], 0
            per_stage = {s: ([], []) for s in stages}
            for seed in seeds:
                with open(f"{out}/rows/{row}/seed_{seed}/{command}/evaluation.json") as f:
                    r = json.load(f)
                nees.append(r["nees_mean"])
                unsafe += r["decisions"]["n_go_unsafe"]
                for s in stages:
                    st = r["stages"].get(s)
                    if st is None:
                        continue
                    per_stage[s][0].append(scale * st[rmse_key])
                    per_stage[s][1].append(scale * max(st[max_key]))
            for s in stages:
                rmse, worst = per_stage[s]
                cells.append(f"{sum(rmse) / len(rmse):7.1f} / {max(worst):5.1f}" if rmse
                             else f"{'-':>15}")
            print(f"{row:>20} " + " ".join(cells) + f" {sum(nees) / len(nees):6.2f} {unsafe:6d}")
PY
