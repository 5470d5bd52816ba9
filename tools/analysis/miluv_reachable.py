#!/usr/bin/python3
"""What an estimator could reach on an imported MILUV robot folder (issue 9, evidence only).

Reads the dataset folder written by `./meshnav import miluv` (imu.csv, ranges.csv, height.csv,
groundtruth.csv, setup.yaml) and prints, per window of the flight:

  * imu-vs-vicon: the IMU integrated over the window with its start attitude offset, start velocity
    and constant biases fitted FROM THE TRUTH (an oracle no estimator has): how well the IMU
    dead-reckons, and the IMU's mounting offset against the Vicon body;
  * ranges-vs-vicon: the tag-anchor ranges against the distances the Vicon pose gives;
  * window fit: IMU + ranges + heights over the window, a robust batch least-squares fit of start
    pose, velocity, biases and the rangefinder offset, started from the truth-fitted solution above.
    Where this fit moves away from the truth, the window's ranges prefer a wrong trajectory: no
    estimator that sees only this window's data (a filter sees less) can be expected to do better.

Usage: /usr/bin/python3 tools/analysis/miluv_reachable.py out/ifo001 [--window 20] [--step 10]
Units: metres, seconds, degrees. Takes about a minute per robot.
"""
import argparse
import csv

import numpy as np
import yaml
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

GRAVITY_M_S2 = np.array([0.0, 0.0, -9.81])
SIGMA_RANGE_M = 0.2  # MILUV ranges against Vicon: sigma 0.19 m (docs/real_data.md)
SIGMA_HEIGHT_M = 0.05
SIGMA_ACC_BIAS_M_S2 = 0.05  # priors of the window fit; the truth fit finds |b_a| < 0.08 m/s^2
SIGMA_GYRO_BIAS_RAD_S = 0.003
HEIGHT_MIN_M = 0.3  # the rangefinder's clamped bottom (0.29 m on the pad)
HEIGHT_EVERY = 6  # use every 6th height reading (~5 Hz) like the estimator's alignment


def load(folder):
    setup = yaml.safe_load(open(f"{folder}/setup.yaml"))
    tags = {int(k): np.array(v, float) for k, v in setup["rel_tag_positions"].items()}
    anchors = {int(k): np.array(v, float) for k, v in setup["abs_anchor_positions"].items()}
    ranges = []
    for r in csv.DictReader(open(f"{folder}/ranges.csv")):
        a, b = int(r["UWB_ID1"]), int(r["UWB_ID2"])
        if a in anchors:
            a, b = b, a
        if a in tags and b in anchors:  # inter-robot ranges need the other robot's state: left out
            ranges.append((float(r["t"]), a, b, float(r["range_corr"])))
    imu = np.loadtxt(f"{folder}/imu.csv", delimiter=",", skiprows=1)
    height = np.loadtxt(f"{folder}/height.csv", delimiter=",", skiprows=1)
    height = height[height[:, 1] > HEIGHT_MIN_M][::HEIGHT_EVERY]
    gt = np.loadtxt(f"{folder}/groundtruth.csv", delimiter=",", comments="#")
    return tags, anchors, ranges, imu, height, gt


class Integrator:
    """Strapdown integration of imu.csv from t0 with x = [rotvec of R_ItoG(t0) (3), v (3), b_a (3),
    b_g (3), p_IinG (3)]; returns p_IinG and R_ItoG at the requested times."""

    def __init__(self, imu):
        self.t, self.acc, self.gyr = imu[:, 0], imu[:, 1:4], imu[:, 4:7]

    def __call__(self, t0, x, times):
        i0 = np.searchsorted(self.t, t0)
        i1 = min(np.searchsorted(self.t, times.max()) + 2, len(self.t) - 1)
        dt = np.diff(self.t[i0:i1 + 1])
        dR = Rotation.from_rotvec((self.gyr[i0:i1] - x[9:12]) * dt[:, None]).as_matrix()
        R = np.empty((len(dt) + 1, 3, 3))
        R[0] = Rotation.from_rotvec(x[0:3]).as_matrix()
        for k in range(len(dt)):
            R[k + 1] = R[k] @ dR[k]
        a = np.einsum("kij,kj->ki", R[:-1], self.acc[i0:i1] - x[6:9]) + GRAVITY_M_S2
        v = np.vstack([x[3:6], x[3:6] + np.cumsum(a * dt[:, None], 0)])
        p = np.vstack([x[12:15], x[12:15] + np.cumsum(v[:-1] * dt[:, None] + 0.5 * a * dt[:, None] ** 2, 0)])
        k = np.clip(np.searchsorted(self.t[i0:i1 + 1], times), 0, len(p) - 1)
        return p[k], R[k]


def truth_fit(integ, gt, t0, t1):
    """The IMU's start state and biases fitted to the Vicon positions of [t0, t1]."""
    sel = (gt[:, 0] > t0) & (gt[:, 0] < t1)
    tv, pv = gt[sel, 0][::5], gt[sel, 1:4][::5]
    j = np.searchsorted(gt[:, 0], t0)
    v0 = (gt[j + 5, 1:4] - gt[j - 5, 1:4]) / (gt[j + 5, 0] - gt[j - 5, 0])
    R0 = Rotation.from_quat(gt[j, 4:8])
    x0 = np.r_[R0.as_rotvec(), v0, np.zeros(6), gt[j, 1:4]]

    def residual(x):
        return np.r_[(integ(t0, x, tv)[0] - pv).ravel(), x[6:9] / 0.5, x[9:12] / 0.05]

    x = least_squares(residual, x0, method="lm").x
    err = np.linalg.norm(integ(t0, x, tv)[0] - pv, axis=1)
    offset = R0.inv() * Rotation.from_rotvec(x[0:3])
    return x, err, offset


def window_fit(integ, data, gt, t0, t1, x_truth):
    """Robust batch fit of IMU + ranges + heights over [t0, t1] started from the truth fit."""
    tags, anchors, ranges, _, height, _ = data
    rr = [r for r in ranges if t0 < r[0] < t1]
    hh = height[(height[:, 0] > t0) & (height[:, 0] < t1)]
    tr = np.array([r[0] for r in rr])

    def residual(x):
        p, R = integ(t0, x[:15], tr)
        e = [(np.linalg.norm(p[k] + R[k] @ tags[a] - anchors[b]) - z) / SIGMA_RANGE_M
             for k, (_, a, b, z) in enumerate(rr)]
        ph, _ = integ(t0, x[:15], hh[:, 0])
        return np.r_[e, (ph[:, 2] + x[15] - hh[:, 1]) / SIGMA_HEIGHT_M, x[6:9] / SIGMA_ACC_BIAS_M_S2,
                     x[9:12] / SIGMA_GYRO_BIAS_RAD_S, x[15] / 0.3]

    ph, _ = integ(t0, x_truth, hh[:, 0])
    x0 = np.r_[x_truth, np.median(hh[:, 1] - ph[:, 2]) if len(hh) else 0.0]
    sol = least_squares(residual, x0, loss="soft_l1", f_scale=2.0)
    sel = (gt[:, 0] > t0) & (gt[:, 0] < t1)
    tv, pv = gt[sel, 0][::10], gt[sel, 1:4][::10]
    err = np.linalg.norm(integ(t0, sol.x[:15], tv)[0] - pv, axis=1)
    moved = Rotation.from_rotvec(sol.x[:3]) * Rotation.from_rotvec(x_truth[:3]).inv()  # in G
    yaw_deg = np.degrees(moved.as_euler("ZYX")[0])
    return len(rr), err, yaw_deg


def range_residuals(data):
    tags, anchors, ranges, _, _, gt = data
    out = []
    for t, a, b, z in ranges:
        j = np.searchsorted(gt[:, 0], t)
        if 0 < j < len(gt):
            p_T = gt[j, 1:4] + Rotation.from_quat(gt[j, 4:8]).as_matrix() @ tags[a]
            out.append(z - np.linalg.norm(p_T - anchors[b]))
    return np.array(out)


def rms(e):
    return float(np.sqrt(np.mean(np.square(e))))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("folder", help="dataset folder written by ./meshnav import miluv")
    ap.add_argument("--window", type=float, default=20.0, help="window length [s] (default 20)")
    ap.add_argument("--step", type=float, default=10.0, help="window start step [s] (default 10)")
    ap.add_argument("--start", type=float, default=8.0, help="first window start [s]; the drones rest before")
    args = ap.parse_args()
    data = load(args.folder)
    integ = Integrator(data[3])
    gt = data[5]
    res = range_residuals(data)
    print(f"{args.folder}: {len(data[2])} tag-anchor ranges in {gt[-1, 0] - gt[0, 0]:.0f} s; against Vicon: "
          f"median {np.median(res):+.3f} m, robust sigma {1.4826 * np.median(np.abs(res - np.median(res))):.3f} m, "
          f"{int(np.sum(np.abs(res) > 0.3))} beyond 0.3 m")
    print(f"{'window [s]':>12} {'imu-vs-vicon rms/max [m]':>25} {'mount offset r/p/y [deg]':>26} "
          f"{'ranges':>6} {'window fit rms/max [m]':>23} {'fit yaw moved [deg]':>20}")
    fit_rms = []
    for t0 in np.arange(args.start, gt[-1, 0] - args.window, args.step):
        t1 = t0 + args.window
        x, err_imu, offset = truth_fit(integ, gt, t0, t1)
        n, err_fit, yaw = window_fit(integ, data, gt, t0, t1, x)
        fit_rms.append(rms(err_fit))
        rpy = np.degrees(offset.as_euler("ZYX"))[::-1]
        print(f"{t0:5.0f}-{t1:<6.0f} {rms(err_imu):12.3f} / {err_imu.max():.3f} {rpy[0]:+9.1f} {rpy[1]:+6.1f} {rpy[2]:+6.1f}"
              f"{n:11d} {rms(err_fit):14.3f} / {err_fit.max():.3f} {yaw:+16.1f}")
    print(f"window fit: median rms {np.median(fit_rms):.3f} m over {len(fit_rms)} windows of {args.window:.0f} s")


if __name__ == "__main__":
    main()
