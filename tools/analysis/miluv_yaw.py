#!/usr/bin/env python3
"""How well a run's heading is known, and how much the flight can tell it (docs/real_data.md,
"What MILUV allows"). For a dataset folder with groundtruth.csv (in the anchors' frame, as MILUV's
Vicon) and a meshnav_run output folder:

  * the yaw error of estimate.csv against the truth over time, with the filter's own σ_yaw and how
    often the error is beyond 3σ;
  * the horizontal specific force of the flight in the body frame (RMS, from the truth's
    accelerations): a yaw error δψ turns it into a horizontal acceleration error of about
    δψ·|f_h|, the only way an IMU-aided filter learns its heading from position fixes;
  * the IMU-to-body rotation fitted to the truth's accelerations on each half of the flight
    (Wahba's problem): if yaw were well excited, both halves would give the same mounting yaw.

σ_yaw is √qyy of estimate.csv, the variance about the IMU's z axis: the yaw variance up to the
tilt (a few degrees on MILUV). "In flight" is the truth's span less 9 s at the start and 4 s at
the end (MILUV's take-off and landing). The CSVs are read comma-separated, as meshnav writes them.

Usage: /usr/bin/python3 tools/analysis/miluv_yaw.py DATASET_DIR RUN_DIR [--step S]
"""

import argparse
import sys

import numpy as np


def quat_to_R(q):
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def yaw_of(qx, qy, qz, qw):
    return np.arctan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz))


def smooth(X, sigma_samples):
    k = np.exp(-0.5 * (np.arange(-3 * sigma_samples, 3 * sigma_samples + 1) / sigma_samples) ** 2)
    k /= k.sum()
    return np.column_stack([np.convolve(X[:, i], k, "same") for i in range(X.shape[1])])


def body_specific_force(truth, imu, dt=0.02, gravity=9.81, max_speed=8.0):
    """Truth accelerations (glitches dropped, 0.1 s Gaussian smoothing) as specific force in the
    truth's body frame, and the IMU's, on a common 50 Hz grid inside the flight."""
    t, p, q = truth[:, 0], truth[:, 1:4], truth[:, 4:8]
    jump = np.r_[False, np.linalg.norm(np.diff(p, axis=0), axis=1) / np.diff(t) > max_speed]
    t, p, q = t[~jump], p[~jump], q[~jump]
    T = np.arange(max(t[0], imu[0, 0]) + 1.0, min(t[-1], imu[-1, 0]) - 1.0, dt)
    P = smooth(np.column_stack([np.interp(T, t, p[:, i]) for i in range(3)]), 5)
    A = np.gradient(np.gradient(P, dt, axis=0), dt, axis=0)
    F = smooth(np.column_stack([np.interp(T, imu[:, 0], imu[:, i]) for i in (1, 2, 3)]), 5)
    Q = np.column_stack([np.interp(T, t, q[:, i]) for i in range(4)])
    Q /= np.linalg.norm(Q, axis=1)[:, None]
    fb = np.array([quat_to_R(qq).T @ (a + np.array([0.0, 0.0, gravity])) for qq, a in zip(Q, A)])
    ok = np.linalg.norm(A, axis=1) < 20.0
    return T[ok], fb[ok], F[ok]


def mounting(fb, F):
    """R_BI with fb ≈ R_BI F (Kabsch); its yaw, roll, pitch in degrees."""
    U, _, Vt = np.linalg.svd(F.T @ fb)
    D = np.diag([1.0, 1.0, np.linalg.det(Vt.T @ U.T)])
    R = Vt.T @ D @ U.T
    return (np.degrees(np.arctan2(R[1, 0], R[0, 0])), np.degrees(np.arctan2(R[2, 1], R[2, 2])),
            np.degrees(-np.arcsin(R[2, 0])))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dataset")
    ap.add_argument("run")
    ap.add_argument("--step", type=float, default=2.0, help="rows every STEP seconds of the estimate (default 2)")
    a = ap.parse_args()
    try:
        truth = np.loadtxt(f"{a.dataset}/groundtruth.csv", delimiter=",", comments="#", ndmin=2)
        imu = np.loadtxt(f"{a.dataset}/imu.csv", delimiter=",", skiprows=1, ndmin=2)
        est = np.genfromtxt(f"{a.run}/estimate.csv", delimiter=",", names=True)
    except OSError as e:
        sys.exit(f"miluv_yaw: {e}")
    if est.size < 2:
        sys.exit(f"miluv_yaw: {a.run}/estimate.csv has no estimate (never initialized?)")
    t = est["t"]
    yaw_true = np.interp(t, truth[:, 0], np.unwrap(yaw_of(*truth[:, 4:8].T)))
    err = np.degrees(np.angle(np.exp(1j * (yaw_of(est["qx"], est["qy"], est["qz"], est["qw"]) - yaw_true))))
    sig = np.degrees(np.sqrt(est["qyy"]))
    print(f"{'t [s]':>7} {'yaw error [deg]':>16} {'sigma [deg]':>12} {'|e|/sigma':>10}")
    for t_row in np.arange(t[0], t[-1], a.step):
        i = np.searchsorted(t, t_row)
        print(f"{t[i]:7.1f} {err[i]:+16.1f} {sig[i]:12.1f} {abs(err[i]) / sig[i]:10.1f}")
    beyond = np.mean(np.abs(err) > 3 * sig)
    print(f"yaw: RMS error {np.sqrt(np.mean(err ** 2)):.1f} deg, median sigma {np.median(sig):.1f} deg, "
          f"beyond 3 sigma {100 * beyond:.0f} % of the time")
    T, fb, F = body_specific_force(truth, imu)
    fly = (T > T[0] + 9.0) & (T < T[-1] - 4.0)
    print(f"horizontal specific force in the body frame (truth, in flight): RMS "
          f"{np.sqrt(np.mean(np.sum(fb[fly][:, :2] ** 2, axis=1))):.2f} m/s^2")
    half = np.median(T[fly])
    for name, m in (("first half", fly & (T < half)), ("second half", fly & (T >= half))):
        y, r, p = mounting(fb[m], F[m])
        print(f"IMU-to-body rotation fitted on the {name}: yaw {y:+.1f}, roll {r:+.1f}, pitch {p:+.1f} deg")


if __name__ == "__main__":
    main()
