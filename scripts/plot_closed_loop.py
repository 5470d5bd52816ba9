#!/usr/bin/env python3
"""Plots of one closed-loop flight (`meshnav fly --out DIR`, docs/closed_loop.md).

Reads DIR/truth.csv (TUM), DIR/estimate.csv, DIR/planned.csv and DIR/truth.yaml (anchors) and writes
  DIR/paths_xy.png   top view: planned (grey dashed), flown = truth (blue), estimated (purple);
                     anchors: true = black stars, final estimates = green diamonds
  DIR/paths_3d.png   the same in 3D
  DIR/errors.png     estimation error |p_est - p_true| and tracking error |p_true - p_ref| [m] over
                     time, with the controller's mode (failsafe shaded red) and the calibrations
Headless (Agg backend).
"""
import argparse
import csv
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def read_rows(path):
    with open(path, newline="") as f:
        lines = [ln for ln in f if ln.strip()]
    header = [h.strip() for h in lines[0].lstrip("#").strip().split(",")]
    return header, [dict(zip(header, ln.strip().split(","))) for ln in lines[1:] if not ln.startswith("#")]


def column(rows, key):
    return np.array([float(r[key]) for r in rows])


def read_anchor_truth(path):
    """{id: (x, y, z)} from truth.yaml's anchor_positions (no yaml module needed for this key)."""
    try:
        import yaml
        with open(path) as f:
            doc = yaml.safe_load(f)
        return {int(k): tuple(v) for k, v in (doc.get("anchor_positions") or {}).items()}
    except Exception:  # noqa: BLE001 - plots without anchors rather than none
        return {}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dir", help="output folder of meshnav fly")
    a = ap.parse_args()
    d = a.dir
    _, truth = read_rows(os.path.join(d, "truth.csv"))
    _, est = read_rows(os.path.join(d, "estimate.csv"))
    _, plan = read_rows(os.path.join(d, "planned.csv"))
    tt = column(truth, "t")
    pt = np.stack([column(truth, k) for k in ("tx", "ty", "tz")], axis=1)
    te = column(est, "t")
    pe = np.stack([column(est, k) for k in ("tx", "ty", "tz")], axis=1)
    tp = column(plan, "t")
    pp = np.stack([column(plan, k) for k in ("x", "y", "z")], axis=1)
    flying = np.array([r["mode"] == "flying" and r["phase"] in ("takeoff", "waypoints", "return") for r in plan])
    failsafe = np.array([r["mode"] == "failsafe" for r in plan])
    airborne = column(plan, "airborne") > 0
    anchors = read_anchor_truth(os.path.join(d, "truth.yaml"))
    final = {}
    if os.path.exists(os.path.join(d, "anchors.csv")):
        _, arows = read_rows(os.path.join(d, "anchors.csv"))
        for r in arows:
            final[int(float(r["id"]))] = (float(r["x"]), float(r["y"]), float(r["z"]))

    fig, ax = plt.subplots(figsize=(6, 8))
    ax.plot(pp[flying, 0], pp[flying, 1], "--", color="grey", lw=1, label="planned")
    ax.plot(pt[:, 0], pt[:, 1], color="tab:blue", lw=1, label="flown (truth)")
    ax.plot(pe[:, 0], pe[:, 1], color="tab:purple", lw=0.8, alpha=0.8, label="estimated")
    for i, (aid, p) in enumerate(sorted(anchors.items())):
        ax.plot(p[0], p[1], "k*", ms=10, label="anchor (true)" if i == 0 else None)
        ax.annotate(str(aid), (p[0], p[1]), textcoords="offset points", xytext=(5, 5), fontsize=8)
    for i, (aid, p) in enumerate(sorted(final.items())):
        ax.plot(p[0], p[1], "gD", ms=5, mfc="none", label="anchor (final estimate)" if i == 0 else None)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_aspect("equal")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    ax.set_title("closed loop: planned, flown and estimated path")
    fig.tight_layout()
    fig.savefig(os.path.join(d, "paths_xy.png"), dpi=120)
    plt.close(fig)

    fig = plt.figure(figsize=(8, 7))
    ax = fig.add_subplot(111, projection="3d")
    ax.plot(pp[flying, 0], pp[flying, 1], pp[flying, 2], "--", color="grey", lw=1, label="planned")
    ax.plot(pt[:, 0], pt[:, 1], pt[:, 2], color="tab:blue", lw=1, label="flown (truth)")
    ax.plot(pe[:, 0], pe[:, 1], pe[:, 2], color="tab:purple", lw=0.8, label="estimated")
    for p in anchors.values():
        ax.scatter([p[0]], [p[1]], [p[2]], marker="*", color="k", s=60)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "paths_3d.png"), dpi=120)
    plt.close(fig)

    # Errors over time: the estimate against the truth at the same instants (both on the IMU grid).
    truth_at = {round(t, 6): i for i, t in enumerate(tt)}
    idx = [(j, truth_at.get(round(t, 6))) for j, t in enumerate(te)]
    idx = [(j, i) for j, i in idx if i is not None and airborne[min(i, len(airborne) - 1)]]
    fig, axs = plt.subplots(2, 1, figsize=(10, 6), sharex=True)
    if idx:
        je, it = zip(*idx)
        err = pe[list(je)] - pt[list(it)]
        for k, c in enumerate(("x", "y", "z")):
            axs[0].plot(te[list(je)], err[:, k], lw=0.7, label=c)
        axs[0].plot(te[list(je)], np.linalg.norm(err, axis=1), "k", lw=0.8, label="norm")
    axs[0].set_ylabel("estimation error [m]")
    axs[0].legend(fontsize=8, ncol=4)
    track = np.linalg.norm(pt - pp, axis=1)
    axs[1].plot(tp[flying], track[flying], ".", ms=1, color="tab:blue", label="|truth - planned|")
    axs[1].set_ylabel("tracking error [m]")
    axs[1].set_xlabel("t [s]")
    for ax in axs:
        ax.grid(True, alpha=0.3)
        if failsafe.any():
            ax.fill_between(tp, 0, 1, where=failsafe, color="red", alpha=0.15, transform=ax.get_xaxis_transform(),
                            label="failsafe")
    fig.tight_layout()
    fig.savefig(os.path.join(d, "errors.png"), dpi=120)
    plt.close(fig)
    print("plots in", d)


if __name__ == "__main__":
    main()
