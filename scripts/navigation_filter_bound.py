#!/usr/bin/python3
"""How well can any linear filter or smoother of dead reckoning and acoustic fixes do on a log?

  /usr/bin/python3 scripts/navigation_filter_bound.py DATASET [DATASET ...] [--against-kf]

For each auvdock dataset folder with `dvl0`, `usbl0` and a ground truth (`groundtruth/data.csv`,
EuRoC columns), this builds dead reckoning with the ground truth's own attitude (better than any
estimator has: no heading error, no tilt error) and the DVL, then runs a 2-D Kalman filter and
its Rauch-Tung-Striebel smoother of that dead reckoning and the fixes over a grid of process
models, and prints each one's horizontal RMSE against the ground truth and its mean NEES:

  state x = [p_D (2), b_D (2)]: position and a slow velocity error of the dead reckoning
  p_k+1 = p_k + dp_k + dt b_k + w_p,   Q_p = (q_p^2 dt + (0.01 |dp_k|)^2) I   (position walk)
  b_k+1 = b_k + w_b,                    Q_b = q_b^2 dt I                      (velocity-error walk)
  (with the integrated-walk cross terms), a fix z = p + v, v ~ N(0, sigma_fix^2 I).

q_p = 0.05 m/sqrt(s) with q_b ~ 0 is the "2-D Kalman filter" baseline a user would write. The
grid spans both families and their mixtures; "oracle" takes the best setting per log (an
estimator cannot: it is the bound's bound). With --against-kf each figure is divided by the
baseline's (q_p 0.05, q_b 0), so that a target stated as a ratio to it can be checked against
what the information in the log allows. Needs numpy. Units: m, s.
"""
import argparse
import os
import sys

import numpy as np
import yaml

BASELINE = (0.05, 0.0)
GRID = [(qp, qb) for qp in (0.0, 0.01, 0.02, 0.05, 0.1) for qb in (0.0, 1e-4, 1e-3, 3e-3, 1e-2)]


def read_csv(path):
    return np.loadtxt(path, delimiter=',', comments='#', ndmin=2)


def quat_to_rot(q):
    """Rotation matrices from rows of unit quaternions (w, x, y, z)."""
    w, x, y, z = q.T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1)], 1)


def dvl_mounting(calibration_path):
    with open(calibration_path) as f:
        cal = yaml.safe_load(f)
    if not isinstance(cal, dict) or 'dvl' not in cal:
        raise SystemExit(f'{calibration_path}: no key "dvl"')
    T = np.array(cal['dvl']['T_B_S'], float).reshape(4, 4)
    return T[:3, :3], T[:3, 3]


def dead_reckoning(dataset):
    """Horizontal positions at the ground truth's times, from the DVL turned into D by the
    ground truth's attitude (lever arm removed with the attitude's own rate), started at the
    ground truth's first position; and the times (s)."""
    gt = read_csv(os.path.join(dataset, 'groundtruth', 'data.csv'))
    dvl = read_csv(os.path.join(dataset, 'dvl0', 'data.csv'))
    R_B_S, p_B_S = dvl_mounting(os.path.join(dataset, 'calibration.yaml'))
    t_gt = gt[:, 0] * 1e-9
    R_gt = quat_to_rot(gt[:, 4:8] / np.linalg.norm(gt[:, 4:8], axis=1, keepdims=True))
    t_dvl = dvl[:, 0] * 1e-9
    j = np.clip(np.searchsorted(t_gt, t_dvl), 1, len(t_gt) - 1)
    R = R_gt[j]
    dR = np.einsum('nji,njk->nik', R_gt[j - 1], R_gt[j])  # R_{j-1}^T R_j
    dt = (t_gt[j] - t_gt[j - 1])[:, None]
    omega = np.stack([dR[:, 2, 1] - dR[:, 1, 2], dR[:, 0, 2] - dR[:, 2, 0],
                      dR[:, 1, 0] - dR[:, 0, 1]], 1) / (2.0 * dt)
    v_B = dvl[:, 1:4] @ R_B_S.T - np.cross(omega, p_B_S)
    v_D = np.einsum('nij,nj->ni', R, v_B)[:, :2]
    v = np.stack([np.interp(t_gt, t_dvl, v_D[:, i]) for i in range(2)], 1)
    p = np.zeros((len(t_gt), 2))
    p[0] = gt[0, 1:3]
    p[1:] = p[0] + np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t_gt)[:, None], 0)
    return t_gt, p, gt[:, 1:3]


def filter_and_smooth(t, dr, fixes, q_p, q_b):
    """The filter's and the smoother's horizontal positions and their 2x2 covariances from the
    first fix on, and the index of the first time they cover."""
    t_fix = fixes[:, 0] * 1e-9
    k0 = int(np.searchsorted(t, t_fix[0]))
    x = np.zeros(4)
    x[:2] = fixes[0, 1:3]
    P = np.diag([fixes[0, 4] ** 2] * 2 + [0.02 ** 2] * 2)
    H = np.hstack([np.eye(2), np.zeros((2, 2))])
    xf, Pf, xp, Pp, Fs = [], [], [], [], []
    i = 1
    for k in range(k0, len(t)):
        if k > k0:
            dt = t[k] - t[k - 1]
            dp = dr[k] - dr[k - 1]
            F = np.eye(4)
            F[:2, 2:] = dt * np.eye(2)
            Q = np.zeros((4, 4))
            Q[:2, :2] = (q_b ** 2 * dt ** 3 / 3 + q_p ** 2 * dt + (0.01 * np.linalg.norm(dp)) ** 2
                         + 1e-12) * np.eye(2)
            Q[:2, 2:] = Q[2:, :2] = q_b ** 2 * dt ** 2 / 2 * np.eye(2)
            Q[2:, 2:] = (q_b ** 2 * dt + 1e-12) * np.eye(2)
            x = F @ x
            x[:2] += dp
            P = F @ P @ F.T + Q
            Fs.append(F)
        xp.append(x.copy())
        Pp.append(P.copy())
        while i < len(t_fix) and t_fix[i] <= t[k]:
            S = H @ P @ H.T + fixes[i, 4] ** 2 * np.eye(2)
            K = P @ H.T @ np.linalg.inv(S)
            x = x + K @ (fixes[i, 1:3] - H @ x)
            P = (np.eye(4) - K @ H) @ P
            i += 1
        xf.append(x.copy())
        Pf.append(P.copy())
    xs, Ps = [None] * len(xf), [None] * len(xf)
    xs[-1], Ps[-1] = xf[-1], Pf[-1]
    for n in range(len(xf) - 2, -1, -1):
        C = Pf[n] @ Fs[n].T @ np.linalg.inv(Pp[n + 1])
        xs[n] = xf[n] + C @ (xs[n + 1] - xp[n + 1])
        Ps[n] = Pf[n] + C @ (Ps[n + 1] - Pp[n + 1]) @ C.T
    return ((np.array(xf)[:, :2], np.array(Pf)[:, :2, :2]),
            (np.array(xs)[:, :2], np.array(Ps)[:, :2, :2]), k0)


def rmse(estimate, truth):
    return float(np.sqrt(((estimate - truth) ** 2).sum(1).mean()))


def mean_nees(estimate, covariance, truth):
    """Mean horizontal NEES (2 when the covariance is honest)."""
    e = estimate - truth
    return float(np.einsum('ni,nij,nj->n', e, np.linalg.inv(covariance), e).mean())


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('datasets', nargs='+')
    ap.add_argument('--against-kf', action='store_true',
                    help='divide every figure by the baseline filter\'s (q_p 0.05, q_b 0)')
    args = ap.parse_args()
    results = []  # per dataset: {setting: (filter rmse, smoother rmse)}
    nees = []  # per dataset: {setting: (filter NEES, smoother NEES)}
    for ds in args.datasets:
        for need in ('dvl0/data.csv', 'usbl0/data.csv', 'groundtruth/data.csv', 'calibration.yaml'):
            if not os.path.exists(os.path.join(ds, need)):
                sys.exit(f'navigation_filter_bound.py: {ds}: no {need}')
        t, dr, truth = dead_reckoning(ds)
        fixes = read_csv(os.path.join(ds, 'usbl0', 'data.csv'))
        row, row_nees = {}, {}
        for setting in sorted(set(GRID + [BASELINE])):
            (f, Pf), (s, Ps), k0 = filter_and_smooth(t, dr, fixes, *setting)
            row[setting] = (rmse(f, truth[k0:]), rmse(s, truth[k0:]))
            row_nees[setting] = (mean_nees(f, Pf, truth[k0:]), mean_nees(s, Ps, truth[k0:]))
        results.append(row)
        nees.append(row_nees)
    scale = [r[BASELINE][0] if args.against_kf else 1.0 for r in results]
    unit = 'x the baseline filter' if args.against_kf else 'm'
    names = [os.path.basename(os.path.normpath(d)) for d in args.datasets]
    print(f'horizontal RMSE ({unit}), filter / smoother; dead reckoning with the reference attitude')
    print('q_p q_b | ' + ' | '.join(names) + ' | median filter, smoother')
    for setting in GRID:
        f = [r[setting][0] / s for r, s in zip(results, scale)]
        sm = [r[setting][1] / s for r, s in zip(results, scale)]
        cells = ' | '.join(f'{a:.2f}/{b:.2f}' for a, b in zip(f, sm))
        print(f'{setting[0]:.2f} {setting[1]:.4f} | {cells} | {np.median(f):.2f}, {np.median(sm):.2f}')
    best_f = [min(r[g][0] for g in GRID) / s for r, s in zip(results, scale)]
    best_s = [min(r[g][1] for g in GRID) / s for r, s in zip(results, scale)]
    print('oracle (best setting per log) | ' + ' | '.join(f'{a:.2f}/{b:.2f}' for a, b in
                                                          zip(best_f, best_s))
          + f' | {np.median(best_f):.2f}, {np.median(best_s):.2f}')
    if not args.against_kf:
        print('baseline filter (0.05, 0) | ' + ' | '.join(f'{r[BASELINE][0]:.2f}' for r in results))
    print('mean horizontal NEES (2 when honest), filter / smoother')
    for setting in GRID:
        cells = ' | '.join(f'{n[setting][0]:.1f}/{n[setting][1]:.1f}' for n in nees)
        print(f'{setting[0]:.2f} {setting[1]:.4f} | {cells} | median '
              f'{np.median([n[setting][0] for n in nees]):.1f}, '
              f'{np.median([n[setting][1] for n in nees]):.1f}')


if __name__ == '__main__':
    main()
