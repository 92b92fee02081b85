#!/usr/bin/env python3
"""Measure the light network (scripts/train_light_net.py) on hand-labelled frames.

    /usr/bin/python3 scripts/measure_light_net.py --images 'FOLDER/*.jpg' --labels labels.csv \
        --model data/models/light_net.onnx [--thresholds 0.3 0.4 0.5]

Runs the ONNX model through OpenCV's DNN module exactly as learned_light_detector.cc does
(cv::imread BGR, INTER_AREA resize to 320x256, pixel / 255) and takes the heatmap's 3x3 local
maxima >= threshold at the network's own positions, u = (4 (j + o_x) + 1/2) / s_x - 1/2 (no
core refinement). Labels: `frame_file,frame_index,u,v,status,quality` (the format of
`auvdock detect --labels`); status ok | border | edge | none. Only labelled frames are scored.
Score: greedy nearest-first matching of detections to ok/border labels within --hit-px (10);
recall over ok labels; precision over all detections in the labelled frames, where a detection
within --edge-px (15) of an edge label is not false; centre RMS over the hits on ok labels of
quality good. False detections within 3 hit_px of a label are counted apart (duplicates of a
light, which learned_light_detector.cc may merge).
"""
import argparse, csv, glob, os, sys, time
import cv2
import numpy as np

IN_W, IN_H, STRIDE = 320, 256, 4


def detect(net, img, thresholds):
    H, W = img.shape[:2]
    sx, sy = IN_W / W, IN_H / H
    x = img if (W, H) == (IN_W, IN_H) else cv2.resize(img, (IN_W, IN_H),
                                                      interpolation=cv2.INTER_AREA)
    net.setInput(cv2.dnn.blobFromImage(x, 1 / 255.0, swapRB=False), "image")
    heat, off, _ = net.forward(["heatmap", "offset", "log_sigma"])
    h, off = heat[0, 0], np.clip(off[0], 0, 1)
    mx = cv2.dilate(h, np.ones((3, 3), np.uint8))
    out = {}
    for t in thresholds:
        i, j = np.nonzero((h >= mx) & (h >= t))
        u = (STRIDE * (j + off[0, i, j]) + 0.5) / sx - 0.5
        v = (STRIDE * (i + off[1, i, j]) + 0.5) / sy - 0.5
        out[t] = np.column_stack([u, v])
    return out


def score(det, labels, hit_px, edge_px):
    """(hits on ok, ok labels, false detections, detections, squared errors on ok/good hits,
    {quality: [hits, ok labels]}, false detections within 3 hit_px of a label)."""
    match = [l for l in labels if l[2] in ("ok", "border")]
    edges = [l for l in labels if l[2] == "edge"]
    pairs = sorted((np.hypot(d[0] - l[0], d[1] - l[1]), a, b)
                   for a, d in enumerate(det) for b, l in enumerate(match))
    used_d, used_l, hits, sq, byq = set(), set(), 0, [], {}
    for l in labels:
        if l[2] == "ok":
            byq.setdefault(l[3], [0, 0])[1] += 1
    for dist, a, b in pairs:
        if dist > hit_px or a in used_d or b in used_l:
            continue
        used_d.add(a)
        used_l.add(b)
        if match[b][2] == "ok":
            hits += 1
            byq[match[b][3]][0] += 1
            if match[b][3] == "good":
                sq.append(dist ** 2)
    false = [d for a, d in enumerate(det) if a not in used_d and
             not any(np.hypot(d[0] - e[0], d[1] - e[1]) <= edge_px for e in edges)]
    dup = sum(1 for d in false if any(np.hypot(d[0] - l[0], d[1] - l[1]) <= 3 * hit_px
                                      for l in labels))
    n_ok = sum(1 for l in labels if l[2] == "ok")
    return hits, n_ok, len(false), len(det), sq, byq, dup


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--images", required=True, help="glob of the frames")
    ap.add_argument("--labels", required=True, help="labels CSV")
    ap.add_argument("--model", required=True, help="ONNX model")
    ap.add_argument("--thresholds", type=float, nargs="+", default=[0.3, 0.4, 0.5])
    ap.add_argument("--hit-px", type=float, default=10.0)
    ap.add_argument("--edge-px", type=float, default=15.0)
    ap.add_argument("--threads", type=int, default=1)
    args = ap.parse_args()
    paths = {os.path.basename(p): p for p in glob.glob(args.images)}
    if not paths:
        sys.exit(f"measure_light_net.py: no images match '{args.images}'")
    if not os.path.isfile(args.labels) or not os.path.isfile(args.model):
        sys.exit("measure_light_net.py: labels or model file not found")
    labels = {}
    with open(args.labels) as f:
        for r in csv.DictReader(f):
            lst = labels.setdefault(r["frame_file"], [])
            if r["status"] != "none":
                lst.append((float(r["u"]), float(r["v"]), r["status"], r["quality"]))
    missing = [k for k in labels if k not in paths]
    if missing:
        sys.exit(f"measure_light_net.py: {len(missing)} labelled frames not among the images, "
                 f"e.g. {missing[0]}")
    cv2.setNumThreads(args.threads)
    net = cv2.dnn.readNetFromONNX(args.model)
    tot = {t: np.zeros(5) for t in args.thresholds}
    sqs = {t: [] for t in args.thresholds}
    qual = {t: {} for t in args.thresholds}
    t0 = time.time()
    for name in sorted(labels):
        img = cv2.imread(paths[name], cv2.IMREAD_COLOR)
        if img is None:
            sys.exit(f"measure_light_net.py: cannot read {paths[name]}")
        for t, det in detect(net, img, args.thresholds).items():
            h, n, fa, nd, sq, byq, dup = score(det, labels[name], args.hit_px, args.edge_px)
            for q, (qh, qn) in byq.items():
                acc = qual[t].setdefault(q, [0, 0])
                acc[0], acc[1] = acc[0] + qh, acc[1] + qn
            tot[t] += (h, n, fa, nd, dup)
            sqs[t] += sq
    ms = (time.time() - t0) / len(labels) * 1000
    print(f"{len(labels)} labelled frames, {int(tot[args.thresholds[0]][1])} ok labels "
          f"({ms:.1f} ms/frame incl. reading)")
    for t in args.thresholds:
        h, n, fa, nd, dup = tot[t]
        rms = np.sqrt(np.mean(sqs[t])) if sqs[t] else float("nan")
        by_q = ", ".join(f"{q} {a / max(b, 1):.2f}" for q, (a, b) in sorted(qual[t].items()))
        print(f"threshold {t:.2f}: recall {h / max(n, 1):.3f} ({int(h)}/{int(n)})  precision "
              f"{(nd - fa) / max(nd, 1):.3f} ({int(nd - fa)}/{int(nd)})  centre RMS ok/good "
              f"{rms:.2f} px; false near a label (duplicates) {int(dup)}; recall by quality {by_q}")


if __name__ == "__main__":
    main()
