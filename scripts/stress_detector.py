#!/usr/bin/python3
"""How the detector holds up on one's own labelled frames when the look changes.

Makes perturbed copies of labelled frames and measures `auvdock detect --labels` on each:
a closer or farther view (zoom about the image centre, with the calibration's focal lengths and
principal point changed to match: the distortion, in normalised coordinates, stays the same, so
the poses stay comparable), a shift (a fraction of the image's width and height; the principal
point moves with it) that puts the dock against a border, exposure (gain), a tone curve (gamma), limited-range video levels
(16-235 shown as full range), defocus blur, JPEG quality and sensor noise. The
labels move with the zoom; a label the zoom pushes out of the image becomes `edge` (not
required), one within the border margin `border`.

    /usr/bin/python3 scripts/stress_detector.py --images "DIR/*.jpg" --labels LABELS.csv \
        --calib CALIB.yaml --dock DOCK.yaml --out OUTDIR [--all-frames] [--variants zoom1.5,gain0.6]
        [-- extra detect options]

Needs python3-opencv and python3-numpy (Debian: call /usr/bin/python3) and a built auvdock
(build/bin/auvdock, or AUVDOCK_BIN). Prints one table row per variant: recall, precision,
centroid RMS, the share of frames with >= 4 lights that get a pose, and the frames with a pose.
By default only the labelled frames are processed (each on its own, no tracking between them);
--all-frames copies every frame, so tracking and the second look work as on the footage.
The calibration must be auvdock's calibration.yaml (one camera, `intrinsics: [fx, fy, cx, cy]`).
"""
import argparse
import csv
import glob
import json
import os
import re
import shutil
import subprocess
import sys

VARIANTS = {
    "original": {},
    "zoom0.7": {"zoom": 0.7},
    "zoom1.5": {"zoom": 1.5},
    "zoom2.0": {"zoom": 2.0},
    "gain0.6": {"gain": 0.6},
    "gain1.4": {"gain": 1.4},
    "videorange": {"levels": (16, 235)},
    "gamma0.6": {"gamma": 0.6},
    "blur1.2": {"blur": 1.2},
    "jpeg40": {"jpeg": 40},
    "noise6": {"noise": 6.0},
    # The dock against the top border and closer, as late in an approach: shifted up by a third
    # of the image's height (y of 576 px: 192 px), and with a zoom and a gain that merges the
    # lights' glow into a white funnel.
    "up0.33": {"shift": (0.0, -1.0 / 3.0)},
    "zoom1.5up": {"zoom": 1.5, "shift": (0.0, -1.0 / 3.0)},
    "gain1.4zoom1.5up": {"zoom": 1.5, "shift": (0.0, -1.0 / 3.0), "gain": 1.4},
}


def fail(message):
    print(f"stress_detector: {message}", file=sys.stderr)
    sys.exit(2)


def read_labels(path):
    try:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        fail(f"{path}: {e.strerror}")
    for key in ("frame_file", "u", "v"):
        if rows and key not in rows[0]:
            fail(f"{path}: no column '{key}'")
    return rows


def zoomed_calibration(text, zoom, centre, shift, path):
    match = re.search(r"intrinsics:\s*\[([^\]]*)\]", text)
    if not match:
        fail(f"{path}: no 'intrinsics: [fx, fy, cx, cy]' (auvdock's calibration.yaml is needed)")
    try:
        fx, fy, cx, cy = (float(x) for x in match.group(1).split(","))
    except ValueError:
        fail(f"{path}: 'intrinsics' is not four numbers")
    cx = zoom * (cx - centre[0]) + centre[0] + shift[0]
    cy = zoom * (cy - centre[1]) + centre[1] + shift[1]
    return text.replace(
        match.group(0), f"intrinsics: [{zoom * fx:.4f}, {zoom * fy:.4f}, {cx:.4f}, {cy:.4f}]")


def make_variant(args, name, effect, labels, folder, cv2, np):
    zoom = effect.get("zoom", 1.0)
    frames_dir = os.path.join(folder, "frames")
    os.makedirs(frames_dir, exist_ok=True)
    wanted = None if args.all_frames else {r["frame_file"] for r in labels}
    files = sorted(glob.glob(args.images))
    if not files:
        fail(f"no image matches {args.images}")
    rng = np.random.default_rng(1)
    size = None
    for path in files:
        base = os.path.basename(path)
        if wanted is not None and base not in wanted:
            continue
        image = cv2.imread(path, cv2.IMREAD_COLOR)
        if image is None:
            fail(f"{path}: not an image")
        size = image.shape[1], image.shape[0]
        if not effect:  # the original, byte for byte
            shutil.copyfile(path, os.path.join(frames_dir, base))
            continue
        centre = ((size[0] - 1) / 2.0, (size[1] - 1) / 2.0)
        shift = (effect.get("shift", (0.0, 0.0))[0] * size[0],
                 effect.get("shift", (0.0, 0.0))[1] * size[1])
        work = image.astype(np.float32)
        if zoom != 1.0 or shift != (0.0, 0.0):
            warp = np.array([[zoom, 0, (1 - zoom) * centre[0] + shift[0]],
                             [0, zoom, (1 - zoom) * centre[1] + shift[1]]])
            work = cv2.warpAffine(work, warp, size, flags=cv2.INTER_LINEAR,
                                  borderMode=cv2.BORDER_REPLICATE)
        work *= effect.get("gain", 1.0)
        if "gamma" in effect:  # a tone curve: out = 255 (in / 255)^gamma
            work = 255.0 * np.power(np.clip(work, 0, 255) / 255.0, effect["gamma"])
        if "levels" in effect:  # limited-range video shown as full range: black 16, white 235
            black, white = effect["levels"]
            work = black + np.clip(work, 0, 255) * (white - black) / 255.0
        if effect.get("blur", 0.0) > 0.0:
            work = cv2.GaussianBlur(work, (0, 0), effect["blur"])
        if effect.get("noise", 0.0) > 0.0:
            work += rng.normal(0.0, effect["noise"], work.shape)
        out = np.clip(work, 0, 255).astype(np.uint8)
        if "jpeg" in effect:  # through JPEG at that quality, whatever the file's own format
            out = cv2.imdecode(cv2.imencode(".jpg", out, [cv2.IMWRITE_JPEG_QUALITY,
                                                          effect["jpeg"]])[1], cv2.IMREAD_COLOR)
        cv2.imwrite(os.path.join(frames_dir, base), out, [cv2.IMWRITE_JPEG_QUALITY, 95])
    if size is None:
        fail("none of the images is labelled (frame_file names the image file)")
    centre = ((size[0] - 1) / 2.0, (size[1] - 1) / 2.0)
    shift = (effect.get("shift", (0.0, 0.0))[0] * size[0],
             effect.get("shift", (0.0, 0.0))[1] * size[1])
    margin = args.border_px * zoom
    with open(os.path.join(folder, "labels.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(labels[0].keys()))
        writer.writeheader()
        for row in labels:
            row = dict(row)
            if row.get("u") and row.get("v"):
                u = zoom * (float(row["u"]) - centre[0]) + centre[0] + shift[0]
                v = zoom * (float(row["v"]) - centre[1]) + centre[1] + shift[1]
                row["u"], row["v"] = f"{u:.3f}", f"{v:.3f}"
                status = row.get("status", "ok")
                if not (0 <= u < size[0] and 0 <= v < size[1]):
                    row["status"] = "edge"
                elif status == "ok" and not (margin <= u < size[0] - margin and
                                             margin <= v < size[1] - margin):
                    row["status"] = "border"
            writer.writerow(row)
    with open(args.calib) as f:
        text = f.read()
    with open(os.path.join(folder, "calibration.yaml"), "w") as f:
        f.write(zoomed_calibration(text, zoom, centre, shift, args.calib))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--images", required=True, help='a glob, e.g. "DIR/*.jpg"')
    parser.add_argument("--labels", required=True)
    parser.add_argument("--calib", required=True)
    parser.add_argument("--dock", required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("--all-frames", action="store_true")
    parser.add_argument("--variants", default=",".join(VARIANTS))
    parser.add_argument("--border-px", type=float, default=8.0,
                        help="an ok label this close to the border after a zoom becomes border")
    argv = sys.argv[1:]
    extra = []
    if "--" in argv:
        extra = argv[argv.index("--") + 1:]
        argv = argv[:argv.index("--")]
    args = parser.parse_args(argv)
    try:
        import cv2
        import numpy as np
    except ImportError:
        fail("needs python3-opencv and python3-numpy (Debian packages; run /usr/bin/python3)")
    names = [v for v in args.variants.split(",") if v]
    for name in names:
        if name not in VARIANTS:
            fail(f"unknown variant '{name}' (known: {', '.join(VARIANTS)})")
    binary = os.environ.get("AUVDOCK_BIN", os.path.join(os.path.dirname(__file__), "..", "build",
                                                        "bin", "auvdock"))
    if not os.access(binary, os.X_OK):
        fail(f"{binary} not found: run scripts/build.sh or set AUVDOCK_BIN")
    if os.path.exists(args.out) and os.listdir(args.out):
        fail(f"{args.out}: exists and is not empty")
    labels = read_labels(args.labels)
    print(f"{'variant':<10} {'recall':>7} {'precision':>9} {'rms px':>7} {'pose rate':>9} "
          f"{'frames with a pose':>18}")
    for name in names:
        folder = os.path.join(args.out, name)
        make_variant(args, name, VARIANTS[name], labels, folder, cv2, np)
        result = os.path.join(folder, "detect")
        command = [binary, "detect", "--images", os.path.join(folder, "frames", "*"),
                   "--calib", os.path.join(folder, "calibration.yaml"), "--dock", args.dock,
                   "--labels", os.path.join(folder, "labels.csv"), "--out", result, "--quiet"]
        run = subprocess.run(command + extra, capture_output=True, text=True)
        if run.returncode != 0:
            fail(f"{name}: detect failed: {run.stderr.strip() or run.stdout.strip()}")
        with open(os.path.join(result, "summary.json")) as f:
            summary = json.load(f)
        m = summary["labels"]
        rms = m.get("centroid_rms_px")
        print(f"{name:<10} {m['recall']:>7.3f} {m['precision']:>9.3f} "
              f"{rms if rms is not None else float('nan'):>7.2f} "
              f"{m['pose_frames']:>4}/{m['pose_frames_eligible']:<4} "
              f"{summary['frames_with_pose']:>8}/{summary['images']}", flush=True)


if __name__ == "__main__":
    main()
