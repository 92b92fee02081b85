#!/usr/bin/python3
"""How honest the mono poses of `auvdock detect` are on a simulated dataset: their errors against
the simulator's truth and their NEES in the covariance that `detect` reports.

    /usr/bin/python3 scripts/detector_pose_nees.py --dataset DIR --camera cam2 --detect OUT

DIR is a simulated dataset (groundtruth.tum: T_D_B; calibration.yaml: each camera's T_B_S), OUT a
`detect` output on DIR/<camera>/data/*.png (frames.csv: T_C_D per frame with a pose, in frame
order; camera_pose_covariance.csv: one row per posed frame, in the same order, the covariance of
T_D_C in the tangent [dp_D, dtheta_D] with T_D_C = (p + dp, Exp(dtheta) q)). The truth of a frame
is T_D_B at the image's time stamp (its file name, nanoseconds) composed with T_B_C.

Prints one line of JSON: poses, median position and rotation errors (mm, deg), mean NEES
(6 dof: 6 when the covariance is right), and the share of poses above the 97.5 % point of
chi-square(6) (14.45; 2.5 % when right), and poses_off: how many are off by more than 0.3 m or
5 deg (a wrong labelling, not noise). Needs python3-numpy (Debian: call /usr/bin/python3).
"""
import argparse
import csv
import json
import math
import re
import sys

import numpy as np

CHI2_6_975 = 14.449


def fail(message):
    print(f"detector_pose_nees: {message}", file=sys.stderr)
    sys.exit(2)


def quat_to_matrix(x, y, z, w):
    n = math.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / n, y / n, z / n, w / n
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def log_so3(R):
    c = max(-1.0, min(1.0, (np.trace(R) - 1.0) / 2.0))
    angle = math.acos(c)
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    if angle < 1e-9:
        return 0.5 * w
    return angle / (2.0 * math.sin(angle)) * w


def camera_extrinsics(path, camera):
    """T_B_C of `camera` from calibration.yaml (the T_B_S row-major 4x4 under its name)."""
    try:
        text = open(path).read()
    except OSError as e:
        fail(f"{path}: {e.strerror}")
    block = re.search(r"-\s*name:\s*" + re.escape(camera) + r"\b(.*?)(?=\n\s*-\s*name:|\n\w|\Z)",
                      text, re.S)
    if not block:
        fail(f"{path}: no camera '{camera}'")
    m = re.search(r"T_B_S:\s*\[([^\]]*)\]", block.group(1))
    if not m:
        fail(f"{path}: camera '{camera}' has no T_B_S")
    return np.array([float(v) for v in m.group(1).split(",")]).reshape(4, 4)


def read_truth(path):
    times, poses = [], []
    for line in open(path):
        if line.startswith("#") or not line.strip():
            continue
        v = [float(x) for x in line.split()]
        T = np.eye(4)
        T[:3, :3] = quat_to_matrix(*v[4:8])
        T[:3, 3] = v[1:4]
        times.append(v[0])
        poses.append(T)
    return np.array(times), poses


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--dataset", required=True)
    parser.add_argument("--camera", required=True)
    parser.add_argument("--detect", required=True)
    args = parser.parse_args()
    T_B_C = camera_extrinsics(f"{args.dataset}/calibration.yaml", args.camera)
    try:
        times, truth = read_truth(f"{args.dataset}/groundtruth.tum")
    except OSError as e:
        fail(f"{e.filename}: {e.strerror}")
    try:
        posed = [r for r in csv.DictReader(open(f"{args.detect}/frames.csv"))
                 if r["status"] == "ok"]
        covariances = list(csv.reader(open(f"{args.detect}/camera_pose_covariance.csv")))[1:]
    except OSError as e:
        fail(f"{e.filename}: {e.strerror}")
    if len(covariances) != len(posed):
        fail(f"{args.detect}: {len(posed)} posed frames but {len(covariances)} covariance rows")
    position_mm, rotation_deg, nees = [], [], []
    for row, cov in zip(posed, covariances):
        t = int(row["image"].split(".")[0]) * 1e-9
        k = int(np.argmin(np.abs(times - t)))
        if abs(times[k] - t) > 1e-3:
            continue
        T_D_C_true = truth[k] @ T_B_C
        R_C_D = quat_to_matrix(*(float(row[c]) for c in ("qx", "qy", "qz", "qw")))
        t_C_D = np.array([float(row[c]) for c in ("tx", "ty", "tz")])
        R_D_C, p_D_C = R_C_D.T, -R_C_D.T @ t_C_D
        e = np.concatenate([p_D_C - T_D_C_true[:3, 3], log_so3(R_D_C @ T_D_C_true[:3, :3].T)])
        P = np.array([float(v) for v in cov[1:]]).reshape(6, 6)
        position_mm.append(1e3 * np.linalg.norm(e[:3]))
        rotation_deg.append(math.degrees(np.linalg.norm(e[3:])))
        nees.append(float(e @ np.linalg.solve(P, e)))
    result = {"poses": len(nees)}
    if nees:
        result.update({
            "median_position_error_mm": float(np.median(position_mm)),
            "median_rotation_error_deg": float(np.median(rotation_deg)),
            "mean_nees": float(np.mean(nees)),
            "median_nees": float(np.median(nees)),
            "share_above_chi2_975": float(np.mean(np.array(nees) > CHI2_6_975)),
            # Wrong poses: off by more than 0.3 m or 5 deg (a wrong labelling, not noise).
            "poses_off": int(np.sum((np.array(position_mm) > 300.0) |
                                    (np.array(rotation_deg) > 5.0))),
        })
    print(json.dumps(result))


if __name__ == "__main__":
    main()
