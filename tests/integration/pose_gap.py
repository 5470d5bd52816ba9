#!/usr/bin/env python3
"""Pose outage and error around an instant (the kill -9 of the estimator in multihost_test.sh).

Usage: pose_gap.py ESTIMATE_CSV GROUNDTRUTH_CSV T_EVENT [--settle S] [--until T]
       pose_gap.py --anchors ANCHORS_CSV T_EVENT ID,ID,...

Prints, in data seconds: the longest gap between two consecutive poses in [T_EVENT - 1, T_EVENT + 10]
(`gap`), the time of the first pose after that gap (`back`), and the largest position error from
T_EVENT + settle (default 10 s) to the end or --until (`max_error_after`), against the ground
truth interpolated linearly. One line "key value" each.

With --anchors: for each anchor the last row of anchors.csv before T_EVENT and the first after,
"anchor ID moved M var_ratio R" (position change [m], trace of the covariance after / before):
an anchor resumed from a checkpoint barely moves and keeps its covariance; one that came back
from the setup prior (or a recalibration) would not. Exit 1 when an anchor has no row after.
"""
import sys

import numpy as np


def load(path, cols):
    rows = []
    with open(path) as f:
        for line in f:
            line = line.strip()
            if not line or line[0] in '#t':
                continue
            v = line.replace(',', ' ').split()
            rows.append([float(v[c]) for c in cols])
    return np.array(rows)


def anchors(argv):
    rows = load(argv[2], [0, 1, 2, 3, 4, 5, 8, 10])
    t_event = float(argv[3])
    ok = True
    for i in [int(x) for x in argv[4].split(',')]:
        r = rows[rows[:, 1] == i]
        before, after = r[r[:, 0] < t_event], r[r[:, 0] > t_event]
        if not len(before) or not len(after):
            print('anchor %d rows_before %d rows_after %d' % (i, len(before), len(after)))
            ok = False
            continue
        b, a = before[-1], after[0]
        moved = float(np.linalg.norm(a[2:5] - b[2:5]))
        ratio = float(a[5:8].sum() / b[5:8].sum()) if b[5:8].sum() > 0 else float('inf')
        print('anchor %d moved %.4f var_ratio %.3f' % (i, moved, ratio))
    return 0 if ok else 1


def main(argv):
    if len(argv) >= 2 and argv[1] == '--anchors':
        return anchors(argv)
    if len(argv) < 4:
        print(__doc__)
        return 2
    est = load(argv[1], [0, 1, 2, 3])
    gt = load(argv[2], [0, 1, 2, 3])
    t_event = float(argv[3])
    settle, until = 10.0, float('inf')
    if '--settle' in argv:
        settle = float(argv[argv.index('--settle') + 1])
    if '--until' in argv:
        until = float(argv[argv.index('--until') + 1])
    t = est[:, 0]
    win = (t >= t_event - 1.0) & (t <= t_event + 10.0)
    idx = np.nonzero(win)[0]
    if len(idx) < 2:
        print('gap inf')
        return 1
    d = np.diff(t[idx])
    k = int(np.argmax(d))
    print('gap %.3f' % d[k])
    print('last_before %.3f' % t[idx[k]])
    print('back %.3f' % t[idx[k + 1]])
    sel = (t >= t_event + settle) & (t <= until) & (t >= gt[0, 0]) & (t <= gt[-1, 0])
    err = np.zeros(int(sel.sum()))
    for j, c in enumerate(range(1, 4)):
        err += (est[sel, c] - np.interp(t[sel], gt[:, 0], gt[:, c])) ** 2
    err = np.sqrt(err)
    print('max_error_after %.3f' % (err.max() if len(err) else float('nan')))
    print('poses_after %d' % len(err))
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
