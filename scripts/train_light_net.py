#!/usr/bin/env python3
"""Train the guide-light network (learned_light_detector.h) on randomised renders; export ONNX.

    AUVDOCK_BIN=/path/to/auvdock /usr/bin/python3 scripts/train_light_net.py \
        --out data/models/light_net.onnx

Seeded (simulator seeds, numpy, torch; one thread): the command reproduces the model, byte for
byte, given the same simulator. The shipped model was trained on the renders of the simulator as
of commit cc80492 (before the randomised look's funnel through the lights, render_look.h, of
commit 74b65f1); a later simulator renders other images and trains another model.
Measured (2 cores shared with a C++ build, one thread): 20.8 min wall from scratch (16 renders
466 s, training 738 s, held-out evaluation and export ~40 s), ~13.5 min with cached renders;
65.7k parameters, 259 kB; cv2.dnn 10-13 ms per image. Held-out renders at 0.4: recall 0.91,
precision 0.95, centre RMS 0.71 px.
Data: renders of data/scenarios/randomized.yaml (a new look per seed and camera) with its dock
swapped for each of data/docks/*.yaml; seeds 100d+k (dock d = 1..4, k < --seeds; the last k held
out). Every --frame-step-th frame of cam0..cam2 is cached in --work/cache/, the rest deleted.

Contract (fixed shapes, opset 11, OpenCV 4.6 DNN; Conv, Relu, Add, Sigmoid only):
  input  image      1x3x256x320, BGR, pixel / 255 (any image resized to 320x256, INTER_AREA)
  output heatmap    1x1x64x80  P(a light's centre lies in cell (i,j)), sigmoid in the graph;
                    cell (i,j) covers input pixels x in [4j, 4j+4), y in [4i, 4i+4)
         offset     1x2x64x80  the centre inside its cell in cells, in [0,1] (sigmoid):
                    x_in = 4 (j + o_x), y_in = 4 (i + o_y)
         log_sigma  1x1x64x80  ln(sigma_px s), the blob sigma in input pixels, s = sqrt(sx sy)
Pixel centres at integer coordinates in both images ((0,0) = centre of the top-left pixel):
with sx = 320 / W, sy = 256 / H,  x_in = (u + 1/2) sx - 1/2  and  u = (x_in + 1/2) / sx - 1/2.
A training crop of cw x ch render pixels from x0 maps alike: x_in = (u - x0 + 1/2) 320/cw - 1/2.

Targets (CenterNet, Zhou et al. 2019): a light is positive when its centre lies inside the
render and the window and its peak contrast times the augmentation's gain is >= --min-peak
(status ok or border); its cell (floor(y_in/4), floor(x_in/4)) gets heat 1, the others
exp(-d^2 / (2 0.8^2)), d in cells (max over lights). Fainter lights, and lights whose centre is
off the window or the render while their glow may show (3 sigma + 2 px), give ignore discs
(radius 2 cells: no loss). Loss = penalty-reduced focal loss (alpha 2, beta 4) / #positives +
(2 L1(offset) + 0.2 L1(log_sigma)) / #positives on the positive cells. Training runs on
--window crops at the input's scale (the network is fully convolutional; 4x cheaper).

Network: 3x3 conv-BN-ReLU, stride 2 (16 ch), 2 (40 ch), 1; three residual 3x3 at dilations
2, 4, 1 (receptive field ~70 input px: a halo and its surroundings); 3x3 heads; BN folded.

Augmentation (what the real footage has and the renders lack): crops 0.35-1.3 x the render
(padded when larger, aspect +-10 %), a light put anywhere in the window incl. its borders,
rotation +-10 deg, flips; interlace combing (odd rows shifted 1-6 px); wide glows round the
lights (2.5-8 sigma); bright rims, discs, vanes and cables drawn beside lights (lighten-only,
off a light's core); per-channel offsets and gains, gain 0.5-2 with clipping; split toning
(highlights' hue -20..+80 deg: the renders' cyan lights towards blue; shadows' hue another
+-60 deg); saturation; gray images; gamma; Gaussian and horizontal motion blur; noise; JPEG
30-95. Lights stay green-cyan to violet-blue (never red). No real footage is used.
"""
import argparse, copy, csv, os, re, shutil, subprocess, sys, time
import cv2
import numpy as np
import torch
import torch.nn as nn
import torch.nn.functional as F
from torch.nn.utils.fusion import fuse_conv_bn_eval

IN_W, IN_H, STRIDE = 320, 256, 4
DOCKS = ["ring_8", "centerline_8", "corners_centre_5", "t_shape"]
REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUTPUTS = ["heatmap", "offset", "log_sigma"]


def render(args, dock, seed):
    """[(png path, lights n x 4: u, v, sigma_px, peak)] of a cached render (made when missing)."""
    cache = os.path.join(args.work, "cache", f"{dock}_s{seed}_every{args.frame_step}")
    if not os.path.exists(os.path.join(cache, "labels.csv")):
        with open(os.path.join(REPO, "data/scenarios/randomized.yaml")) as f:
            text, n = re.subn(r"(?m)^dock:.*$", "dock: " + os.path.join(REPO, "data/docks",
                                                                        dock + ".yaml"), f.read())
        if n != 1:
            sys.exit("train_light_net.py: data/scenarios/randomized.yaml has no 'dock:' line")
        scen, tmp = os.path.join(args.work, f"scenario_{dock}.yaml"), os.path.join(args.work, "tmp")
        with open(scen, "w") as f:
            f.write(text)
        shutil.rmtree(tmp, ignore_errors=True)
        shutil.rmtree(cache, ignore_errors=True)
        subprocess.run([args.auvdock, "simulate", "--scenario", scen, "--seed", str(seed),
                        "--out", tmp, "--quiet"], check=True, stdout=subprocess.DEVNULL)
        os.makedirs(cache)
        rows = []
        for cam in ("cam0", "cam1", "cam2"):
            with open(os.path.join(tmp, "groundtruth", cam + "_lights.csv")) as f:
                gt = list(csv.DictReader(f))
            keep = sorted({r["frame_file"] for r in gt})[::args.frame_step]
            for fr in keep:
                shutil.copy(os.path.join(tmp, cam, "data", fr), os.path.join(cache, cam + "_" + fr))
            rows += [[cam + "_" + r["frame_file"]] + [r[k] for k in ("u", "v", "status", "sigma_px",
                     "peak")] for r in gt if r["frame_file"] in set(keep)]
        with open(os.path.join(cache, "labels.csv"), "w") as f:
            csv.writer(f).writerows(rows)
        shutil.rmtree(tmp)
    data = {}
    with open(os.path.join(cache, "labels.csv")) as f:
        for name, u, v, status, sig, peak in csv.reader(f):
            lst = data.setdefault(os.path.join(cache, name), [])
            if status != "none":  # ok | border
                lst.append([float(u), float(v), float(sig), float(peak)])
    return [(p, np.array(l, np.float64).reshape(-1, 4)) for p, l in sorted(data.items())]


def augment(img, lights, rng, ww, wh):
    """A wh x ww window of a random crop of the render, at the scale the 320x256 input would have
    it, and its lights as rows (x_in, y_in, sigma_in, peak x gain, centre inside the render)."""
    H, W = img.shape[:2]
    inside = ((lights[:, 0] >= 0) & (lights[:, 0] <= W - 1) & (lights[:, 1] >= 0) &
              (lights[:, 1] <= H - 1)).astype(np.float64)
    if rng.random() < 0.3:  # interlace combing: the odd field shifted horizontally
        img = img.copy()
        img[1::2] = np.roll(img[1::2], int(rng.choice([-1, 1]) * rng.integers(1, 7)), axis=1)
    c, a = np.exp(rng.uniform(np.log(0.35), np.log(1.3))), np.exp(rng.uniform(-0.1, 0.1))
    sx, sy = IN_W / (c * a * W), IN_H / (c / a * H)  # crop c x the render, aspect a
    fx = fy = 1.0
    if sx < 1 and sy < 1:  # downscale first with INTER_AREA, as the C++ side does
        img = cv2.resize(img, (round(W * sx), round(H * sy)), interpolation=cv2.INTER_AREA)
        fx, fy = img.shape[1] / W, img.shape[0] / H
    x, y = (lights[:, 0] + 0.5) * fx - 0.5, (lights[:, 1] + 0.5) * fy - 0.5
    kx, ky = sx / fx, sy / fy  # the remaining scale
    if len(lights) and rng.random() < 0.8:  # a random light at a random window position
        k = rng.integers(len(lights))
        tx = rng.uniform(-0.1, 1.1) * (ww - 1) - x[k] * kx
        ty = rng.uniform(-0.1, 1.1) * (wh - 1) - y[k] * ky
    else:
        tx = rng.uniform(-0.2, 1.0) * ww - (img.shape[1] - 1) * kx * rng.random()
        ty = rng.uniform(-0.2, 1.0) * wh - (img.shape[0] - 1) * ky * rng.random()
    ang = np.deg2rad(rng.uniform(-10, 10)) if rng.random() < 0.5 else 0.0
    R = np.array([[np.cos(ang), -np.sin(ang)], [np.sin(ang), np.cos(ang)]])
    A, ctr = R @ np.diag([kx, ky]), np.array([ww / 2, wh / 2])
    t = R @ (np.array([tx, ty]) - ctr) + ctr
    pad = tuple(int(v) for v in (rng.uniform(0, 90, 3) if rng.random() < 0.5 else (0, 0, 0)))
    out = cv2.warpAffine(img, np.hstack([A, t[:, None]]), (ww, wh), flags=cv2.INTER_LINEAR,
                         borderMode=cv2.BORDER_CONSTANT, borderValue=pad)
    pts, sig = (A @ np.stack([x, y]) + t[:, None]).T, lights[:, 2] * np.sqrt(sx * sy)
    if rng.random() < 0.5:
        out, pts[:, 0] = out[:, ::-1], ww - 1 - pts[:, 0]
    if rng.random() < 0.5:
        out, pts[:, 1] = out[::-1], wh - 1 - pts[:, 1]
    if rng.random() < 0.5:
        out = halos(out, pts, sig, lights[:, 3], rng)
    if rng.random() < 0.4:
        out = structures(out, pts, sig, rng)
    f = out.astype(np.float32)  # photometric
    f += rng.uniform(-40, 40, 3).astype(np.float32) * (rng.random() < 0.7)
    gain = np.exp(rng.uniform(np.log(0.5), np.log(2.0)))
    f = np.clip(f * (gain * rng.uniform(0.75, 1.25, 3)).astype(np.float32), 0, 255).astype(np.uint8)
    hsv = cv2.cvtColor(f, cv2.COLOR_BGR2HSV)
    hi = rng.uniform(-10, 40)  # split toning (OpenCV hue units of 2 deg): highlights, shadows
    lo = hi + (rng.uniform(-30, 30) if rng.random() < 0.5 else 0.0)
    w = np.clip((hsv[..., 2].astype(np.float32) - 100) / 100, 0, 1)
    hsv[..., 0] = np.round(hsv[..., 0] + lo + (hi - lo) * w).astype(np.int16) % 180
    hsv[..., 1] = np.clip(hsv[..., 1] * rng.uniform(0.6, 1.4), 0, 255)
    f = cv2.cvtColor(hsv, cv2.COLOR_HSV2BGR)
    if rng.random() < 0.05:
        f = cv2.cvtColor(cv2.cvtColor(f, cv2.COLOR_BGR2GRAY), cv2.COLOR_GRAY2BGR)
    g = rng.uniform(0.7, 1.5)
    f = (255.0 * (f / 255.0) ** g).astype(np.float32)
    if rng.random() < 0.3:
        f = cv2.GaussianBlur(f, (0, 0), rng.uniform(0.3, 1.2))
    if rng.random() < 0.25:  # horizontal motion blur
        n = int(rng.integers(2, 7))
        f = cv2.filter2D(f, -1, np.full((1, n), 1.0 / n, np.float32))
    f = np.clip(f + rng.normal(0, rng.uniform(0, 6), f.shape).astype(np.float32), 0, 255)
    f = f.astype(np.uint8)
    if rng.random() < 0.6:
        q = int(rng.integers(30, 96))
        f = cv2.imdecode(cv2.imencode(".jpg", f, [cv2.IMWRITE_JPEG_QUALITY, q])[1], 1)
    peak = lights[:, 3] * gain * max(0.3, 1.0 - 0.5 * (g - 1.0))
    return f, np.column_stack([pts, sig, peak, inside])


def halos(img, pts, sig, peak, rng):
    """A wide glow (scattering, bloom) round every light: a Gaussian of 2.5-8 sigma, up to
    20-150 gray levels (less for faint lights), tinted like the light's own glow."""
    wh, ww = img.shape[:2]
    f, (k, amp) = img.astype(np.float32), (rng.uniform(2.5, 8), rng.uniform(20, 150))
    jj, ii = np.meshgrid(np.arange(ww), np.arange(wh))
    for (x, y), s, p in zip(pts, sig, peak):
        r = k * s
        if -3 * r < x < ww + 3 * r and -3 * r < y < wh + 3 * r:
            d2 = (jj - x) ** 2 + (ii - y) ** 2
            ring = (d2 >= (1.5 * s) ** 2) & (d2 <= (3 * s + 1) ** 2)
            tint = f[ring].mean(0) if ring.any() else np.full(3, 255.0, np.float32)
            tint = tint / max(tint.max(), 1.0)
            f += (amp * min(1.0, p / 255) * np.exp(-d2 / (2 * r * r)))[..., None] * tint
    return np.clip(f, 0, 255).astype(np.uint8)


def structures(img, pts, sig, rng):
    """1-3 bright structures (discs, rim arcs, cables, vanes), often beside a light, drawn
    lighten-only and kept off a light's core (1.5 sigma + 1 px when it is bright, else off its
    glow, 3 sigma + 2 px): glow merging into a white rim."""
    wh, ww = img.shape[:2]
    alpha = np.zeros((wh, ww), np.float32)
    for _ in range(rng.integers(1, 4)):
        if len(pts) and rng.random() < 0.7:
            k = rng.integers(len(pts))
            c = tuple(int(v) for v in pts[k] + rng.normal(0, 4 * sig[k] + 6, 2))
        else:
            c = tuple(int(v) for v in rng.uniform(0, 1, 2) * (ww, wh))
        r, kind = int(rng.uniform(4, 60)), rng.integers(4)
        if kind == 0:
            ax = (r, int(r * rng.uniform(0.5, 1)))
            cv2.ellipse(alpha, c, ax, rng.uniform(0, 180), 0, 360, 1, -1)
        elif kind == 1:
            a0 = rng.uniform(0, 360)
            ax = (r, int(r * rng.uniform(0.7, 1)))
            cv2.ellipse(alpha, c, ax, 0, a0, a0 + rng.uniform(60, 300), 1, int(rng.integers(1, 5)))
        else:
            d = rng.normal(0, 1, 2)
            e = (int(c[0] + 3 * r * d[0]), int(c[1] + 3 * r * d[1]))
            cv2.line(alpha, c, e, 1, int(rng.integers(1, 3 if kind == 2 else 9)))
    alpha = cv2.GaussianBlur(alpha, (0, 0), rng.uniform(0.5, 1.5)) * rng.uniform(0.5, 1.0)
    jj, ii = np.meshgrid(np.arange(ww), np.arange(wh))
    for (x, y), s in zip(pts, sig):
        if -20 < x < ww + 20 and -20 < y < wh + 20:
            xi, yi = int(np.clip(x, 0, ww - 1)), int(np.clip(y, 0, wh - 1))
            r = 1.5 * s + 1 if img[yi, xi].max() >= 200 else 3 * s + 2
            alpha *= np.clip(np.hypot(jj - x, ii - y) / r - 1, 0, 1)
    colour, f = rng.uniform(170, 255, 3).astype(np.float32), img.astype(np.float32)
    return np.maximum(f, f * (1 - alpha[..., None]) + colour * alpha[..., None]).astype(np.uint8)


def targets(lights, ww, wh, min_peak):
    """Heat, loss mask, offset, log-sigma and positive-cell maps (wh/4 x ww/4) of a window."""
    gw, gh = ww // STRIDE, wh // STRIDE
    heat, lsig, posm = (np.zeros((gh, gw), np.float32) for _ in range(3))
    mask, off, pos = np.ones((gh, gw), np.float32), np.zeros((2, gh, gw), np.float32), []
    jj, ii = np.meshgrid(np.arange(gw), np.arange(gh))
    for x, y, s, peak, inside in lights:
        if 0 <= x <= ww - 1 and 0 <= y <= wh - 1 and inside and peak >= min_peak:
            j, i = min(int(x // STRIDE), gw - 1), min(int(y // STRIDE), gh - 1)
            heat = np.maximum(heat, np.exp(-((jj - j) ** 2 + (ii - i) ** 2) / (2 * 0.8 ** 2)))
            off[:, i, j] = np.clip([x / STRIDE - j, y / STRIDE - i], 0, 1)
            lsig[i, j] = np.log(max(s, 0.2))
            pos.append((i, j))
        elif -3 * s - 2 <= x <= ww + 3 * s + 1 and -3 * s - 2 <= y <= wh + 3 * s + 1:
            cj, ci = np.clip(x / STRIDE, 0, gw - 1), np.clip(y / STRIDE, 0, gh - 1)
            mask[(jj - cj) ** 2 + (ii - ci) ** 2 <= 2.0 ** 2 + 1e-6] = 0  # faint or off: ignore
    for i, j in pos:
        posm[i, j], heat[i, j], mask[i, j] = 1, 1, 1
    return heat, mask, off, lsig, posm


class LightNet(nn.Module):
    def __init__(self, a=16, b=40):
        super().__init__()
        def cbr(i, o, s=1, d=1):
            return nn.Sequential(nn.Conv2d(i, o, 3, s, d, d, bias=False), nn.BatchNorm2d(o),
                                 nn.ReLU(inplace=True))
        self.stem = nn.Sequential(cbr(3, a, 2), cbr(a, b, 2), cbr(b, b))
        self.ctx = nn.ModuleList([cbr(b, b, 1, 2), cbr(b, b, 1, 4), cbr(b, b, 1, 1)])
        self.heat, self.off, self.sig = (nn.Conv2d(b, n, 3, 1, 1) for n in (1, 2, 1))
        nn.init.constant_(self.heat.bias, -2.19)

    def forward(self, image):
        x = self.stem(image)
        for m in self.ctx:
            x = x + m(x)
        return torch.sigmoid(self.heat(x)), torch.sigmoid(self.off(x)), self.sig(x)


def loss_fn(out, heat, mask, off, lsig, posm, w_off=2.0, w_sig=0.2):
    p, npos = out[0][:, 0].clamp(1e-4, 1 - 1e-4), posm.sum().clamp(min=1)
    lp = -(torch.log(p) * (1 - p) ** 2 * posm).sum()
    ln = -(torch.log(1 - p) * p ** 2 * (1 - heat) ** 4 * (1 - posm) * mask).sum()
    lo = (torch.abs(out[1] - off).sum(1) * posm).sum()
    ls = (torch.abs(out[2][:, 0] - lsig) * posm).sum()
    return (lp + ln) / npos + (w_off * lo + w_sig * ls) / npos


def evaluate(model, holdout, thrs, min_peak, tol=3.0):
    """Per threshold: recall, precision, centre RMS (full-resolution px) of the heatmap's 3x3
    peaks at the network's own positions on renders; hit within tol px, greedy nearest first.
    Required: lights inside the image with peak >= min_peak; a detection within 2 tol of another
    light (faint, off the image) is not false."""
    res = {t: [0, 0, 0, []] for t in thrs}  # hits, false, required, squared errors
    model.eval()
    with torch.no_grad():
        for path, L in holdout:
            img = cv2.imread(path)
            H, W = img.shape[:2]
            x = cv2.resize(img, (IN_W, IN_H), interpolation=cv2.INTER_AREA)
            o = model(torch.from_numpy(x.transpose(2, 0, 1)[None].astype(np.float32) / 255))
            h, off = o[0][0, 0].numpy(), o[1][0].numpy()
            top = (o[0] == F.max_pool2d(o[0], 3, 1, 1))[0, 0].numpy()
            inside = (L[:, 0] >= 0) & (L[:, 0] <= W - 1) & (L[:, 1] >= 0) & (L[:, 1] <= H - 1)
            req = inside & (L[:, 3] >= min_peak)
            for t in thrs:
                i, j = np.nonzero(top & (h >= t))
                du = (STRIDE * (j + off[0, i, j]) + 0.5) * W / IN_W - 0.5
                dv = (STRIDE * (i + off[1, i, j]) + 0.5) * H / IN_H - 0.5
                r, free = res[t], np.ones(len(du), bool)
                r[2] += req.sum()
                d = np.hypot(du[:, None] - L[None, :, 0], dv[:, None] - L[None, :, 1])
                for k in np.argsort(d.min(0) if len(du) else []):
                    cand = np.where(free & (d[:, k] <= tol))[0]
                    if len(cand):
                        m = cand[np.argmin(d[cand, k])]
                        free[m] = False
                        if req[k]:
                            r[0], r[3] = r[0] + 1, r[3] + [d[m, k] ** 2]
                near = (d[:, ~req] <= 2 * tol).any(1) if (~req).any() else np.zeros(len(du), bool)
                r[1] += (free & ~near).sum()
    return {t: (h / max(n, 1), h / max(h + f, 1), float(np.sqrt(np.mean(q))) if q else 0.0)
            for t, (h, f, n, q) in res.items()}


def export(model, path, sample):
    """Fold the batch norms, export ONNX opset 11, check OpenCV's outputs against torch's and
    time cv2.dnn on one thread."""
    m = copy.deepcopy(model).eval()
    for seq in [b for b in m.modules() if isinstance(b, nn.Sequential) and len(b) == 3
                and isinstance(b[1], nn.BatchNorm2d)]:
        seq[0], seq[1] = fuse_conv_bn_eval(seq[0], seq[1]), nn.Identity()
    torch.onnx.export(m, torch.zeros(1, 3, IN_H, IN_W), path, opset_version=11,
                      input_names=["image"], output_names=OUTPUTS, do_constant_folding=True)
    cv2.setNumThreads(1)
    net = cv2.dnn.readNetFromONNX(path)
    blob = cv2.dnn.blobFromImage(cv2.resize(sample, (IN_W, IN_H), interpolation=cv2.INTER_AREA),
                                 1 / 255.0, swapRB=False)
    net.setInput(blob, "image")
    outs = net.forward(OUTPUTS)
    with torch.no_grad():
        ref = model.eval()(torch.from_numpy(blob))
    diff = max(float(np.abs(a - b.numpy()).max()) for a, b in zip(outs, ref))
    print(f"cv2.dnn vs torch: max abs diff {diff:.2e}; shapes {[o.shape for o in outs]}")
    if diff > 1e-3:
        sys.exit("train_light_net.py: OpenCV's outputs differ from torch's")
    t0 = time.time()
    for _ in range(50):
        net.setInput(blob, "image"), net.forward(OUTPUTS)
    print(f"cv2.dnn forward (1 thread): {(time.time() - t0) / 50 * 1000:.1f} ms/image; "
          f"model {os.path.getsize(path) / 1024:.0f} kB")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="data/models/light_net.onnx")
    ap.add_argument("--auvdock", default=os.environ.get("AUVDOCK_BIN", "build/bin/auvdock"))
    ap.add_argument("--work", default="out/light_net", help="renders, scenario copies")
    ap.add_argument("--seeds", type=int, default=4, help="renders per dock (the last held out)")
    ap.add_argument("--frame-step", type=int, default=5, help="keep every n-th frame")
    ap.add_argument("--iters", type=int, default=6000)
    ap.add_argument("--batch", type=int, default=16)
    ap.add_argument("--window", type=int, nargs=2, default=[160, 128], metavar=("W", "H"))
    ap.add_argument("--lr", type=float, default=3e-3)
    ap.add_argument("--min-peak", type=float, default=15.0, help="gray levels for a positive")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--seed", type=int, default=7)
    args = ap.parse_args()
    if not (os.path.isfile(args.auvdock) and os.access(args.auvdock, os.X_OK)):
        sys.exit(f"train_light_net.py: no simulator at '{args.auvdock}' (--auvdock, AUVDOCK_BIN)")
    if args.seeds < 2 or args.iters < 1 or args.window[0] % STRIDE or args.window[1] % STRIDE:
        sys.exit("train_light_net.py: need --seeds >= 2, --iters >= 1, --window multiple of 4")
    torch.set_num_threads(args.threads), cv2.setNumThreads(args.threads)
    torch.manual_seed(args.seed)
    rng = np.random.default_rng(args.seed)
    os.makedirs(args.work, exist_ok=True)
    t_start, train, hold = time.time(), [], []
    for d, dock in enumerate(DOCKS):
        for k in range(args.seeds):
            (hold if k == args.seeds - 1 else train).extend(render(args, dock, 100 * (d + 1) + k))
    print(f"renders: {len(train)} training images, {len(hold)} held out "
          f"({time.time() - t_start:.0f} s)", flush=True)
    imgs = [cv2.imread(p, cv2.IMREAD_COLOR) for p, _ in train]  # decoded once, ~1 MB each
    lit = np.array([len(L) > 0 for _, L in train])  # 85 % of the draws show lights
    wts = np.where(lit, 0.85 / max(lit.sum(), 1), 0.15 / max((~lit).sum(), 1))
    model = LightNet()
    print(f"parameters: {sum(p.numel() for p in model.parameters())}")
    opt = torch.optim.AdamW(model.parameters(), lr=args.lr, weight_decay=1e-4)
    sched = torch.optim.lr_scheduler.OneCycleLR(opt, args.lr, total_steps=args.iters, pct_start=0.1)
    (ww, wh), t_train, run = args.window, time.time(), 0.0
    for it in range(args.iters):
        model.train()
        batch = [augment(imgs[k], train[k][1], rng, ww, wh)
                 for k in rng.choice(len(train), size=args.batch, p=wts / wts.sum())]
        tg = [targets(L, ww, wh, args.min_peak) for _, L in batch]
        x = np.stack([b[0] for b in batch]).transpose(0, 3, 1, 2).astype(np.float32) / 255
        loss = loss_fn(model(torch.from_numpy(x)),
                       *[torch.from_numpy(np.stack([t[i] for t in tg])) for i in range(5)])
        opt.zero_grad(), loss.backward(), opt.step(), sched.step()
        run = 0.98 * run + 0.02 * loss.item() if it else loss.item()
        if (it + 1) % 500 == 0:
            print(f"iter {it + 1}/{args.iters} loss {run:.3f} ({time.time() - t_train:.0f} s)",
                  flush=True)
    print(f"training: {time.time() - t_train:.0f} s")
    for thr, (r, p, rms) in evaluate(model, hold, [0.3, 0.4, 0.5], args.min_peak).items():
        print(f"held-out renders ({len(hold)} images) @ {thr}: recall {r:.3f} precision {p:.3f} "
              f"centre RMS {rms:.2f} px")
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    export(model, args.out, cv2.imread(hold[len(hold) // 2][0]))
    print(f"total wall time {time.time() - t_start:.0f} s -> {args.out}")


if __name__ == "__main__":
    main()
