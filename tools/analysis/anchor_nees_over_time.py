#!/usr/bin/python3
"""Estimated anchors' NEES and error over time, pooled over the runs of a paper-table output.

  anchor_nees_over_time.py OUT     OUT/seedNN/{dataset,run} as written by `./meshnav paper-table`

For every ANCHORS row (run/anchors.csv) of an estimated anchor (id >= 106, the fly-by anchors of
the paper scenario) the position NEES against dataset/truth.yaml, in 10 s bins of data time: how
many beliefs are within the χ²(3) 99.7 % bound 13.93, the median NEES (2.37 for a consistent
filter) and the mean error (issue 10: the beliefs after a re-run on an anchor join).
"""
import csv
import glob
import sys

import numpy as np
import yaml

BOUND = 13.93


def main():
    if len(sys.argv) != 2:
        print(__doc__)
        return 2
    bins = {}
    for d in sorted(glob.glob(sys.argv[1] + "/seed*")):
        truth = yaml.safe_load(open(d + "/dataset/truth.yaml"))["anchor_positions"]
        for r in csv.DictReader(open(d + "/run/anchors.csv")):
            i = int(r["id"])
            if i < 106:
                continue
            c = [float(r[k]) for k in ("pxx", "pxy", "pxz", "pyy", "pyz", "pzz")]
            P = np.array([[c[0], c[1], c[2]], [c[1], c[3], c[4]], [c[2], c[4], c[5]]])
            e = np.array([float(r["x"]), float(r["y"]), float(r["z"])]) - np.array(truth[i], float)
            b = int(float(r["t"]) // 10) * 10
            bins.setdefault(b, []).append((e @ np.linalg.solve(P, e), np.linalg.norm(e)))
    for b in sorted(bins):
        a = np.array(bins[b])
        print(f"t {b:4d}-{b + 10:<4d} beliefs {len(a):4d}  NEES <= {BOUND}: {np.mean(a[:, 0] <= BOUND) * 100:5.1f} %"
              f"  median NEES {np.median(a[:, 0]):6.2f}  mean error {a[:, 1].mean():.3f} m")
    return 0


if __name__ == "__main__":
    sys.exit(main())
