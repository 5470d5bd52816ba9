#!/usr/bin/env python3
"""The checks of fleet_peer_ranges_lcm_test.sh on its two launches (with and without the fleet's
peer_router) and the one-process run of the same fleet: see that script's header.

  fleet_peer_ranges_check.py WORK T0 T1
"""
import bisect
import csv
import math
import os
import sys

import yaml


def errors(estimate, truth_csv):
    """(t, position error [m]) of every estimate row with a truth row within 10 ms."""
    truth = [list(map(float, r[:4])) for r in csv.reader(l for l in open(truth_csv) if l[:1].isdigit())]
    tt = [r[0] for r in truth]
    out = []
    for r in csv.DictReader(open(estimate)):
        t = float(r["t"])
        i = bisect.bisect_left(tt, t)
        cand = [j for j in (i - 1, i) if 0 <= j < len(tt)]
        if not cand:
            continue
        j = min(cand, key=lambda k: abs(tt[k] - t))
        if abs(tt[j] - t) > 0.01:
            continue
        out.append((t, math.dist((float(r["tx"]), float(r["ty"]), float(r["tz"])), truth[j][1:4])))
    return out


def rmse(errs, keep):
    e = [x for t, x in errs if keep(t)]
    return (math.sqrt(sum(x * x for x in e) / len(e)) if e else float("nan")), len(e)


def main():
    work, t0, t1 = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
    data = os.path.join(work, "data")
    t_start = min(float(l.split(",")[0]) for l in open(os.path.join(data, "v0", "groundtruth.csv")) if l[:1].isdigit())
    inside = lambda t: t0 <= t - t_start <= t1  # noqa: E731  (the outage, in the sim's relative time)
    outside = lambda t: not inside(t) and t - t_start > 5.0  # noqa: E731  (after the start-up)
    res = {}
    for name, run in (("with", "run_with"), ("without", "run_without"), ("one process", "one_process")):
        res[name] = {}
        for v in ("v0", "v1"):
            est = os.path.join(work, run, v, "estimate.csv")
            if not os.path.exists(est):
                sys.exit(f"FAIL: no {est}")
            e = errors(est, os.path.join(data, v, "groundtruth.csv"))
            res[name][v] = (rmse(e, inside), rmse(e, outside), max((x for t, x in e if inside(t)), default=float("nan")))
            (ri, ni), (ro, no), mx = res[name][v]
            print(f"{name:12s} {v}: outage RMSE {ri:.3f} m (max {mx:.3f} m, {ni} poses), outside {ro:.3f} m ({no} poses)")
    summ = {v: yaml.safe_load(open(os.path.join(work, "run_with", v, "summary.yaml"))) for v in ("v0", "v1")}
    n_peer = {v: summ[v]["channels"].get(f"{v}/PEER_RANGE", {}).get("messages", 0) for v in ("v0", "v1")}
    fused = summ["v0"]["estimator_status"]["counters"].get("peer_range_fused", 0)
    print(f"PEER_RANGE received: v0 {n_peer['v0']}, v1 {n_peer['v1']}; v0's estimator fused {fused}")
    without = yaml.safe_load(open(os.path.join(work, "run_without", "v0", "summary.yaml")))
    if without["channels"].get("v0/PEER_RANGE", {}).get("messages", 0):
        sys.exit("FAIL: PEER_RANGE without a peer_router")
    if n_peer["v0"] < 50 or fused < 0.5 * n_peer["v0"]:
        sys.exit(f"FAIL: v0 (without anchors for {t1 - t0:.0f} s) received {n_peer['v0']} PEER_RANGE and fused {fused}")
    if n_peer["v1"] > 0.1 * n_peer["v0"]:
        sys.exit(f"FAIL: v1, which had its anchors, received {n_peer['v1']} PEER_RANGE (v0 {n_peer['v0']})")
    w, wo = res["with"]["v0"][0][0], res["without"]["v0"][0][0]
    if not (w <= 0.5 and w <= 0.5 * wo):
        sys.exit(f"FAIL: v0's outage RMSE {w:.3f} m with the peer_router, {wo:.3f} m without (expected <= 0.5 m and "
                 "<= half)")
    one = res["one process"]["v0"][0][0]
    if not w <= one + 0.1:
        sys.exit(f"FAIL: v0's outage RMSE over LCM {w:.3f} m, in one process {one:.3f} m")
    # Outside the outage: both vehicles with the peer_router, v1 without (v0 is lost after it).
    for name, v in (("with", "v0"), ("with", "v1"), ("without", "v1")):
        ro = res[name][v][1][0]
        if not ro < 0.3:
            sys.exit(f"FAIL: {v}'s RMSE outside the outage ({name} the peer_router) {ro:.3f} m")


if __name__ == "__main__":
    main()
