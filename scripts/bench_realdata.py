#!/usr/bin/env python3
"""Wall time of the real-data path a user runs first: `./meshnav import rosbag` of ISAS-Walk1 and
`meshnav_run` with its defaults on the imported folder (issue 9: "import plus run of ISAS-Walk1 in
under 5 s"). Each of --runs repetitions imports into a fresh folder and runs the pipeline; the
medians are printed with the target. A speed figure, not a test: the machine is shared, so it
reports and never fails on the time (it fails when a step fails)."""

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

TARGET_S = 5.0


def timed(cmd, env=None):
    t0 = time.monotonic()
    proc = subprocess.run(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    elapsed = time.monotonic() - t0
    if proc.returncode != 0:
        sys.exit(f"bench realdata: {' '.join(cmd)} failed (exit {proc.returncode}):\n{proc.stderr[-2000:]}")
    return elapsed


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap = argparse.ArgumentParser(prog="meshnav bench realdata", description=__doc__)
    ap.add_argument("--bag", default=os.path.join(root, "..", "shared", "data", "real-isas-walk1", "ISAS-Walk1.bag"),
                    help="the ISAS-Walk1 ROS 1 bag (default: ../shared/data/real-isas-walk1/ISAS-Walk1.bag)")
    ap.add_argument("--runs", type=int, default=5, help="repetitions (default 5); medians are reported")
    ap.add_argument("--bin", default=os.path.join(root, "build", "bin"), help="folder of meshnav_run (default build/bin)")
    a = ap.parse_args()
    if a.runs < 1:
        sys.exit("bench realdata: --runs must be at least 1")
    if not os.path.isfile(a.bag):
        sys.exit(f"bench realdata: {a.bag} not found (give --bag FILE)")
    run_bin = os.path.join(a.bin, "meshnav_run")
    if not os.access(run_bin, os.X_OK):
        sys.exit(f"bench realdata: {run_bin} missing (build first)")
    env = dict(os.environ)
    env["PYTHONPATH"] = os.path.join(root, "tools") + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    imports, runs = [], []
    with tempfile.TemporaryDirectory(prefix="meshnav-bench-realdata-") as tmp:
        for k in range(a.runs):
            ds, out = os.path.join(tmp, f"ds{k}"), os.path.join(tmp, f"run{k}")
            imports.append(timed(["/usr/bin/python3", "-m", "meshnav_import", "rosbag", "--bag", a.bag, "--out", ds], env))
            runs.append(timed([run_bin, "--dataset", ds, "--out", out]))
            print(f"run {k + 1}/{a.runs}: import {imports[-1]:.2f} s, run {runs[-1]:.2f} s, "
                  f"total {imports[-1] + runs[-1]:.2f} s", flush=True)
    totals = [i + r for i, r in zip(imports, runs)]
    med = statistics.median(totals)
    print(f"ISAS-Walk1, median of {a.runs}: import {statistics.median(imports):.2f} s, "
          f"run {statistics.median(runs):.2f} s, import + run {med:.2f} s "
          f"(target <= {TARGET_S:.0f} s: {'met' if med <= TARGET_S else 'NOT met'})")


if __name__ == "__main__":
    main()
