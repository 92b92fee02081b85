#!/usr/bin/python3
"""`auvdock frontend` (the per-frame pipeline of run and smooth) measured on labelled footage.

`detect --labels` measures the footage path; this measures the estimator's own front-end on the
same frames and labels: it makes a one-camera dataset of the images (a folder of links, each image
timed by its rank at --rate-hz), runs `frontend` on it and scores its detections.csv as `detect
--labels` does (the labels' format and measure: docs/user_guide.md, "detect"):
  - a detection within 10 px of a label is a hit (greedy, nearest first);
  - recall over the `ok` labels; precision over all detections in the labelled frames, where a
    detection within 15 px of an `edge` label counts as neither;
  - centroid RMS over the hits on `ok` labels of quality `good` (all hits when there is no
    quality column);
  - pose rate: the share of labelled frames with >= 4 `ok` labels in which frontend has a pose.

    /usr/bin/python3 scripts/frontend_on_labels.py --images "DIR/*.jpg" --labels LABELS.csv \
        --calib CALIB.yaml --dock DOCK.yaml --rate-hz 61.82 --out OUTDIR [-- frontend options]

The calibration must be auvdock's calibration.yaml with one camera (role mono). Needs a built
auvdock (build/bin/auvdock, or AUVDOCK_BIN). Prints one line and writes OUTDIR/score.json.
"""
import argparse
import csv
import glob
import json
import math
import os
import shutil
import subprocess
import sys

HIT_PX = 10.0
EDGE_PX = 15.0


def fail(message):
    print(f"frontend_on_labels: {message}", file=sys.stderr)
    sys.exit(2)


def camera_name(calib_path):
    with open(calib_path) as f:
        for line in f:
            stripped = line.strip()
            if stripped.startswith("- name:"):
                return stripped.split(":", 1)[1].strip()
    fail(f"{calib_path}: no camera ('- name:')")


def read_labels(path):
    try:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        fail(f"{path}: {e.strerror}")
    for key in ("frame_file", "u", "v"):
        if rows and key not in rows[0]:
            fail(f"{path}: no column '{key}'")
    by_frame = {}
    for row in rows:
        labels = by_frame.setdefault(row["frame_file"], [])
        if row["u"] and row["v"] and row.get("status", "ok") != "none":
            labels.append((float(row["u"]), float(row["v"]), row.get("status", "ok"),
                           row.get("quality", "good")))
    return by_frame


def score(labels, detections, posed):
    """labels: frame -> [(u, v, status, quality)]; detections: frame -> [(u, v)]."""
    ok = hits = det = true = eligible = with_pose = 0
    squared = []
    for frame, frame_labels in labels.items():
        found = detections.get(frame, [])
        pairs = sorted((math.hypot(d[0] - l[0], d[1] - l[1]), i, j)
                       for i, d in enumerate(found) for j, l in enumerate(frame_labels)
                       if l[2] != "edge")
        used_d, used_l = set(), set()
        for distance, i, j in pairs:
            if distance > HIT_PX or i in used_d or j in used_l:
                continue
            used_d.add(i)
            used_l.add(j)
            if frame_labels[j][2] == "ok":
                hits += 1
                if frame_labels[j][3] == "good":
                    squared.append(distance ** 2)
        ok_here = sum(1 for l in frame_labels if l[2] == "ok")
        ok += ok_here
        for i, d in enumerate(found):
            near_edge = any(l[2] == "edge" and math.hypot(d[0] - l[0], d[1] - l[1]) <= EDGE_PX
                            for l in frame_labels)
            if i in used_d:
                det += 1
                true += 1
            elif not near_edge:
                det += 1
        if ok_here >= 4:
            eligible += 1
            with_pose += frame in posed
    return {
        "frames": len(labels), "ok_labels": ok, "recall": hits / max(1, ok),
        "precision": true / max(1, det), "detections": det,
        "centroid_rms_px": math.sqrt(sum(squared) / len(squared)) if squared else None,
        "pose_frames": with_pose, "pose_frames_eligible": eligible,
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--images", required=True, help='a glob, e.g. "DIR/*.jpg"')
    parser.add_argument("--labels", required=True)
    parser.add_argument("--calib", required=True)
    parser.add_argument("--dock", required=True)
    parser.add_argument("--rate-hz", type=float, required=True, help="the footage's frame rate")
    parser.add_argument("--out", required=True)
    argv = sys.argv[1:]
    extra = []
    if "--" in argv:
        extra = argv[argv.index("--") + 1:]
        argv = argv[:argv.index("--")]
    args = parser.parse_args(argv)
    if not args.rate_hz > 0:
        fail("--rate-hz: expected a positive number")
    binary = os.environ.get("AUVDOCK_BIN", os.path.join(os.path.dirname(__file__), "..", "build",
                                                        "bin", "auvdock"))
    if not os.access(binary, os.X_OK):
        fail(f"{binary} not found: run scripts/build.sh or set AUVDOCK_BIN")
    if os.path.exists(args.out) and os.listdir(args.out):
        fail(f"{args.out}: exists and is not empty")
    files = sorted(glob.glob(args.images))
    if not files:
        fail(f"no image matches {args.images}")
    labels = read_labels(args.labels)
    camera = camera_name(args.calib)
    dataset = os.path.join(args.out, "dataset")
    os.makedirs(os.path.join(dataset, camera, "data"))
    shutil.copyfile(args.calib, os.path.join(dataset, "calibration.yaml"))
    shutil.copyfile(args.dock, os.path.join(dataset, "dock.yaml"))
    time_of = {}
    with open(os.path.join(dataset, camera, "data.csv"), "w") as f:
        f.write("#timestamp [ns],filename\n")
        for k, path in enumerate(files):
            name = os.path.basename(path)
            t_ns = 1_000_000_000 + round(k * 1e9 / args.rate_hz)
            time_of[t_ns] = name
            os.symlink(os.path.abspath(path), os.path.join(dataset, camera, "data", name))
            f.write(f"{t_ns},{name}\n")
    result = os.path.join(args.out, "frontend")
    run = subprocess.run([binary, "frontend", "--dataset", dataset, "--out", result, "--quiet"] +
                         extra, capture_output=True, text=True)
    if run.returncode != 0:
        fail(f"frontend failed: {run.stderr.strip() or run.stdout.strip()}")
    detections = {}
    with open(os.path.join(result, "detections.csv"), newline="") as f:
        for row in csv.reader(f):
            if not row or row[0].startswith("#") or not row[3]:
                continue
            detections.setdefault(time_of[int(row[0])], []).append((float(row[3]), float(row[4])))
    posed = set()
    with open(os.path.join(result, "per_frame.tum")) as f:
        for line in f:
            if line.strip() and not line.startswith("#"):
                t_ns = round(float(line.split()[0]) * 1e9)
                nearest = min(time_of, key=lambda t: abs(t - t_ns))
                if abs(nearest - t_ns) < 1e6:
                    posed.add(time_of[nearest])
    summary = score(labels, detections, posed)
    summary["frames_with_pose"] = len(posed)
    summary["images"] = len(files)
    with open(os.path.join(args.out, "score.json"), "w") as f:
        json.dump(summary, f, indent=2)
    rms = summary["centroid_rms_px"]
    print(f"frontend on {summary['frames']} labelled frames: recall {summary['recall']:.3f}, "
          f"precision {summary['precision']:.3f}, centroid rms "
          f"{rms if rms is not None else float('nan'):.2f} px, pose in "
          f"{summary['pose_frames']}/{summary['pose_frames_eligible']} frames with >= 4 ok lights; "
          f"{summary['frames_with_pose']}/{summary['images']} frames with a pose")


if __name__ == "__main__":
    main()
