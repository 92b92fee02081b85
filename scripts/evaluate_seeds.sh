#!/usr/bin/env bash
# Accuracy, covariance consistency (NEES) and go/no-go safety of `auvdock run` (and `smooth`
# with --smooth) over several seeds of a scenario, on the full image pipeline:
#   bash scripts/evaluate_seeds.sh [--scenario FILE] [--seeds "1 2 3"] [--out DIR] [--smooth]
#                                  [--detector blob|learned] [--reuse-datasets]
#                                  [--config FILE] [--commands "run smooth"]
# (--reuse-datasets: keep OUT/seed_N/dataset from an earlier call of the same scenario instead of
# simulating again; --config: estimator options for run and smooth, data/estimator/default.yaml's
# format; --commands: which of run/smooth to run, e.g. "smooth" alone; AUVDOCK_BIN=path/to/auvdock
# runs another build.)
# Needs a built tree (scripts/build.sh). Per seed it simulates, estimates and evaluates into
# OUT/seed_N/, then prints one table: position RMSE and mean NEES by stage, GO count, unsafe GO
# and the largest true lateral error at GO, and the means over the seeds.
set -euo pipefail
cd "$(dirname "$0")/.."
scenario=data/scenarios/default.yaml
seeds="1 2 3 4 5"
out=out/seeds
commands="run"
detector=blob
reuse=0
config=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --scenario) scenario="$2"; shift 2 ;;
    --seeds) seeds="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --smooth) commands="run smooth"; shift ;;
    --detector) detector="$2"; shift 2 ;;
    --reuse-datasets) reuse=1; shift ;;
    --config) config=(--config "$2"); shift 2 ;;
    --commands) commands="$2"; shift 2 ;;
    *) echo "evaluate_seeds.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
bin=${AUVDOCK_BIN:-build/bin/auvdock}
[[ -x "$bin" ]] || { echo "evaluate_seeds.sh: $bin not found: run scripts/build.sh" >&2; exit 2; }
mkdir -p "$out"
for seed in $seeds; do
  dir="$out/seed_$seed"
  if [[ $reuse == 1 && -f "$dir/dataset/groundtruth.tum" ]]; then
    for command in $commands; do rm -rf "${dir:?}/$command"; done
  else
    rm -rf "$dir"   # this script's own folder from an earlier call
    "$bin" simulate --scenario "$scenario" --seed "$seed" --out "$dir/dataset" --quiet
  fi
  for command in $commands; do
    "$bin" "$command" --dataset "$dir/dataset" --out "$dir/$command" --detector "$detector" \
      "${config[@]}" --quiet > /dev/null
    "$bin" evaluate --dataset "$dir/dataset" --estimate "$dir/$command/trajectory.tum" \
      --covariance "$dir/$command/covariance.csv" --decisions "$dir/$command/decisions.csv" \
      --json > "$dir/$command/evaluation.json"
  done
done
/usr/bin/python3 - "$out" $commands -- $seeds <<'PY'
import json, sys
out = sys.argv[1]
split = sys.argv.index("--")
commands, seeds = sys.argv[2:split], sys.argv[split + 1:]
stages = ["stereo_only", "both", "mono_only", "neither"]
for command in commands:
    print(f"\n{command}: position RMSE [mm] and mean NEES by stage; go/no-go audit")
    print(f"{'seed':>5} " + " ".join(f"{s:>17}" for s in stages) +
          f" {'NEES all':>9} {'GO':>5} {'unsafe':>7} {'max lat@GO [mm]':>16}")
    sums = {}
    for seed in seeds:
        with open(f"{out}/seed_{seed}/{command}/evaluation.json") as f:
            r = json.load(f)
        cells = []
        for s in stages:
            st = r["stages"].get(s)
            if st is None:
                cells.append(f"{'-':>17}")
                continue
            rmse, nees = 1e3 * st["pos_rmse_m"], st.get("nees_mean")
            cells.append(f"{rmse:8.1f} / {nees if nees is not None else float('nan'):6.2f}")
            sums.setdefault(s, []).append((rmse, nees))
        d = r["decisions"]
        sums.setdefault("nees", []).append(r["nees_mean"])
        sums.setdefault("unsafe", []).append(d["n_go_unsafe"])
        print(f"{seed:>5} " + " ".join(cells) + f" {r['nees_mean']:9.2f} {d['n_go']:5d} "
              f"{d['n_go_unsafe']:7d} {1e3 * d['max_lateral_error_at_go_m']:16.1f}")
    cells = []
    for s in stages:
        v = sums.get(s, [])
        if not v:
            cells.append(f"{'-':>17}")
            continue
        nees = [n for _, n in v if n is not None]
        cells.append(f"{sum(x for x, _ in v) / len(v):8.1f} / "
                     f"{(sum(nees) / len(nees)) if nees else float('nan'):6.2f}")
    print(f"{'mean':>5} " + " ".join(cells) +
          f" {sum(sums['nees']) / len(sums['nees']):9.2f} {'':5} {sum(sums['unsafe']):7d}")
PY
