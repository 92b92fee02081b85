#!/usr/bin/env python3
"""How many of a dataset's injected sensor faults the estimator rejected, and how many clean
samples it rejected (false alarms):

  python3 scripts/fault_detection.py DATASET OUTDIR [OUTDIR ...]

DATASET/groundtruth/faults.csv lists the injected faults (sim/dvl_simulator.h, ...), the
sensor's DATASET/<sensor>/data.csv its samples, OUTDIR/rejections.csv what `run` or `smooth`
left out. Per sensor and fault kind: faults, rejected, the fraction; per sensor: clean samples
and the fraction of them rejected as outliers (false alarms); a clean sample left out because it
could not be used yet (before the estimator's first state, before the DVL's admission while the
window cannot test it, no state or IMU at its time) is counted apart ("not used"), as it says
nothing of the outlier tests. Several OUTDIRs (of one dataset each, given as DATASET=OUTDIR
pairs with --pairs) are pooled. Standard library only.
"""
import csv
import os
import sys
from collections import defaultdict


def rows(path):
    with open(path, newline="") as f:
        return [r for r in csv.reader(f) if r and not r[0].startswith("#")]


# Reasons (rejections.csv, estimator/rejection.h) for samples that were not judged at all.
NOT_USED_REASONS = (
    "before the estimator's first state",
    "before admission: the window's velocity cannot test it yet",
    "no state at or before its time",
)


def tally(dataset, outdir, faults, rejected, clean, clean_rejected, clean_unused):
    fault_at = defaultdict(dict)  # sensor -> t_ns -> kind
    for t, sensor, kind, _ in rows(os.path.join(dataset, "groundtruth", "faults.csv")):
        fault_at[sensor][int(t)] = kind
    rejected_at = defaultdict(set)
    unused_at = defaultdict(set)
    for r in rows(os.path.join(outdir, "rejections.csv")):
        if r[0] == "timestamp_ns":
            continue
        if len(r) > 3 and r[3].startswith(NOT_USED_REASONS):
            unused_at[r[1]].add(int(r[0]))
        else:
            rejected_at[r[1]].add(int(r[0]))
    folders = {d for d in os.listdir(dataset) if d not in ("groundtruth", "imu0") and
               os.path.isfile(os.path.join(dataset, d, "data.csv"))}
    for sensor in sorted(folders):
        data = os.path.join(dataset, sensor, "data.csv")
        if not os.path.exists(data):
            continue
        with open(data) as f:
            if "filename" in f.readline():
                continue  # a camera: its faults are scene distractors, not samples
        samples = [int(r[0]) for r in rows(data)]
        for t in samples:
            kind = fault_at[sensor].get(t)
            if kind is None:
                clean[sensor] += 1
                clean_rejected[sensor] += t in rejected_at[sensor]
                clean_unused[sensor] += t in unused_at[sensor] and t not in rejected_at[sensor]
            else:
                faults[(sensor, kind)] += 1
                # A fault left out before it could be judged did not get in either.
                rejected[(sensor, kind)] += t in rejected_at[sensor] or t in unused_at[sensor]


def main(argv):
    if len(argv) < 3 or "=" in argv[1] and argv[1] != "--pairs":
        sys.exit(__doc__)
    pairs = [a.split("=", 1) for a in argv[2:]] if argv[1] == "--pairs" else \
        [(argv[1], o) for o in argv[2:]]
    faults, rejected = defaultdict(int), defaultdict(int)
    clean, clean_rejected, clean_unused = defaultdict(int), defaultdict(int), defaultdict(int)
    for dataset, outdir in pairs:
        tally(dataset, outdir, faults, rejected, clean, clean_rejected, clean_unused)
    print(f"{'sensor':8} {'kind':18} {'faults':>7} {'rejected':>9} {'fraction':>9}")
    for (sensor, kind) in sorted(faults):
        n, k = faults[(sensor, kind)], rejected[(sensor, kind)]
        print(f"{sensor:8} {kind:18} {n:7d} {k:9d} {k / n:9.3f}")
    for sensor in sorted(clean):
        n, k = clean[sensor], clean_rejected[sensor]
        print(f"{sensor:8} {'clean (false alarm)':18} {n:7d} {k:9d} {k / max(n, 1):9.4f}"
              f"   (not used yet: {clean_unused[sensor]})")


if __name__ == "__main__":
    main(sys.argv)
