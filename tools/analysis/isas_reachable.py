#!/usr/bin/python3
"""What an estimator could reach on an imported ISAS-Walk1 folder (issue 9, evidence only).

Reads the dataset folder written by `./meshnav import rosbag` (ranges.csv, groundtruth.csv,
imu.csv, setup.yaml) and prints, all SE(3)-aligned to the Vive truth like `meshnav eval`:

  * per-message and windowed multilateration of the raw ranges (the eval baseline's method),
  * the same after removing per-anchor range offsets fitted FROM THE TRUTH (an oracle no
    estimator has), and a cubic B-spline smoother over all ranges with those offsets,
  * the truth itself: tracker-to-tag lever arm, per-anchor offsets, time offset of the truth and
    Vive scale fitted jointly with the alignment; tracker-to-IMU rotation and time offset from the
    gyro against the tracker's angular rate.

Usage: /usr/bin/python3 tools/analysis/isas_reachable.py out/isas
"""
import csv
import sys

import numpy as np
import yaml
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation


def load(folder):
    setup = yaml.safe_load(open(f"{folder}/setup.yaml"))
    anchors = {int(k): np.array(v, float) for k, v in setup["abs_anchor_positions"].items()}
    p_TinI = np.array(list(setup["rel_tag_positions"].values())[0], float)
    rows = list(csv.DictReader(open(f"{folder}/ranges.csv")))
    rng = np.array([(float(r["t"]), int(r["UWB_ID2"]), float(r["range_corr"])) for r in rows])
    gt = np.loadtxt(f"{folder}/groundtruth.csv", delimiter=",", comments="#")
    imu = np.loadtxt(f"{folder}/imu.csv", delimiter=",", skiprows=1)
    return anchors, p_TinI, rng, gt, imu


def umeyama(p, g, scale=False):
    """R, t, s with g ≈ s R p + t (least squares)."""
    mp, mg = p.mean(0), g.mean(0)
    P, G = p - mp, g - mg
    U, D, Vt = np.linalg.svd(G.T @ P / len(p))
    S = np.diag([1, 1, np.sign(np.linalg.det(U) * np.linalg.det(Vt))])
    R = U @ S @ Vt
    s = np.trace(np.diag(D) @ S) / (P ** 2).sum(1).mean() if scale else 1.0
    return R, mg - s * R @ mp, s


def interp_pos(gt, t):
    return np.stack([np.interp(t, gt[:, 0], gt[:, 1 + k]) for k in range(3)], 1)


def interp_rot(gt, t):
    from scipy.spatial.transform import Slerp
    slerp = Slerp(gt[:, 0], Rotation.from_quat(gt[:, 4:8]))
    return slerp(np.clip(t, gt[0, 0], gt[-1, 0]))


def ate(p, g, scale=False):
    R, t, s = umeyama(p, g, scale)
    e = (R.T @ (g - (s * (R @ p.T).T + t)).T).T  # error in the anchors' frame G (z up)
    return np.sqrt((e ** 2).sum(1).mean()), np.sqrt((e[:, 2] ** 2).mean()), (R, t, s)


def solve_fix(A, z, x0, k=0.15):
    """Huber IRLS Gauss-Newton, as eval/multilateration."""
    x = x0.copy()
    for _ in range(20):
        d = x - A
        r = np.linalg.norm(d, axis=1)
        res = r - z
        w = np.where(np.abs(res) <= k, 1.0, k / np.maximum(np.abs(res), 1e-12))
        J = d / r[:, None]
        H = (J * w[:, None]).T @ J
        if np.linalg.cond(H) > 1e8:
            return None
        dx = np.linalg.solve(H, -(J * w[:, None]).T @ res)
        x += dx
        if np.linalg.norm(dx) < 1e-6:
            break
    res = np.linalg.norm(x - A, axis=1) - z
    return x if np.sqrt((res ** 2).mean()) <= 0.5 else None


def multilaterate(rng, anchors, offsets, window):
    """Fixes from epochs: ranges from the first unused one up to `window` later."""
    t, ids, z = rng[:, 0], rng[:, 1].astype(int), rng[:, 2]
    corr = np.array([offsets.get(i, 0.0) for i in ids])
    fixes, i, x_prev, t_prev = [], 0, None, -1e9
    while i < len(t):
        j = i
        while j < len(t) and t[j] - t[i] <= window + 1e-9:
            j += 1
        sel = slice(i, j)
        if len(set(ids[sel])) >= 4:
            A = np.array([anchors[a] for a in ids[sel]])
            zz = z[sel] - corr[sel]
            x0 = x_prev if (x_prev is not None and t[i] - t_prev <= 1.0) else A.mean(0)
            x = solve_fix(A, zz, x0)
            if x is not None:
                tm = t[sel].mean()
                fixes.append((tm, *x))
                x_prev, t_prev = x, tm
        i = j
    return np.array(fixes)


def truth_model(gt, rng, anchors, R, tvec, lever_trk, offsets, dt=0.0, scale=1.0):
    """Tag position in G from the truth: s R (p_trk + R_trk l) + t, at range time + dt."""
    t = rng[:, 0] + dt
    p = interp_pos(gt, t) + interp_rot(gt, t).apply(lever_trk)
    return scale * (R @ p.T).T + tvec


def fit_range_model(gt, rng, anchors, R0, t0, fit_dt=True, fit_scale=True):
    """Joint robust fit of alignment, tracker->tag lever arm, per-anchor offsets, dt, scale."""
    ids = rng[:, 1].astype(int)
    A = np.array([anchors[a] for a in ids])
    uids = sorted(anchors)
    col = np.array([uids.index(a) for a in ids])
    inside = (rng[:, 0] > gt[0, 0] + 0.5) & (rng[:, 0] < gt[-1, 0] - 0.5)
    r_in = rng[inside]

    def unpack(x):
        R = Rotation.from_rotvec(x[0:3]).as_matrix() @ R0
        return R, t0 + x[3:6], x[6:9], x[9:9 + len(uids)], (x[-2] if fit_dt else 0.0), \
            (1.0 + x[-1] if fit_scale else 1.0)

    def resid(x):
        R, tv, lev, b, dt, s = unpack(x)
        p = truth_model(gt, r_in, anchors, R, tv, lev, None, dt, s)
        return np.linalg.norm(p - A[inside], axis=1) + b[col[inside]] - r_in[:, 2]

    x0 = np.zeros(9 + len(uids) + 2)
    sol = least_squares(resid, x0, loss="huber", f_scale=0.15, x_scale=0.1)
    R, tv, lev, b, dt, s = unpack(sol.x)
    return dict(R=R, t=tv, lever=lev, offsets={u: b[k] for k, u in enumerate(uids)}, dt=dt,
                scale=s, resid=sol.fun, ids=ids[inside])


def spline_smoother(rng, anchors, offsets, knot_dt, t0, t1, x_init, lam=1e-3):
    """Cubic B-spline position through all ranges (offsets removed): the batch optimum."""
    sel = (rng[:, 0] >= t0) & (rng[:, 0] <= t1)
    r = rng[sel]
    ids = r[:, 1].astype(int)
    A = np.array([anchors[a] for a in ids])
    z = r[:, 2] - np.array([offsets.get(i, 0.0) for i in ids])
    n = int(np.ceil((t1 - t0) / knot_dt)) + 3
    u = (r[:, 0] - t0) / knot_dt
    k = np.clip(np.floor(u).astype(int), 0, n - 4)
    f = u - k
    B = np.stack([(1 - f) ** 3, 3 * f ** 3 - 6 * f ** 2 + 4, -3 * f ** 3 + 3 * f ** 2 + 3 * f + 1,
                  f ** 3], 1) / 6.0
    from scipy.sparse import lil_matrix
    # control points start at the initial guess (interpolated fixes)
    tc = t0 + (np.arange(n) - 1) * knot_dt
    C = np.stack([np.interp(tc, x_init[:, 0], x_init[:, 1 + d]) for d in range(3)], 1)

    def positions(Cf):
        return sum(B[:, m:m + 1] * Cf[k + m] for m in range(4))

    def resid(x):
        Cf = x.reshape(n, 3)
        p = positions(Cf)
        rr = np.linalg.norm(p - A, axis=1) - z
        reg = np.sqrt(lam) * (Cf[2:] - 2 * Cf[1:-1] + Cf[:-2]).ravel() / knot_dt ** 2 * knot_dt ** 2
        return np.concatenate([rr, reg])

    sp = lil_matrix((len(z) + 3 * (n - 2), 3 * n), dtype=int)
    for i in range(len(z)):
        for m in range(4):
            sp[i, 3 * (k[i] + m):3 * (k[i] + m) + 3] = 1
    for i in range(n - 2):
        for d in range(3):
            row = len(z) + 3 * i + d
            for m in range(3):
                sp[row, 3 * (i + m) + d] = 1
    sol = least_squares(resid, C.ravel(), jac_sparsity=sp, loss="huber", f_scale=0.15)
    Cf = sol.x.reshape(n, 3)
    ts = np.arange(t0, t1, 0.05)
    uu = (ts - t0) / knot_dt
    kk = np.clip(np.floor(uu).astype(int), 0, n - 4)
    ff = uu - kk
    BB = np.stack([(1 - ff) ** 3, 3 * ff ** 3 - 6 * ff ** 2 + 4,
                   -3 * ff ** 3 + 3 * ff ** 2 + 3 * ff + 1, ff ** 3], 1) / 6.0
    P = sum(BB[:, m:m + 1] * Cf[kk + m] for m in range(4))
    return np.column_stack([ts, P])


def gyro_vs_tracker(gt, imu, t_first):
    """Rotation tracker->IMU (wi ≈ R wt) and time offset of the truth from angular rates.

    The gyro bias is the mean rate of the first 1-6 s (the rig lies still), both rates are
    averaged over about 0.1 s (the tracker's rate differences over 5 poses)."""
    from scipy.ndimage import uniform_filter1d
    b_g = imu[(imu[:, 0] > t_first + 1) & (imu[:, 0] < t_first + 6), 4:7].mean(0)
    tg, rot, k = gt[:, 0], Rotation.from_quat(gt[:, 4:8]), 5
    w_trk = (rot[:-k].inv() * rot[k:]).as_rotvec() / (tg[k:] - tg[:-k])[:, None]
    tw = 0.5 * (tg[:-k] + tg[k:])
    wi_all = uniform_filter1d(imu[:, 4:7] - b_g, 8, axis=0)
    best = None
    for dt in np.arange(-0.2, 0.2001, 0.005):
        ti = imu[:, 0] + dt
        m = (ti > tw[0]) & (ti < tw[-1])
        wt = np.stack([np.interp(ti[m], tw, w_trk[:, d]) for d in range(3)], 1)
        wi = wi_all[m]
        U, _, Vt = np.linalg.svd(wi.T @ wt)
        R = U @ np.diag([1, 1, np.sign(np.linalg.det(U @ Vt))]) @ Vt
        rms = np.sqrt(((wi - (R @ wt.T).T) ** 2).sum(1).mean())
        if best is None or rms < best[0]:
            best = (rms, dt, R, np.sqrt((wi ** 2).sum(1).mean()))
    return best


def gravity_in_truth_frame(gt, imu, R_ti, dt):
    """Gravity in the truth frame: mean of (truth acceleration − specific force rotated into it),
    and the RMS of what is left (0.5 s averages; a wrong R_ti or gravity leaves metres/s²)."""
    from scipy.ndimage import uniform_filter1d
    from scipy.signal import savgol_filter
    tu = np.arange(gt[0, 0], gt[-1, 0], 0.02)
    acc = savgol_filter(interp_pos(gt, tu), 25, 3, deriv=2, delta=0.02, axis=0)
    f = np.stack([np.interp(tu, imu[:, 0] + dt, uniform_filter1d(imu[:, 1 + d], 40)) for d in range(3)], 1)
    m = (tu > imu[0, 0] + 1) & (tu < imu[-1, 0] - 1)
    f_v = interp_rot(gt, tu[m]).apply((R_ti.T @ f[m].T).T)
    g_v = (acc[m] - f_v).mean(0)
    left = f_v - (acc[m] - g_v)
    return g_v, np.sqrt((left ** 2).sum(1).mean())


def main():
    folder = sys.argv[1] if len(sys.argv) > 1 else "out/isas"
    anchors, p_TinI, rng, gt, imu = load(folder)
    gt_pos = lambda t: interp_pos(gt, t)
    inside = lambda f: f[(f[:, 0] > gt[0, 0]) & (f[:, 0] < gt[-1, 0])]

    def report(name, fixes, tmin=None):
        f = inside(fixes)
        if tmin is not None:
            f = f[f[:, 0] >= tmin]
        a, z, _ = ate(f[:, 1:4], gt_pos(f[:, 0]))
        print(f"  {name:58s} ATE {a:.3f} m  z {z:.3f} m  ({len(f)} fixes)")
        return a

    print("== multilateration of the raw ranges (tag fix scored as the tracker, as meshnav eval)")
    fx = multilaterate(rng, anchors, {}, 0.03)
    report("per message (0.03 s), offsets 0", fx)
    fx2 = multilaterate(rng, anchors, {}, 0.2)
    report("window 0.2 s, offsets 0", fx2)
    _, _, (R0, t0, _) = ate(inside(fx)[:, 1:4], gt_pos(inside(fx)[:, 0]))
    # R0,t0 map fix (G) -> vive. Invert for vive -> G.
    Rv, tv = R0.T, -R0.T @ t0

    print("== range model fitted to the truth (robust; vive->G alignment, tracker->tag lever,")
    print("   per-anchor offsets; optionally the Vive scale)")
    for fit_dt, fit_s in [(False, False), (False, True)]:
        m = fit_range_model(gt, rng, anchors, Rv, tv, fit_dt, fit_s)
        r = m["resid"]
        mad = 1.4826 * np.median(np.abs(r - np.median(r)))
        print(f"  scale {'fit' if fit_s else ' 1 '}: scale {m['scale']:.4f}, lever tracker->tag "
              f"{np.round(m['lever'], 3)} m (|l| {np.linalg.norm(m['lever']):.3f}), residual "
              f"RMS {np.sqrt((r**2).mean()):.3f} m, robust σ {mad:.3f} m")
        print("    offsets (range - true) " + ", ".join(f"{a}: {o:+.3f}" for a, o in m["offsets"].items()))
    model = fit_range_model(gt, rng, anchors, Rv, tv, False, False)
    off = model["offsets"]
    # time offset of the truth against the ranges: Huber cost of the fitted model on a grid
    # (the fit's finite differences do not move dt off 0 through the interpolation)
    ids = rng[:, 1].astype(int)
    ins = (rng[:, 0] > gt[0, 0] + 0.5) & (rng[:, 0] < gt[-1, 0] - 0.5)
    A_in = np.array([anchors[a] for a in ids[ins]])
    b_in = np.array([off[a] for a in ids[ins]])
    costs = []
    for dt in np.arange(-0.2, 0.2001, 0.025):
        q = truth_model(gt, rng[ins], anchors, model["R"], model["t"], model["lever"], None, dt)
        r = rng[ins, 2] - b_in - np.linalg.norm(q - A_in, axis=1)
        costs.append((np.where(np.abs(r) < 0.15, 0.5 * r ** 2, 0.15 * (np.abs(r) - 0.075)).sum(), dt))
    print("  truth time offset against the ranges (Huber cost on a 25 ms grid): best "
          f"{min(costs)[1]*1e3:+.0f} ms, cost {min(costs)[0]:.2f} vs {costs[len(costs)//2][0]:.2f} at 0, "
          f"{costs[0][0]:.2f} at -0.2 s, {costs[-1][0]:.2f} at +0.2 s")
    for a in sorted(anchors):
        r = model["resid"][model["ids"] == a]
        print(f"    anchor {a:5d}: residual median {np.median(r):+.3f} robust σ "
              f"{1.4826*np.median(np.abs(r-np.median(r))):.3f} beyond 0.3 m {100*np.mean(np.abs(r)>0.3):.1f} %")

    print("== oracle: offsets from the truth removed")
    fo = multilaterate(rng, anchors, off, 0.03)
    report("per message, oracle offsets", fo)
    for w in (0.1, 0.2, 0.3, 0.5):
        report(f"window {w} s, oracle offsets", multilaterate(rng, anchors, off, w))
    # scored against the tag's own truth position (tracker + fitted lever), not the tracker
    tag_truth = lambda t: truth_model(gt, np.column_stack([t, t, t]), anchors, model["R"],
                                      model["t"], model["lever"], None, model["dt"])
    for name, f in [("per message, oracle offsets, vs tag truth", fo),
                    ("window 0.2 s, oracle offsets, vs tag truth", multilaterate(rng, anchors, off, 0.2)),
                    ("per message, offsets 0, vs tag truth", fx)]:
        f = inside(f)
        e = f[:, 1:4] - tag_truth(f[:, 0])
        print(f"  {name:58s} RMSE {np.sqrt((e**2).sum(1).mean()):.3f} m  z "
              f"{np.sqrt((e[:,2]**2).mean()):.3f} m (model frame, no re-alignment)")

    print("== oracle smoother: cubic B-spline through all ranges, oracle offsets")
    t_a, t_b = max(rng[0, 0], gt[0, 0]) + 0.1, min(rng[-1, 0], gt[-1, 0]) - 0.1
    for kd in (0.1, 0.2, 0.4):
        for o_name, o in [("oracle offsets", off), ("offsets 0", {})]:
            s = spline_smoother(rng, anchors, o, kd, t_a, t_b, fx2)
            report(f"spline knots {kd} s, {o_name}", s)
            if kd == 0.2 and o is off:
                e = s[:, 1:4] - tag_truth(s[:, 0])
                print(f"  {'   same vs tag truth (model frame)':58s} RMSE "
                      f"{np.sqrt((e**2).sum(1).mean()):.3f} m  z {np.sqrt((e[:,2]**2).mean()):.3f} m")
    s = spline_smoother(rng, anchors, off, 0.2, t_a, t_b, fx2)
    report("spline 0.2 s, oracle offsets, from t = 690.6 s (meshnav span)", s, gt[0, 0] * 0 + 1664959690.6)

    print("== truth: tracker vs IMU from angular rates, gravity")
    rms, dt, R_ti, wrms = gyro_vs_tracker(gt, imu, rng[0, 0])
    print(f"  truth time offset {dt*1e3:+.0f} ms (IMU t + dt = tracker t), rotation tracker->IMU "
          f"{np.degrees(Rotation.from_matrix(R_ti).magnitude()):.1f}° {np.round(R_ti, 2).tolist()}, rate "
          f"residual {rms:.3f} rad/s of {wrms:.3f} rad/s RMS")
    print(f"  IMU->tag in the tracker frame {np.round(R_ti.T @ p_TinI, 3)} m; tracker->tag fitted "
          f"{np.round(model['lever'], 3)} m: IMU {np.round(model['lever'] - R_ti.T @ p_TinI, 3)} m from the tracker")
    g_v, left = gravity_in_truth_frame(gt, imu, R_ti, dt)
    _, _, (R0, t0, _) = ate(inside(fx)[:, 1:4], gt_pos(inside(fx)[:, 0]))
    up = -g_v / np.linalg.norm(g_v)
    print(f"  gravity in the truth frame {np.round(g_v, 2)} m/s² (|g| {np.linalg.norm(g_v):.2f}), "
          f"acceleration left {left:.2f} m/s² RMS")
    print(f"  z axis of the anchor frame G (SE(3) fit of the fixes) is {np.degrees(np.arccos(R0[:, 2] @ up)):.0f}° "
          f"from up: {'G is z-DOWN' if R0[:, 2] @ up < 0 else 'G is z-up'}")
    f = inside(fo)
    a2 = ate(f[:, 1:4], gt_pos(f[:, 0]), scale=True)
    print(f"  per-message oracle fixes with scale (sim3): ATE {a2[0]:.3f} m, scale {a2[2][2]:.4f}")
    # vertical dilution of precision along the walk
    vd = []
    for x in inside(fx)[:, 1:4]:
        H = np.array([(x - a) / np.linalg.norm(x - a) for a in anchors.values()])
        vd.append(np.sqrt(np.linalg.inv(H.T @ H).diagonal()))
    vd = np.array(vd)
    print(f"  dilution of precision along the walk (5 anchors), median x {np.median(vd[:,0]):.2f} "
          f"y {np.median(vd[:,1]):.2f} z {np.median(vd[:,2]):.2f}")

if __name__ == "__main__":
    main()
