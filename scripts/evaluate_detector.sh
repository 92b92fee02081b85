#!/usr/bin/env bash
# The real-water light detector (`auvdock detect`) measured on simulated images against the
# simulator's ground truth, over several seeds of a scenario (by default the randomised one:
# each seed draws another look per camera, sim/render_look.h):
#   bash scripts/evaluate_detector.sh [--scenario FILE] [--seeds "1 2 3"] [--out DIR]
#                                     [--max-range M] [--cameras "cam0 cam1 cam2"]
#                                     [-- extra detect options]
# Needs a built tree (scripts/build.sh). Per seed and camera it runs `detect --labels
# groundtruth/<camera>_lights.csv --label-max-range M` (lights farther than M, 8 m by default,
# are not required: a detection of one is a hit) into OUT/seed_N/<camera>/, then prints recall,
# precision, centroid RMS and the mono pose rate per seed and camera, and the pooled figures;
# and how honest the mono poses are (scripts/detector_pose_nees.py: median position error
# against the truth, mean NEES in the covariance that detect reports).
set -euo pipefail
cd "$(dirname "$0")/.."
scenario=data/scenarios/randomized.yaml
seeds="1 2 3"
out=out/detector
max_range=8
cameras="cam0 cam1 cam2"
extra=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --scenario) scenario="$2"; shift 2 ;;
    --seeds) seeds="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --max-range) max_range="$2"; shift 2 ;;
    --cameras) cameras="$2"; shift 2 ;;
    --) shift; extra=("$@"); break ;;
    *) echo "evaluate_detector.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
bin=${AUVDOCK_BIN:-build/bin/auvdock}   # another build: AUVDOCK_BIN=path/to/auvdock
[[ -x "$bin" ]] || { echo "evaluate_detector.sh: $bin not found: run scripts/build.sh" >&2; exit 2; }
mkdir -p "$out"
for seed in $seeds; do
  dir="$out/seed_$seed"
  if [[ ! -f "$dir/dataset/groundtruth/cam0_lights.csv" ]]; then
    rm -rf "$dir"   # this script's own folder from an earlier call
    "$bin" simulate --scenario "$scenario" --seed "$seed" --out "$dir/dataset" --quiet > /dev/null
  fi
  for camera in $cameras; do
    rm -rf "$dir/$camera"
    "$bin" detect --images "$dir/dataset/$camera/data/*.png" --calib "$dir/dataset/calibration.yaml" \
      --camera "$camera" --dock "$dir/dataset/dock.yaml" \
      --labels "$dir/dataset/groundtruth/${camera}_lights.csv" --label-max-range "$max_range" \
      --out "$dir/$camera" --quiet "${extra[@]}" > /dev/null
    /usr/bin/python3 scripts/detector_pose_nees.py --dataset "$dir/dataset" --camera "$camera" \
      --detect "$dir/$camera" > "$dir/$camera/pose_nees.json"
  done
done
/usr/bin/python3 - "$out" "$max_range" $cameras -- $seeds <<'PY'
import json, sys
out, max_range = sys.argv[1], sys.argv[2]
split = sys.argv.index("--")
cameras, seeds = sys.argv[3:split], sys.argv[split + 1:]
print(f"detector on renders ({out}), lights nearer than {max_range} m required")
print(f"{'seed':>5} {'camera':>7} {'recall':>8} {'precision':>10} {'rms [px]':>9} "
      f"{'median':>7} {'pose':>11} {'ms/frame':>9} {'pose mm':>8} {'NEES':>7} {'>97.5%':>7}")
total = dict(ok=0, hits=0, det=0, true=0, sq=0.0, n=0, pose=0, eligible=0, nees=0.0, above=0.0,
             posed=0, off=0)
for seed in seeds:
    for camera in cameras:
        with open(f"{out}/seed_{seed}/{camera}/summary.json") as f:
            s = json.load(f)
        e = s["labels"]
        hits = round(e["recall"] * e["ok_labels"])
        true = round(e["precision"] * e["detections"])
        with open(f"{out}/seed_{seed}/{camera}/pose_nees.json") as f:
            p = json.load(f)
        pose_columns = (f"{p['median_position_error_mm']:8.1f} {p['mean_nees']:7.2f} "
                        f"{p['share_above_chi2_975']:7.3f}" if p["poses"] else "")
        print(f"{seed:>5} {camera:>7} {e['recall']:8.3f} {e['precision']:10.3f} "
              f"{e['centroid_rms_px']:9.3f} {e['centroid_median_px']:7.3f} "
              f"{e['pose_frames']:>5}/{e['pose_frames_eligible']:<5} "
              f"{s['time_per_frame_ms']['detect']:9.2f} {pose_columns}")
        if p["poses"]:
            total["posed"] += p["poses"]
            total["nees"] += p["mean_nees"] * p["poses"]
            total["above"] += p["share_above_chi2_975"] * p["poses"]
            total["off"] += p.get("poses_off", 0)
        total["ok"] += e["ok_labels"]; total["hits"] += hits
        total["det"] += e["detections"]; total["true"] += true
        total["sq"] += e["centroid_rms_px"] ** 2 * e["centroid_samples"]
        total["n"] += e["centroid_samples"]
        total["pose"] += e["pose_frames"]; total["eligible"] += e["pose_frames_eligible"]
recall = total["hits"] / max(1, total["ok"])
precision = total["true"] / max(1, total["det"])
rms = (total["sq"] / max(1, total["n"])) ** 0.5
posed = max(1, total["posed"])
print(f"{'all':>5} {'':>7} {recall:8.3f} {precision:10.3f} {rms:9.3f} {'':>7} "
      f"{total['pose']:>5}/{total['eligible']:<5} {'':>9} {'':>8} {total['nees'] / posed:7.2f} "
      f"{total['above'] / posed:7.3f}")
print(f"mono poses: {total['posed']}, of which {total['off']} off by more than 0.3 m or 5 deg")
print("pose mm: median position error of the mono poses against the truth; NEES: their mean "
      "NEES in detect's covariance (6 when honest); >97.5%: the share above chi-square(6)'s "
      "97.5 % point (0.025 when honest)")
PY
