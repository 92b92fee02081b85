#!/usr/bin/env bash
# Monte-Carlo safety and consistency audit of `auvdock run` (and `smooth`) from synthetic
# detections (no images: a run takes seconds), with the sensor faults at several times the
# scenario's rates:
#   bash scripts/monte_carlo.sh [--runs N] [--first-seed S] [--scenario FILE] [--fault-scale K]
#                               [--out DIR] [--commands "run smooth"] [--config FILE]
# Defaults: 200 runs from seed 1, data/scenarios/default.yaml, K = 3, OUT = out/monte_carlo,
# "run". Per run (OUT/seed_N/): simulate --detections-only --fault-scale K, the estimator with
# --detections, evaluate. Then one table per command: unsafe GO count, the worst true lateral
# error at a GO, GO availability in the lit frames (a camera sees >= 3 lights), the NEES
# distribution and the share of runs whose mean NEES lies in the 95 % band of a consistent
# estimator (mean of n chi-square(6) values, taken as independent: a narrow band, see the
# note), resets and solver failures. AUVDOCK_BIN=path/to/auvdock runs another build.
set -euo pipefail
cd "$(dirname "$0")/.."
runs=200
first=1
scenario=data/scenarios/default.yaml
scale=3
out=out/monte_carlo
commands="run"
config=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --runs) runs="$2"; shift 2 ;;
    --first-seed) first="$2"; shift 2 ;;
    --scenario) scenario="$2"; shift 2 ;;
    --fault-scale) scale="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --commands) commands="$2"; shift 2 ;;
    --config) config=(--config "$2"); shift 2 ;;
    *) echo "monte_carlo.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
bin=${AUVDOCK_BIN:-build/bin/auvdock}
[[ -x "$bin" ]] || { echo "monte_carlo.sh: $bin not found: run scripts/build.sh" >&2; exit 2; }
mkdir -p "$out"
start=$(date +%s)
seeds=$(seq "$first" $((first + runs - 1)))
for seed in $seeds; do
  dir="$out/seed_$seed"
  rm -rf "$dir"   # this script's own folder from an earlier call
  "$bin" simulate --scenario "$scenario" --seed "$seed" --detections-only --fault-scale "$scale" \
    --out "$dir/dataset" --quiet > /dev/null
  for command in $commands; do
    if ! "$bin" "$command" --dataset "$dir/dataset" --detections "$dir/dataset/detections.csv" \
        --out "$dir/$command" "${config[@]}" --quiet > "$dir/$command.log" 2>&1; then
      echo "monte_carlo.sh: seed $seed: $command failed: $(tail -1 "$dir/$command.log")" >&2
      continue
    fi
    "$bin" evaluate --dataset "$dir/dataset" --estimate "$dir/$command/trajectory.tum" \
      --covariance "$dir/$command/covariance.csv" --decisions "$dir/$command/decisions.csv" \
      --json > "$dir/$command/evaluation.json"
  done
  printf '\rmonte_carlo.sh: %d/%d runs' $((seed - first + 1)) "$runs" >&2
done
echo >&2
echo "monte_carlo.sh: $runs runs in $(( $(date +%s) - start )) s (fault scale $scale)"
/usr/bin/python3 - "$out" "$scale" $commands -- $seeds <<'PY'
import csv, json, math, sys
out, scale = sys.argv[1], sys.argv[2]
split = sys.argv.index("--")
commands, seeds = sys.argv[3:split], sys.argv[split + 1:]

def chi2_mean_band(n, dof=6):
    # 95 % band of the mean of n independent chi-square(dof) values (Wilson-Hilferty).
    k = n * dof
    def q(z):
        return k * (1 - 2 / (9 * k) + z * math.sqrt(2 / (9 * k))) ** 3 / n
    return q(-1.959964), q(1.959964)

def rows(path):
    with open(path) as f:
        return [r for r in csv.reader(f) if r and not r[0].startswith("#")]

for command in commands:
    nees, in_band, below, above = [], 0, 0, 0
    eff_in_band, eff_below, eff_above, taus = 0, 0, 0, []
    unsafe, worst_lat, resets, failures, missing = 0, 0.0, 0, 0, 0
    go_lit, lit, rmse = 0, 0, []
    for seed in seeds:
        d = f"{out}/seed_{seed}"
        try:
            r = json.load(open(f"{d}/{command}/evaluation.json"))
            s = json.load(open(f"{d}/{command}/summary.json"))
        except (OSError, ValueError):
            missing += 1
            continue
        n, m = r.get("nees_n", 0), r.get("nees_mean")
        if n and m is not None:
            nees.append(m)
            lo, hi = chi2_mean_band(n)
            in_band += lo <= m <= hi
            below += m < lo
            above += m > hi
            # The same band for the number of independent values the mean is worth (successive
            # poses' NEES are correlated: evaluate's nees_effective_n).
            n_eff = r.get("nees_effective_n")
            if n_eff:
                taus.append(r["nees_correlation_poses"])
                lo, hi = chi2_mean_band(n_eff)
                eff_in_band += lo <= m <= hi
                eff_below += m < lo
                eff_above += m > hi
        a = r["decisions"]
        unsafe += a["n_go_unsafe"]
        worst_lat = max(worst_lat, a["max_lateral_error_at_go_m"] or 0.0)
        resets += s.get("resets", 0)
        failures += s.get("solver_failures", 0)
        rmse.append(r["pos_rmse_m"])
        stage = {int(v[0]): v[4] for v in rows(f"{d}/dataset/groundtruth/visibility.csv")}
        go = {int(v[0]) for v in rows(f"{d}/{command}/decisions.csv") if v[1] == "GO"}
        for t, st in stage.items():
            if st != "neither":
                lit += 1
                go_lit += t in go
    done = len(seeds) - missing
    nees.sort()
    pct = lambda p: nees[min(len(nees) - 1, int(p * len(nees)))] if nees else float("nan")
    print(f"\n{command}: {done} of {len(seeds)} runs evaluated (fault rates x{scale})")
    print(f"  unsafe GO: {unsafe}; worst true lateral error at a GO: {1e3 * worst_lat:.1f} mm")
    print(f"  GO in the lit frames: {100.0 * go_lit / max(lit, 1):.1f} % ({go_lit} of {lit})")
    print(f"  mean NEES per run: median {pct(0.5):.2f}, 5 % {pct(0.05):.2f}, 95 % {pct(0.95):.2f}, "
          f"max {nees[-1] if nees else float('nan'):.2f}")
    print(f"  runs with mean NEES in the 95 % band: {in_band} of {len(nees)} "
          f"({100.0 * in_band / max(len(nees), 1):.0f} %; {below} below, {above} above)")
    taus.sort()
    if taus:
        print(f"  ... with the band of each run's effective number of independent values "
              f"(NEES correlation time median {taus[len(taus) // 2]:.1f} poses): {eff_in_band} of "
              f"{len(taus)} ({100.0 * eff_in_band / len(taus):.0f} %; {eff_below} below, "
              f"{eff_above} above)")
    rmse.sort()
    print(f"  position RMSE per run: median {1e3 * rmse[len(rmse) // 2] if rmse else float('nan'):.1f} mm, "
          f"max {1e3 * rmse[-1] if rmse else float('nan'):.1f} mm")
    print(f"  resets: {resets}; solver failures: {failures}")
PY
