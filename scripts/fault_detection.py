#!/usr/bin/env python3
"""How many of a dataset's injected sensor faults the estimator rejected, and how many clean
samples it rejected (false alarms):

  python3 scripts/fault_detection.py DATASET OUTDIR [OUTDIR ...]

DATASET/groundtruth/faults.csv lists the injected faults (sim/dvl_simulator.h, ...), the
sensor's DATASET/<sensor>/data.csv its samples, OUTDIR/rejections.csv what `run` or `smooth`
left out. Per sensor and fault kind: faults, rejected, the fraction; per sensor: clean samples
and the fraction of them rejected. Several OUTDIRs (of one dataset each, given as DATASET=OUTDIR
pairs with --pairs) are pooled. Standard library only.
"""
import csv
import os
import sys
from collections import defaultdict


def rows(path):
    with open(path, newline="") as f:
        return [r for r in csv.reader(f) if r and not r[0].startswith("#")]


def tally(dataset, outdir, faults, rejected, clean, clean_rejected):
    fault_at = defaultdict(dict)  # sensor -> t_ns -> kind
    for t, sensor, kind, _ in rows(os.path.join(dataset, "groundtruth", "faults.csv")):
        fault_at[sensor][int(t)] = kind
    rejected_at = defaultdict(set)
    for r in rows(os.path.join(outdir, "rejections.csv")):
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
            else:
                faults[(sensor, kind)] += 1
                rejected[(sensor, kind)] += t in rejected_at[sensor]


def main(argv):
    if len(argv) < 3 or "=" in argv[1] and argv[1] != "--pairs":
        sys.exit(__doc__)
    pairs = [a.split("=", 1) for a in argv[2:]] if argv[1] == "--pairs" else \
        [(argv[1], o) for o in argv[2:]]
    faults, rejected = defaultdict(int), defaultdict(int)
    clean, clean_rejected = defaultdict(int), defaultdict(int)
    for dataset, outdir in pairs:
        tally(dataset, outdir, faults, rejected, clean, clean_rejected)
    print(f"{'sensor':8} {'kind':18} {'faults':>7} {'rejected':>9} {'fraction':>9}")
    for (sensor, kind) in sorted(faults):
        n, k = faults[(sensor, kind)], rejected[(sensor, kind)]
        print(f"{sensor:8} {kind:18} {n:7d} {k:9d} {k / n:9.3f}")
    for sensor in sorted(clean):
        n, k = clean[sensor], clean_rejected[sensor]
        print(f"{sensor:8} {'clean (false alarm)':18} {n:7d} {k:9d} {k / max(n, 1):9.4f}")


if __name__ == "__main__":
    main(sys.argv)
