#!/usr/bin/env python3
"""Plots of one evaluated meshnav run (called by meshnav_eval; usable alone).

Writes into --out:
  trajectory_xy.png      top view: true (blue) and estimated (purple) trajectory, anchors as in the
                         paper's figures: true = black stars, initial estimate = blue triangles,
                         final estimate = green diamonds
  trajectory_3d.png      the same in 3D
  position_error.png     position error x/y/z (truth - estimate) [m] with +-3 sigma bounds
  orientation_error.png  orientation error x/y/z (local, Log(R_est^T R_true)) [deg] with +-3 sigma
  nees.png               NEES of position and orientation with the 95 % chi2(3) interval
  anchor_errors.png      per estimated anchor with a true position: error norm [m] and NEES (3 dof,
                         log scale, 95 % interval and 99.7 % threshold) over time, from anchors.csv

Inputs: errors.csv and anchors_eval.csv written by meshnav_eval, groundtruth.csv (TUM, optional),
estimate.csv and the run's anchors.csv (optional). Headless: uses the Agg backend.
"""
import argparse
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

CHI2_3_95 = (0.2158, 9.3484)  # two-sided 95 % interval of chi2 with 3 dof
CHI2_3_997 = 13.93  # 99.7 % quantile of chi2 with 3 dof
MAX_POINTS = 20000


def read_csv(path):
    """Dict of column name -> float array; tolerates a leading '#' and spaces in the header."""
    if not path or not os.path.exists(path):
        return None
    with open(path, newline="") as f:
        lines = [ln for ln in f if ln.strip()]
    if not lines:
        return None
    header_line = lines[0].lstrip("#").strip()
    sep = "," if "," in header_line else None
    header = [h.strip() for h in header_line.split(sep)]
    rows = []
    for ln in lines[1:]:
        if ln.startswith("#"):
            continue
        parts = [p.strip() for p in ln.strip().split(sep)]
        if len(parts) != len(header):
            continue
        try:
            rows.append([float(p) for p in parts])
        except ValueError:
            continue
    if not rows:
        return None
    arr = np.array(rows)
    return {h: arr[:, i] for i, h in enumerate(header)}


def thin(n):
    step = max(1, n // MAX_POINTS)
    return slice(None, None, step)


def plot_anchors(ax, anchors, three_d=False):
    if anchors is None:
        return
    has_truth = anchors["has_truth"] > 0.5
    calibrated = anchors["known"] < 0.5

    def sc(x, y, z, **kw):
        if three_d:
            ax.scatter(x, y, z, depthshade=False, **kw)
        else:
            ax.scatter(x, y, **kw)

    t = has_truth
    sc(anchors["true_x"][t], anchors["true_y"][t], anchors["true_z"][t], marker="*", s=140, c="black",
       label="anchor true", zorder=5)
    c = calibrated
    if np.any(c):
        sc(anchors["init_x"][c], anchors["init_y"][c], anchors["init_z"][c], marker="^", s=70, c="tab:blue",
           label="anchor initial", zorder=6)
        sc(anchors["final_x"][c], anchors["final_y"][c], anchors["final_z"][c], marker="D", s=50, c="tab:green",
           label="anchor final", zorder=7)
    for i, aid in enumerate(anchors["id"]):
        x, y, z = (anchors["true_x"][i], anchors["true_y"][i], anchors["true_z"][i]) if has_truth[i] else (
            anchors["final_x"][i], anchors["final_y"][i], anchors["final_z"][i])
        if three_d:
            ax.text(x, y, z, " %d" % int(aid), fontsize=8)
        else:
            ax.annotate("%d" % int(aid), (x, y), textcoords="offset points", xytext=(6, 6), fontsize=8)


def plot_trajectories(out, gt, est, anchors):
    fig, ax = plt.subplots(figsize=(7, 8))
    if gt is not None:
        s = thin(len(gt["t"]))
        ax.plot(gt["tx"][s], gt["ty"][s], color="tab:blue", lw=1.2, label="true")
    if est is not None:
        s = thin(len(est["t"]))
        ax.plot(est["tx"][s], est["ty"][s], color="tab:purple", lw=1.0, alpha=0.85, label="estimate")
    plot_anchors(ax, anchors)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    ax.set_title("Trajectory and anchors (top view)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "trajectory_xy.png"), dpi=130)
    plt.close(fig)

    fig = plt.figure(figsize=(8, 7))
    ax = fig.add_subplot(111, projection="3d")
    if gt is not None:
        s = thin(len(gt["t"]))
        ax.plot(gt["tx"][s], gt["ty"][s], gt["tz"][s], color="tab:blue", lw=1.0, label="true")
    if est is not None:
        s = thin(len(est["t"]))
        ax.plot(est["tx"][s], est["ty"][s], est["tz"][s], color="tab:purple", lw=0.9, alpha=0.85,
                label="estimate")
    plot_anchors(ax, anchors, three_d=True)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.legend(loc="upper left", fontsize=8)
    ax.set_title("Trajectory and anchors")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "trajectory_3d.png"), dpi=130)
    plt.close(fig)


def plot_errors(out, err, prefix, sigma_prefix, unit, fname, title):
    t = err["t"]
    s = thin(len(t))
    fig, axes = plt.subplots(3, 1, figsize=(9, 7), sharex=True)
    selected = err["selected"] > 0.5
    for i, (axis, color) in enumerate(zip("xyz", ("tab:blue", "tab:red", "tab:orange"))):
        ax = axes[i]
        e = err["%s_%s_%s" % (prefix, axis, unit)]
        sg = err["%s_%s_%s" % (sigma_prefix, axis, unit)]
        ax.fill_between(t[s], -sg[s], sg[s], color="0.85", label="±3σ")
        ax.plot(t[s], e[s], color=color, lw=0.9, label="error %s" % axis)
        if not np.all(selected):
            ax.plot(t[s][~selected[s]], e[s][~selected[s]], ".", color="0.5", ms=1, label="not evaluated")
        ax.set_ylabel("%s [%s]" % (axis, unit))
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper right", fontsize=7, ncol=3)
        if len(e):
            lim = max(np.percentile(np.abs(e), 99.5) * 1.5, 1e-3)
            lim = max(lim, min(np.percentile(sg, 50) * 1.2, 10 * lim))
            ax.set_ylim(-lim, lim)
    axes[-1].set_xlabel("t [s]")
    axes[0].set_title(title)
    fig.tight_layout()
    fig.savefig(os.path.join(out, fname), dpi=130)
    plt.close(fig)


def plot_nees(out, err):
    t = err["t"]
    s = thin(len(t))
    fig, axes = plt.subplots(2, 1, figsize=(9, 5.5), sharex=True)
    for ax, key, name in zip(axes, ("nees_p", "nees_theta"), ("position", "orientation")):
        v = err[key]
        ok = np.isfinite(v)
        if np.any(ok):
            ax.semilogy(t[s][ok[s]], np.maximum(v[s][ok[s]], 1e-4), lw=0.7, color="tab:blue", label="NEES " + name)
            ax.axhline(np.mean(v[ok]), color="tab:red", lw=1.0, label="ANEES %.2f" % np.mean(v[ok]))
        for b in CHI2_3_95:
            ax.axhline(b, color="k", ls="--", lw=0.8)
        ax.axhline(3.0, color="0.4", ls=":", lw=0.8)
        ax.set_ylabel("NEES [-]")
        ax.grid(True, alpha=0.3, which="both")
        ax.legend(loc="upper right", fontsize=7)
    axes[0].set_title("NEES (dashed: 95 % interval of χ²(3), dotted: 3)")
    axes[-1].set_xlabel("t [s]")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "nees.png"), dpi=130)
    plt.close(fig)


def anchor_tracks(track, anchors):
    """{id: (t, error norm, NEES)} for every anchor that is estimated (not known) and has a true
    position; rows without a positive-definite covariance get NEES nan."""
    out = {}
    if track is None or anchors is None:
        return out
    for i, aid in enumerate(anchors["id"]):
        if anchors["known"][i] > 0.5 or anchors["has_truth"][i] < 0.5:
            continue
        rows = track["id"] == aid
        if not np.any(rows):
            continue
        truth = np.array([anchors["true_x"][i], anchors["true_y"][i], anchors["true_z"][i]])
        e = np.stack([track["x"][rows], track["y"][rows], track["z"][rows]], 1) - truth
        nees = np.full(len(e), np.nan)
        for k in range(len(e)):
            P = np.array([[track["pxx"][rows][k], track["pxy"][rows][k], track["pxz"][rows][k]],
                          [track["pxy"][rows][k], track["pyy"][rows][k], track["pyz"][rows][k]],
                          [track["pxz"][rows][k], track["pyz"][rows][k], track["pzz"][rows][k]]])
            try:
                np.linalg.cholesky(P)
                nees[k] = e[k] @ np.linalg.solve(P, e[k])
            except np.linalg.LinAlgError:
                pass
        out[int(aid)] = (track["t"][rows], np.linalg.norm(e, axis=1), nees)
    return out


def plot_anchor_errors(out, tracks):
    fig, (ax_e, ax_n) = plt.subplots(2, 1, figsize=(10, 7), sharex=True)
    t0 = min(v[0][0] for v in tracks.values())
    for aid, (t, err, nees) in sorted(tracks.items()):
        ax_e.plot(t - t0, err, lw=1.2, label=str(aid))
        ax_n.semilogy(t - t0, np.maximum(nees, 1e-3), lw=1.2, label=str(aid))
    ax_e.set_ylabel("error [m]")
    ax_e.set_title("Estimated anchors: position error and NEES over time")
    ax_e.grid(alpha=0.3)
    ax_e.legend(fontsize=8, ncol=5)
    ax_n.axhspan(*CHI2_3_95, color="0.85", label="95 % χ²(3)")
    ax_n.axhline(CHI2_3_997, color="tab:red", ls="--", lw=1, label="99.7 % (13.93)")
    ax_n.set_ylabel("NEES (3 dof)")
    ax_n.set_xlabel("t − %.3f [s]" % t0)
    ax_n.grid(alpha=0.3, which="both")
    ax_n.legend(fontsize=8, ncol=6)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "anchor_errors.png"), dpi=110)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", required=True, help="output folder for the PNGs")
    ap.add_argument("--errors", help="errors.csv from meshnav_eval")
    ap.add_argument("--anchors", help="anchors_eval.csv from meshnav_eval")
    ap.add_argument("--groundtruth", help="groundtruth.csv (TUM)")
    ap.add_argument("--estimate", help="estimate.csv")
    ap.add_argument("--anchor-track", help="anchors.csv of the run (anchor estimates over time)")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    gt = read_csv(args.groundtruth)
    est = read_csv(args.estimate)
    anchors = read_csv(args.anchors)
    err = read_csv(args.errors)
    written = []
    if gt is not None or est is not None:
        plot_trajectories(args.out, gt, est, anchors)
        written += ["trajectory_xy.png", "trajectory_3d.png"]
    if err is not None:
        plot_errors(args.out, err, "ep", "sigma3_p", "m", "position_error.png",
                    "Position error (truth − estimate) with ±3σ")
        plot_errors(args.out, err, "eth", "sigma3_th", "deg", "orientation_error.png",
                    "Orientation error Log(R_est^T R_true) (body frame) with ±3σ")
        plot_nees(args.out, err)
        written += ["position_error.png", "orientation_error.png", "nees.png"]
    tracks = anchor_tracks(read_csv(args.anchor_track), anchors)
    if tracks:
        plot_anchor_errors(args.out, tracks)
        written.append("anchor_errors.png")
    if not written:
        print("plot_run.py: nothing to plot (no trajectory, no errors)", file=sys.stderr)
        return 1
    print("plot_run.py: wrote " + ", ".join(written) + " to " + args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
