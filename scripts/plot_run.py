#!/usr/bin/python3
"""Plots of one estimate against a dataset's ground truth (PNG, matplotlib).

    /usr/bin/python3 scripts/plot_run.py --dataset DIR --estimate trajectory.tum --out PLOTDIR
        [--covariance covariance.csv] [--decisions decisions.csv] [--label NAME]

Writes into PLOTDIR (created; it may exist, the five files are replaced):
  trajectory.png  top (x-y) and side (x-z) views of the dock frame D: truth, estimate, the dock's
                  lights (dock.yaml) and the deck outline;
  errors.png      position (m) and attitude (deg) error per axis over time, with the +-3 sigma band
                  of the reported covariance, on the visibility stages (groundtruth/visibility.csv);
  stages.png      the visibility-stage timeline and how many lights each camera sees;
  nees.png        the pose NEES e^T Sigma^-1 e per estimate, with the 95 % band of chi-square(6);
  go_no_go.png    the go/no-go decision over time, NO-GO coloured by its reason's class.

Frames and conventions (README "Output files"): estimate and truth are T_D_B (body B in dock frame
D) in TUM files; covariance.csv is the 6x6 covariance over [dp_D (m), dtheta_D (rad)] with
T_D_B = (p + dp, Exp(dtheta) q), so the error of an estimate is
    e = [p_true - p_est,  Log(R_true R_est^T)]  (rotation vector in D).
Each estimate is compared with the ground truth interpolated at its own time stamp (linear in
position, geodesic in attitude) between samples at most MAX_TRUTH_GAP_S apart, as `auvdock
evaluate` does; estimates outside the truth or in a wider gap are left out.

Bad input (a missing or malformed file, a folder that cannot be written): one line on stderr,
exit 2; the plots are written to a temporary folder first and moved in only when all succeed.
"""
import argparse
import math
import os
import re
import shutil
import sys
import tempfile

try:
    import numpy as np
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError as missing:
    print(f"plot_run.py: needs numpy and matplotlib for this Python ({sys.executable}): "
          f"{missing} (on Debian: apt-get install python3-matplotlib, then /usr/bin/python3)",
          file=sys.stderr)
    sys.exit(2)

STAGE_COLOURS = {"stereo_only": "#cfe3f5", "both": "#d5efd0", "mono_only": "#fbe3c4",
                 "neither": "#eeeeee"}
CHI2_6_95 = (1.2373, 14.4494)  # chi-square, 6 dof: 2.5 % and 97.5 % quantiles
MAX_TRUTH_GAP_S = 0.1


class InputError(Exception):
    pass


def read_rows(path, min_columns, what):
    """Data rows of a CSV or whitespace file ('#' comments skipped) as lists of strings."""
    if not os.path.isfile(path):
        raise InputError(f"{path}: no such file ({what})")
    rows = []
    with open(path, newline="") as f:
        for number, line in enumerate(f, start=1):
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            fields = [x.strip() for x in (line.split(",") if "," in line else line.split())]
            if len(fields) < min_columns:
                raise InputError(f"{path}:{number}: expected {min_columns} columns, got {len(fields)}")
            rows.append((number, fields))
    return rows


def to_float(path, number, text):
    try:
        value = float(text)
    except ValueError:
        raise InputError(f"{path}:{number}: '{text}' is not a number") from None
    return value


def read_tum(path):
    """(t [s], p (N x 3), q xyzw (N x 4)) of a TUM file."""
    rows = read_rows(path, 8, "TUM trajectory")
    if not rows:
        raise InputError(f"{path}: no poses")
    data = np.array([[to_float(path, n, x) for x in r[:8]] for n, r in rows])
    return data[:, 0], data[:, 1:4], data[:, 4:8]


def quat_to_matrix(q):
    x, y, z, w = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def rotation_log(R):
    """Rotation vector of R (rad)."""
    cos_angle = np.clip((np.trace(R) - 1.0) / 2.0, -1.0, 1.0)
    angle = math.acos(cos_angle)
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    if angle < 1e-9:
        return 0.5 * w
    if math.pi - angle < 1e-6:  # near a half turn: the axis from the symmetric part
        axis = np.sqrt(np.maximum(np.diag(R) + 1.0, 0.0) / 2.0)
        axis *= np.sign(w + (w == 0))
        return angle * axis / np.linalg.norm(axis)
    return angle / (2.0 * math.sin(angle)) * w


def read_timestamped_ns(path, min_columns, what):
    """(t [s], rows) of a CSV whose first column is a time stamp in nanoseconds."""
    rows = read_rows(path, min_columns, what)
    times = []
    for number, fields in rows:
        if not re.fullmatch(r"\d+", fields[0]):
            raise InputError(f"{path}:{number}: '{fields[0]}' is not a time stamp in ns")
        times.append(int(fields[0]) * 1e-9)
    return np.array(times), rows


def read_covariance(path):
    times, rows = read_timestamped_ns(path, 37, "covariance")
    covariances = np.array([[to_float(path, n, x) for x in r[1:37]] for n, r in rows])
    return times, covariances.reshape(-1, 6, 6)


def read_dock(path):
    """Light positions in D (N x 3) and the deck's length and width (m) of a dock.yaml."""
    if not os.path.isfile(path):
        raise InputError(f"{path}: no such file (dock)")
    text = open(path).read()
    lights = [[float(v) for v in m.groups()] for m in re.finditer(
        r"p_D:\s*\[\s*([-\d.eE+]+)\s*,\s*([-\d.eE+]+)\s*,\s*([-\d.eE+]+)\s*\]", text)]
    if not lights:
        raise InputError(f"{path}: no lights (expected 'p_D: [x, y, z]' entries)")
    length = re.search(r"length_m:\s*([-\d.eE+]+)", text)
    width = re.search(r"width_m:\s*([-\d.eE+]+)", text)
    deck = (float(length.group(1)), float(width.group(1))) if length and width else None
    return np.array(lights), deck


def exp_so3(w):
    angle = np.linalg.norm(w)
    K = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    if angle < 1e-9:
        return np.eye(3) + K
    return (np.eye(3) + math.sin(angle) / angle * K +
            (1 - math.cos(angle)) / angle ** 2 * K @ K)


def interpolate_truth(t_est, t_truth, p_truth, q_truth):
    """(valid mask, p (N x 3), R (N x 3 x 3)) of the truth at each estimate time."""
    i1 = np.searchsorted(t_truth, t_est)
    exact = (i1 < len(t_truth)) & (t_truth[np.minimum(i1, len(t_truth) - 1)] == t_est)
    i1 = np.where(exact, i1 + 1, i1)  # an exact sample: interpolate from it (a = 0)
    i1 = np.clip(i1, 1, len(t_truth) - 1)
    i0 = i1 - 1
    gap = t_truth[i1] - t_truth[i0]
    a = np.where(gap > 0, (t_est - t_truth[i0]) / np.where(gap > 0, gap, 1), 0.0)
    valid = (a >= -1e-9) & (a <= 1 + 1e-9) & (gap <= MAX_TRUTH_GAP_S)
    p = p_truth[i0] + a[:, None] * (p_truth[i1] - p_truth[i0])
    R = []
    for k in range(len(t_est)):
        R0 = quat_to_matrix(q_truth[i0[k]])
        R1 = quat_to_matrix(q_truth[i1[k]])
        R.append(R0 @ exp_so3(a[k] * rotation_log(R0.T @ R1)))
    return valid, p, np.array(R)


def shade_stages(ax, stage_times, stages, t0):
    if stage_times is None:
        return
    start = 0
    for i in range(1, len(stages) + 1):
        if i == len(stages) or stages[i] != stages[start]:
            end = stage_times[i] if i < len(stages) else stage_times[-1]
            ax.axvspan(stage_times[start] - t0, end - t0,
                       color=STAGE_COLOURS.get(stages[start], "#ffffff"), lw=0, zorder=0)
            start = i


def stage_legend(fig):
    handles = [plt.Rectangle((0, 0), 1, 1, color=c) for c in STAGE_COLOURS.values()]
    fig.legend(handles, [s.replace("_", " ") for s in STAGE_COLOURS], loc="lower center",
               ncol=4, frameon=False, fontsize=8)


def reason_class(reason):
    """A NO-GO reason without its figures: 'no estimate: not initialised (...)' stays whole,
    numbers become N, text after the first ':' past the class is dropped."""
    text = re.sub(r"[-+]?\d+(\.\d+)?(e[-+]?\d+)?", "N", reason)
    parts = text.split(":")
    return ":".join(parts[:2]).strip() if len(parts) > 2 else text.strip()


class Run:
    """What the time plots show of one estimate (arrays over the estimates matched to truth)."""

    def __init__(self, **fields):
        self.__dict__.update(fields)


def say_missing(ax, text):
    ax.text(0.5, 0.5, text, ha="center", transform=ax.transAxes)


def save(fig, staging, name, bottom):
    """Stage legend below, tight layout above it, PNG into the staging folder."""
    stage_legend(fig)
    fig.tight_layout(rect=(0, bottom, 1, 1))
    fig.savefig(os.path.join(staging, name), dpi=110)
    plt.close(fig)


def plot_trajectory(staging, label, p_truth, p_est, lights, deck):
    fig, (top, side) = plt.subplots(2, 1, figsize=(9, 8))
    for ax, j, name in ((top, 1, "y [m] (starboard)"), (side, 2, "z [m] (down)")):
        ax.plot(p_truth[:, 0], p_truth[:, j], "k-", lw=1.2, label="truth")
        ax.plot(p_est[:, 0], p_est[:, j], ".", ms=2.5, color="tab:blue", label=label)
        ax.plot(lights[:, 0], lights[:, j], "o", ms=5, mfc="gold", mec="darkorange",
                label="dock lights")
        if deck and j == 1:
            ax.add_patch(plt.Rectangle((-deck[0] / 2, -deck[1] / 2), deck[0], deck[1],
                                       fill=False, ec="grey", ls="--", lw=0.8))
        ax.set_xlabel("x [m] (docking axis)")
        ax.set_ylabel(name)
        ax.grid(alpha=0.3)
    top.set_aspect("equal", adjustable="datalim")
    side.invert_yaxis()
    top.set_title("Trajectory in the dock frame D: top view")
    side.set_title("side view")
    top.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(staging, "trajectory.png"), dpi=110)
    plt.close(fig)


def plot_errors(staging, run):
    """Position and attitude error per axis, with the reported +-3 sigma."""
    fig, axes = plt.subplots(3, 2, figsize=(11, 8), sharex=True)
    for i, axis in enumerate("xyz"):
        for col, (err, scale, unit) in enumerate(((run.e_p, 1000.0, "mm"),
                                                  (run.e_theta, 180.0 / math.pi, "deg"))):
            ax = axes[i, col]
            shade_stages(ax, run.stage_times, run.stages, run.t0)
            ax.plot(run.t - run.t0, err[:, i] * scale, "-", lw=0.8, color="tab:blue")
            limit = max(np.percentile(np.abs(err[:, i] * scale), 99) * 1.5, 1e-9)
            if run.sigma is not None:
                band = 3.0 * run.sigma[:, i + 3 * col] * scale
                ax.plot(run.t - run.t0, band, "-", color="tab:red", lw=0.8,
                        label="+-3 sigma (reported)")
                ax.plot(run.t - run.t0, -band, "-", color="tab:red", lw=0.8)
                limit = max(limit, np.nanpercentile(band, 50))
            ax.axhline(0.0, color="k", lw=0.5)
            ax.set_ylabel(f"{'position' if col == 0 else 'attitude'} {axis} [{unit}]")
            ax.set_ylim(-limit, limit)
            ax.grid(alpha=0.3)
    for col in (0, 1):
        axes[2, col].set_xlabel("time [s]")
    axes[0, 0].set_title(f"{run.label}: position error (truth - estimate)")
    axes[0, 1].set_title("attitude error Log(R_true R_est^T)")
    if run.sigma is not None:
        axes[0, 0].legend(fontsize=8, loc="upper right")
    save(fig, staging, "errors.png", 0.04)


def plot_stages(staging, run):
    fig, ax = plt.subplots(figsize=(11, 3))
    if run.stage_times is not None:
        shade_stages(ax, run.stage_times, run.stages, run.t0)
        for j, name in enumerate(("stereo left", "stereo right", "mono")):
            ax.step(run.stage_times - run.t0, run.counts[:, j], where="post", lw=1.0, label=name)
        ax.legend(fontsize=8, loc="upper left")
    else:
        say_missing(ax, "no groundtruth/visibility.csv in the dataset")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("lights in view")
    ax.set_title("Visibility stages")
    save(fig, staging, "stages.png", 0.08)


def plot_nees(staging, run):
    fig, ax = plt.subplots(figsize=(11, 3.5))
    shade_stages(ax, run.stage_times, run.stages, run.t0)
    if run.nees is not None:
        ok = np.isfinite(run.nees)
        ax.semilogy(run.t[ok] - run.t0, run.nees[ok], ".", ms=3, color="tab:blue",
                    label="pose NEES")
        ax.axhspan(*CHI2_6_95, color="tab:green", alpha=0.15, label="95 % of chi-square(6)")
        ax.axhline(6.0, color="tab:green", lw=0.8)
        ax.set_title(f"{run.label}: NEES of the reported covariance "
                     f"(mean {np.mean(run.nees[ok]):.2f}, expected 6)")
        ax.legend(fontsize=8, loc="upper right")
    else:
        say_missing(ax, "no covariance given (--covariance)")
    ax.set_xlabel("time [s]")
    ax.grid(alpha=0.3, which="both")
    save(fig, staging, "nees.png", 0.06)


def plot_go_no_go(staging, run):
    fig, ax = plt.subplots(figsize=(11, 4))
    if run.decisions is not None:
        times, verdicts, reasons = run.decisions
        classes = ["GO"] + sorted({reason_class(r) for v, r in zip(verdicts, reasons)
                                   if v == "NO-GO"})
        level = [0 if v == "GO" else classes.index(reason_class(r))
                 for v, r in zip(verdicts, reasons)]
        colours = ["tab:green" if v == "GO" else "tab:red" for v in verdicts]
        shade_stages(ax, run.stage_times, run.stages, run.t0)
        ax.scatter(times - run.t0, level, c=colours, s=6)
        ax.set_yticks(range(len(classes)))
        ax.set_yticklabels([c if len(c) < 70 else c[:67] + "..." for c in classes], fontsize=7)
        ax.invert_yaxis()
        go = sum(v == "GO" for v in verdicts)
        ax.set_title(f"{run.label}: go/no-go ({go} GO of {len(verdicts)} decisions; "
                     "NO-GO by reason)")
    else:
        say_missing(ax, "no decisions given (--decisions)")
    ax.set_xlabel("time [s]")
    ax.grid(alpha=0.3, axis="x")
    save(fig, staging, "go_no_go.png", 0.06)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--dataset", required=True, help="dataset folder with groundtruth.tum")
    parser.add_argument("--estimate", required=True, help="TUM trajectory (T_D_B)")
    parser.add_argument("--covariance", help="covariance.csv of the estimate")
    parser.add_argument("--decisions", help="decisions.csv of the estimate")
    parser.add_argument("--label", default="estimate", help="name of the estimate in legends")
    parser.add_argument("--out", required=True, help="folder for the PNG files")
    args = parser.parse_args()

    if os.path.exists(args.out) and not os.path.isdir(args.out):
        raise InputError(f"{args.out}: exists and is not a folder (--out)")
    truth_path = os.path.join(args.dataset, "groundtruth.tum")
    t_truth, p_truth, q_truth = read_tum(truth_path)
    t_est, p_est, q_est = read_tum(args.estimate)
    lights, deck = read_dock(os.path.join(args.dataset, "dock.yaml"))
    visibility = os.path.join(args.dataset, "groundtruth", "visibility.csv")
    stage_times = stages = counts = None
    if os.path.isfile(visibility):
        stage_times, rows = read_timestamped_ns(visibility, 5, "visibility stages")
        stages = [r[4] for _, r in rows]
        counts = np.array([[to_float(visibility, n, x) for x in r[1:4]] for n, r in rows])
    cov_times = covariances = None
    if args.covariance:
        cov_times, covariances = read_covariance(args.covariance)
    decisions = None
    if args.decisions:
        decision_times, rows = read_timestamped_ns(args.decisions, 2, "decisions")
        decisions = (decision_times, [r[1] for _, r in rows],
                     [",".join(r[2:]) if len(r) > 2 else "" for _, r in rows])
        for (number, _), d in zip(rows, decisions[1]):
            if d not in ("GO", "NO-GO"):
                raise InputError(f"{args.decisions}:{number}: decision '{d}' is not GO or NO-GO")

    keep, p_true, R_true = interpolate_truth(t_est, t_truth, p_truth, q_truth)
    if not np.any(keep):
        raise InputError(f"{args.estimate}: no estimate lies within the ground truth of "
                         f"{truth_path}")
    t = t_est[keep]
    e_p = p_true[keep] - p_est[keep]
    e_theta = np.array([rotation_log(Rt @ quat_to_matrix(qe).T)
                        for Rt, qe in zip(R_true[keep], q_est[keep])])
    sigma = nees = None
    if covariances is not None:
        # The row of each estimate: the same time stamp (TUM seconds carry ~1e-7 s of float
        # rounding at these epochs, so within 1 ms).
        order = np.argsort(cov_times)
        sorted_times = cov_times[order]
        at = np.clip(np.searchsorted(sorted_times, t), 1, max(len(sorted_times) - 1, 1))
        rows = []
        for k, x in enumerate(t):
            near = [j for j in (at[k] - 1, at[k]) if 0 <= j < len(sorted_times)]
            j = min(near, key=lambda j: abs(sorted_times[j] - x))
            rows.append(int(order[j]) if abs(sorted_times[j] - x) < 1e-3 else -1)
        has = np.array([r >= 0 for r in rows])
        sigma = np.full((len(t), 6), np.nan)
        nees = np.full(len(t), np.nan)
        for k, r in enumerate(rows):
            if r < 0:
                continue
            c = covariances[r]
            sigma[k] = np.sqrt(np.maximum(np.diag(c), 0.0))
            e = np.concatenate([e_p[k], e_theta[k]])
            try:
                nees[k] = float(e @ np.linalg.solve(c, e))
            except np.linalg.LinAlgError:
                pass
        if not np.any(has):
            raise InputError(f"{args.covariance}: no row has the time stamp of an estimate")

    run = Run(label=args.label, t0=t_truth[0], t=t, e_p=e_p, e_theta=e_theta, sigma=sigma,
              nees=nees, stage_times=stage_times, stages=stages, counts=counts,
              decisions=decisions)
    parent = os.path.dirname(os.path.abspath(args.out))
    os.makedirs(parent, exist_ok=True)
    staging = tempfile.mkdtemp(prefix=".plots-", dir=parent)
    try:
        plot_trajectory(staging, args.label, p_truth, p_est, lights, deck)
        plot_errors(staging, run)
        plot_stages(staging, run)
        plot_nees(staging, run)
        plot_go_no_go(staging, run)
        os.makedirs(args.out, exist_ok=True)
        for name in os.listdir(staging):
            os.replace(os.path.join(staging, name), os.path.join(args.out, name))
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    print(f"plots: {args.out}/{{trajectory,errors,stages,nees,go_no_go}}.png")


if __name__ == "__main__":
    try:
        main()
    except InputError as error:
        print(f"plot_run.py: {error}", file=sys.stderr)
        sys.exit(2)
    except OSError as error:
        print(f"plot_run.py: {error.filename or ''}: {error.strerror}", file=sys.stderr)
        sys.exit(2)
