#!/usr/bin/env python3
"""Range error histograms per ordered pair (called by meshnav_range_stats --plots DIR).

Reads range_errors.csv (id1,id2,t,error_m,bias_m,std_m,lower_m,upper_m) and writes
range_hist_<id1>_<id2>.png per pair and range_hist_all.png (grid of all pairs): histogram of the
errors within the gate, the window kept by the bias estimator, and the fitted Gaussian N(bias, std).
"""
import argparse
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def load(path):
    pairs = {}
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            key = (int(r["id1"]), int(r["id2"]))
            p = pairs.setdefault(key, {"e": [], "bias": float(r["bias_m"]), "std": float(r["std_m"]),
                                       "lo": float(r["lower_m"]), "hi": float(r["upper_m"])})
            p["e"].append(float(r["error_m"]))
    return pairs


def draw(ax, key, p, max_error):
    e = np.array(p["e"])
    e = e[np.abs(e) <= max_error]
    if len(e) == 0:
        ax.set_title("%d→%d: no errors within gate" % key)
        return
    ax.hist(e, bins=50, density=True, color="tab:red", alpha=0.5, label="errors |e| ≤ %.2g m" % max_error)
    inside = e[(e > p["lo"]) & (e < p["hi"])]
    if len(inside) > 1 and math.isfinite(p["std"]) and p["std"] > 0:
        ax.hist(inside, bins=25, density=True, color="tab:blue", alpha=0.5, label="kept")
        x = np.linspace(e.min(), e.max(), 300)
        ax.plot(x, np.exp(-0.5 * ((x - p["bias"]) / p["std"]) ** 2) / (math.sqrt(2 * math.pi) * p["std"]),
                "g--", lw=1.2, label="N(γ, σ)")
    ax.axvline(0.0, color="k", lw=0.6)
    ax.set_title("%d→%d: γ=%.3f m, σ=%.3f m" % (key[0], key[1], p["bias"], p["std"]), fontsize=9)
    ax.set_xlabel("z − d [m]")
    ax.legend(fontsize=6)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--errors", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--max-error", type=float, default=1.0)
    a = ap.parse_args()
    pairs = load(a.errors)
    if not pairs:
        print("plot_range_hist.py: no errors in " + a.errors, file=sys.stderr)
        return 1
    os.makedirs(a.out, exist_ok=True)
    for key, p in sorted(pairs.items()):
        fig, ax = plt.subplots(figsize=(5, 3.5))
        draw(ax, key, p, a.max_error)
        fig.tight_layout()
        fig.savefig(os.path.join(a.out, "range_hist_%d_%d.png" % key), dpi=110)
        plt.close(fig)
    n = len(pairs)
    cols = int(math.ceil(math.sqrt(n)))
    rows = int(math.ceil(n / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(4 * cols, 3 * rows), squeeze=False)
    for ax, (key, p) in zip(axes.flat, sorted(pairs.items())):
        draw(ax, key, p, a.max_error)
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "range_hist_all.png"), dpi=100)
    plt.close(fig)
    print("plot_range_hist.py: wrote %d pair histograms and range_hist_all.png to %s" % (n, a.out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
