#!/usr/bin/env python3
"""Plots of one evaluated meshnav run (called by meshnav_eval; usable alone).

Writes into --out:
  trajectory_xy.png      top view: true (blue) and estimated (purple) trajectory (with --smoothed the
                         smoothed estimate of the same run in green), anchors as in the
                         paper's figures: true = black stars, initial estimate = blue triangles,
                         final estimate = green diamonds. With --alignment (the truth lives in
                         another frame) the truth is drawn mapped into the estimate's frame G,
                         p_G = R^T (p_T - t), where the anchors are
  trajectory_3d.png      the same in 3D
  position_error.png     position error x/y/z (truth - estimate) [m] with +-3 sigma bounds
  orientation_error.png  orientation error x/y/z (local, Log(R_est^T R_true)) [deg] with +-3 sigma
  nees.png               NEES of position and orientation with the 95 % chi2(3) interval
  position_error_smoothed.png  with --smoothed-errors: the smoothed estimate's position error
  anchor_errors.png      per estimated anchor with a true position: error norm [m] and NEES (3 dof,
                         log scale, 95 % interval and 99.7 % threshold) over time, from anchors.csv
  range_residuals.png    per anchor: tag-anchor range residual z - |p_IinG + R_ItoG p_TinI - p_AinG| [m]
                         over time, with the estimate interpolated at the range's time (position
                         linear, orientation of the nearest estimate), anchors from the run's last
                         anchors.csv row or setup.yaml; raw ranges, no bias correction. Median and
                         robust sigma (1.4826 MAD) per anchor in the titles

Inputs: errors.csv and anchors_eval.csv written by meshnav_eval, groundtruth.csv (TUM, optional),
estimate.csv and the run's anchors.csv (optional), ranges.csv and setup.yaml of the dataset
(optional, for the residuals). Time axes start at the first sample when the stamps are absolute
(recordings in Unix seconds). Headless: uses the Agg backend.
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


def time_axis(t, t0=None):
    """(t - t0, axis label): times from the first sample when the stamps are absolute (a recording
    stamped in Unix seconds, 1.66e9 s), else unchanged."""
    if t0 is None:
        t0 = float(t[0]) if len(t) else 0.0
    if abs(t0) < 1e5:
        return t, "t [s]"
    return t - t0, "t − %.3f [s]" % t0


def read_alignment(text):
    """(R_EtoT, t_EinT) from "r00,r01,...,r22,tx,ty,tz" (meshnav_eval --align: p_T = R p_E + t)."""
    v = [float(x) for x in text.split(",")]
    if len(v) != 12 or not np.all(np.isfinite(v)):
        raise ValueError("--alignment needs 12 finite numbers (R row by row, then t), got %r" % text)
    return np.array(v[:9]).reshape(3, 3), np.array(v[9:])


def truth_in_estimate_frame(gt, alignment):
    """The truth's positions mapped into the estimate's frame: p_E = R^T (p_T - t)."""
    if gt is None or alignment is None:
        return gt
    R, t = alignment
    p_T = np.stack([gt["tx"], gt["ty"], gt["tz"]], 1)
    p_E = (p_T - t) @ R  # row-wise R^T (p_T - t)
    out = dict(gt)
    out["tx"], out["ty"], out["tz"] = p_E[:, 0], p_E[:, 1], p_E[:, 2]
    return out


def read_tag_anchor_ranges(path):
    """Tag-anchor rows of a ranges.csv as arrays t, z, tag id, anchor id (either device may be
    the initiator; anchor-anchor and tag-tag rows and unreadable rows are left out)."""
    t, z, tag, anchor = [], [], [], []
    if not path or not os.path.exists(path):
        return None
    types = {"T": "T", "84": "T", "A": "A", "65": "A"}
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            try:
                t1 = types.get(r["type_ID1"].strip().upper())
                t2 = types.get(r["type_ID2"].strip().upper())
                row = (float(r["t"]), float(r["range_raw"]), int(r["UWB_ID1"]), int(r["UWB_ID2"]))
            except (KeyError, ValueError, AttributeError):
                continue
            if {t1, t2} != {"T", "A"}:
                continue
            t.append(row[0])
            z.append(row[1])
            tag.append(row[2] if t1 == "T" else row[3])
            anchor.append(row[3] if t1 == "T" else row[2])
    if not t:
        return None
    return {"t": np.array(t), "z": np.array(z), "tag": np.array(tag), "anchor": np.array(anchor)}


def read_setup_geometry(path):
    """({tag id: p_TinI}, {anchor id: p_AinG}) from setup.yaml; empty when PyYAML is missing."""
    if not path or not os.path.exists(path):
        return {}, {}
    try:
        import yaml
    except ImportError:
        print("plot_run.py: PyYAML missing (python3-yaml): no range residuals", file=sys.stderr)
        return {}, {}
    with open(path) as f:
        setup = yaml.safe_load(f) or {}
    tags = {int(k): np.array(v, float) for k, v in (setup.get("rel_tag_positions") or {}).items()}
    anchors = {int(k): np.array(v, float) for k, v in (setup.get("abs_anchor_positions") or {}).items()}
    return tags, anchors


def rotate(q_xyzw, v):
    """Rows of v rotated by the unit quaternions q (x, y, z, w), row by row: R(q) v."""
    u, w = q_xyzw[:, :3], q_xyzw[:, 3:4]
    c = np.cross(u, v)
    return v + 2.0 * w * c + 2.0 * np.cross(u, c)


def range_residuals(ranges, est, tags, anchors):
    """{anchor id: (t, residual)} with residual = z - |p_IinG + R_ItoG p_TinI - p_AinG| for the
    tag-anchor ranges within the estimate's time span whose tag and anchor positions are known.
    Position interpolated linearly, orientation of the nearest estimate in time."""
    out = {}
    if ranges is None or est is None or len(est["t"]) < 2:
        return out
    te = est["t"]
    keep = (ranges["t"] >= te[0]) & (ranges["t"] <= te[-1])
    keep &= np.array([g in tags for g in ranges["tag"]], bool) & np.array([a in anchors for a in ranges["anchor"]], bool)
    if not np.any(keep):
        return out
    t, z = ranges["t"][keep], ranges["z"][keep]
    tag, anchor = ranges["tag"][keep], ranges["anchor"][keep]
    p_IinG = np.stack([np.interp(t, te, est[k]) for k in ("tx", "ty", "tz")], 1)
    i = np.clip(np.searchsorted(te, t), 1, len(te) - 1)
    i -= (t - te[i - 1]) < (te[i] - t)  # the nearer neighbour
    q = np.stack([est[k][i] for k in ("qx", "qy", "qz", "qw")], 1)
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    p_TinI = np.array([tags[g] for g in tag])
    p_AinG = np.array([anchors[a] for a in anchor])
    d = np.linalg.norm(p_IinG + rotate(q, p_TinI) - p_AinG, axis=1)
    r = z - d
    for a in sorted(set(anchor.tolist())):
        m = anchor == a
        out[int(a)] = (t[m], r[m])
    return out


def robust_stats(r):
    """(median, 1.4826 MAD) of the residuals."""
    med = float(np.median(r))
    return med, 1.4826 * float(np.median(np.abs(r - med)))


def plot_range_residuals(out, residuals):
    ids = sorted(residuals)
    t0 = min(float(v[0][0]) for v in residuals.values())
    fig, axes = plt.subplots(len(ids), 1, figsize=(9, 1.6 + 1.5 * len(ids)), sharex=True, squeeze=False)
    label = "t [s]"
    for ax, aid in zip(axes[:, 0], ids):
        t, r = residuals[aid]
        tr, label = time_axis(t, t0)
        med, sigma = robust_stats(r)
        lim = min(max(0.3, 1.5 * float(np.percentile(np.abs(r), 99))), 3.0)
        outside = int(np.sum(np.abs(r) > lim))
        ax.plot(tr, np.clip(r, -lim, lim), ".", ms=2, color="tab:blue")
        ax.axhline(0.0, color="k", lw=0.6)
        ax.axhline(med, color="tab:red", lw=1.0)
        ax.set_ylim(-lim * 1.05, lim * 1.05)
        ax.set_ylabel("%d [m]" % aid)
        ax.grid(True, alpha=0.3)
        ax.set_title("anchor %d: %d ranges, median %+.3f m, robust σ %.3f m%s"
                     % (aid, len(r), med, sigma, ", %d beyond ±%.2f m (drawn at the edge)" % (outside, lim)
                        if outside else ""), fontsize=8)
    axes[0, 0].figure.suptitle("Range residuals z − |p_T − p_A| along the estimate (raw ranges, red: median)",
                               fontsize=10)
    axes[-1, 0].set_xlabel(label)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "range_residuals.png"), dpi=110)
    plt.close(fig)


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


def plot_trajectories(out, gt, est, anchors, aligned=None, smoothed=None):
    """`aligned`: the alignment mode when `gt` was mapped into the estimate's frame (legend);
    `smoothed`: estimate_smoothed.csv of the same run (meshnav smooth), drawn beside the filter's."""
    true_label = "true" if not aligned else "true (%s-aligned)" % aligned
    fig, ax = plt.subplots(figsize=(7, 8))
    if gt is not None:
        s = thin(len(gt["t"]))
        ax.plot(gt["tx"][s], gt["ty"][s], color="tab:blue", lw=1.2, label=true_label)
    if est is not None:
        s = thin(len(est["t"]))
        ax.plot(est["tx"][s], est["ty"][s], color="tab:purple", lw=1.0, alpha=0.85, label="estimate")
    if smoothed is not None:
        s = thin(len(smoothed["t"]))
        ax.plot(smoothed["tx"][s], smoothed["ty"][s], color="tab:green", lw=1.0, alpha=0.85, label="smoothed")
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
        ax.plot(gt["tx"][s], gt["ty"][s], gt["tz"][s], color="tab:blue", lw=1.0, label=true_label)
    if est is not None:
        s = thin(len(est["t"]))
        ax.plot(est["tx"][s], est["ty"][s], est["tz"][s], color="tab:purple", lw=0.9, alpha=0.85,
                label="estimate")
    if smoothed is not None:
        s = thin(len(smoothed["t"]))
        ax.plot(smoothed["tx"][s], smoothed["ty"][s], smoothed["tz"][s], color="tab:green", lw=0.9, alpha=0.85,
                label="smoothed")
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
    t, t_label = time_axis(err["t"])
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
    axes[-1].set_xlabel(t_label)
    axes[0].set_title(title)
    fig.tight_layout()
    fig.savefig(os.path.join(out, fname), dpi=130)
    plt.close(fig)


def plot_nees(out, err):
    t, t_label = time_axis(err["t"])
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
    axes[-1].set_xlabel(t_label)
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
    ap.add_argument("--alignment", help="r00,r01,...,r22,tx,ty,tz: the fitted p_T = R p_E + t of meshnav_eval "
                    "--align; the truth is drawn mapped into the estimate's frame")
    ap.add_argument("--alignment-mode", default="se3", help="name of the alignment for the legend")
    ap.add_argument("--ranges", help="ranges.csv of the dataset (range residuals)")
    ap.add_argument("--setup", help="setup.yaml of the dataset (tag lever arms, known anchors)")
    ap.add_argument("--smoothed", help="estimate_smoothed.csv of the run (meshnav smooth): drawn beside the estimate")
    ap.add_argument("--smoothed-errors", help="errors_smoothed.csv from meshnav_eval: position_error_smoothed.png")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    gt = read_csv(args.groundtruth)
    est = read_csv(args.estimate)
    anchors = read_csv(args.anchors)
    err = read_csv(args.errors)
    smoothed = read_csv(args.smoothed)
    written = []
    alignment = read_alignment(args.alignment) if args.alignment else None
    if gt is not None or est is not None:
        plot_trajectories(args.out, truth_in_estimate_frame(gt, alignment), est, anchors,
                          args.alignment_mode if alignment is not None else None, smoothed)
        written += ["trajectory_xy.png", "trajectory_3d.png"]
    if err is not None:
        plot_errors(args.out, err, "ep", "sigma3_p", "m", "position_error.png",
                    "Position error (truth − estimate) with ±3σ")
        plot_errors(args.out, err, "eth", "sigma3_th", "deg", "orientation_error.png",
                    "Orientation error Log(R_est^T R_true) (body frame) with ±3σ")
        plot_nees(args.out, err)
        written += ["position_error.png", "orientation_error.png", "nees.png"]
    err_smoothed = read_csv(args.smoothed_errors)
    if err_smoothed is not None:
        plot_errors(args.out, err_smoothed, "ep", "sigma3_p", "m", "position_error_smoothed.png",
                    "Position error of the smoothed estimate (truth − estimate) with ±3σ")
        written.append("position_error_smoothed.png")
    track = read_csv(args.anchor_track)
    tracks = anchor_tracks(track, anchors)
    if tracks:
        plot_anchor_errors(args.out, tracks)
        written.append("anchor_errors.png")
    tags, anchor_pos = read_setup_geometry(args.setup)
    if track is not None:  # the run's own anchors in G (calibrated ones too): the last row of each
        for k in range(len(track["t"])):
            anchor_pos[int(track["id"][k])] = np.array([track["x"][k], track["y"][k], track["z"][k]])
    residuals = range_residuals(read_tag_anchor_ranges(args.ranges), est, tags, anchor_pos)
    if residuals:
        plot_range_residuals(args.out, residuals)
        written.append("range_residuals.png")
    if not written:
        print("plot_run.py: nothing to plot (no trajectory, no errors)", file=sys.stderr)
        return 1
    print("plot_run.py: wrote " + ", ".join(written) + " to " + args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
