#!/usr/bin/env python3
"""Closed-loop flights over several seeds (`./meshnav fly-table`, docs/closed_loop.md): runs
meshnav_fly per seed into OUT/seedN and prints a markdown table of closed_loop.yaml's figures with
the issue-37 targets (tracking RMSE <= 0.25 m, estimation RMSE <= 0.15 m, no crash, landing within
0.3 m of the pad, fly-by anchors within the replayed flights' figures + 0.05 m: initial <= 0.158 m,
final <= 0.111 m: the centralized = DP means of docs/results.md "Fly-by calibration", 0.108 and 0.061 m,
+ 0.05 m; DAH 0.112 and 0.061 m). Exit 1 when a target
is missed.

--lcm flies each seed as processes over LCM instead (scripts/fly_lcm.sh; `-- --realtime` for real
time) and adds the controller's loop timing (controller_timing.yaml) with the target jitter
p99 <= 5 ms (checked in real time only)."""
import argparse
import os
import subprocess
import sys

import yaml

TARGETS = {"tracking": 0.25, "estimation": 0.15, "landing": 0.3, "anchors_initial": 0.108 + 0.05,
           "anchors_final": 0.061 + 0.05}


def seeds_of(text):
    a, _, b = text.partition("-")
    return list(range(int(a), int(b or a) + 1))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", required=True, help="folder with meshnav_fly")
    ap.add_argument("--seeds", default="1-12", help="range A-B (default 1-12)")
    ap.add_argument("--mission", default=os.path.join(os.path.dirname(__file__), "..", "config", "missions",
                                                      "paper_like_closed_loop.yaml"))
    ap.add_argument("--out", default="out/fly-table")
    ap.add_argument("--lcm", action="store_true", help="fly over LCM (scripts/fly_lcm.sh) instead of in one process")
    ap.add_argument("--reuse", action="store_true", help="fly nothing: tabulate OUT/seedN of an earlier run")
    ap.add_argument("fly_args", nargs=argparse.REMAINDER, help="after --: more meshnav_fly options")
    a = ap.parse_args()
    extra = [x for x in a.fly_args if x != "--"]
    rows = []
    for seed in seeds_of(a.seeds):
        out = os.path.join(a.out, f"seed{seed}")
        if a.lcm:
            cmd = ["bash", os.path.join(os.path.dirname(os.path.abspath(__file__)), "fly_lcm.sh")]
            env = dict(os.environ, MESHNAV_BUILD_DIR=os.path.dirname(os.path.abspath(a.bin)))
        else:
            cmd, env = [os.path.join(a.bin, "meshnav_fly")], None
        cmd += ["--mission", a.mission, "--seed", str(seed), "--out", out] + extra
        if a.reuse:
            r = subprocess.CompletedProcess(cmd, 0, "", "--reuse: not flown")
        else:
            r = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=env)
        path = os.path.join(out, "closed_loop.yaml")
        if not os.path.exists(path):
            print(f"seed {seed}: meshnav_fly failed (exit {r.returncode}): {r.stderr[-500:]}", file=sys.stderr)
            return 1
        with open(path) as f:
            m = yaml.safe_load(f)
        m["seed"] = seed
        timing = os.path.join(out, "controller_timing.yaml")
        if os.path.exists(timing):
            with open(timing) as f:
                m["timing"] = yaml.safe_load(f)
        rows.append(m)
        print(f"seed {seed}: exit {r.returncode}", file=sys.stderr)
    print("| seed | tracking RMSE [m] | estimation RMSE [m] | max est. error [m] | crashed | landed within [m] "
          "| failsafe events | anchors ★ → final [m] |")
    print("| ---: | ---: | ---: | ---: | --- | ---: | ---: | ---: |")
    for m in rows:
        print(f"| {m['seed']} | {m['tracking_rmse_m']:.3f} | {m['estimation_rmse_m']:.3f} | "
              f"{m['max_estimation_error_m']:.3f} | {'yes' if m['crashed'] else 'no'} | {m['landed_within_m']:.3f} | "
              f"{m['failsafe_events']} | {m['anchors_initial_mean_m']:.3f} → {m['anchors_final_mean_m']:.3f} |")
    n = len(rows)
    mean = lambda k: sum(m[k] for m in rows) / n  # noqa: E731
    worst = lambda k: max(m[k] for m in rows)  # noqa: E731
    print(f"| mean | {mean('tracking_rmse_m'):.3f} | {mean('estimation_rmse_m'):.3f} | "
          f"{mean('max_estimation_error_m'):.3f} | {sum(m['crashed'] for m in rows)} / {n} | "
          f"{mean('landed_within_m'):.3f} | {sum(m['failsafe_events'] for m in rows)} | "
          f"{mean('anchors_initial_mean_m'):.3f} → {mean('anchors_final_mean_m'):.3f} |")
    print(f"| max | {worst('tracking_rmse_m'):.3f} | {worst('estimation_rmse_m'):.3f} | "
          f"{worst('max_estimation_error_m'):.3f} | | {worst('landed_within_m'):.3f} | "
          f"{worst('failsafe_events')} | {worst('anchors_initial_mean_m'):.3f} → {worst('anchors_final_mean_m'):.3f} |")
    checks = [
        ("tracking RMSE <= 0.25 m on every seed", worst("tracking_rmse_m") <= TARGETS["tracking"]),
        ("estimation RMSE <= 0.15 m on every seed", worst("estimation_rmse_m") <= TARGETS["estimation"]),
        ("no crash", not any(m["crashed"] for m in rows)),
        ("landed within 0.3 m of the pad on every seed",
         all(m["landed"] and 0 <= m["landed_within_m"] <= TARGETS["landing"] for m in rows)),
        ("fly-by anchors, mean initial <= 0.158 m and final <= 0.111 m",
         mean("anchors_initial_mean_m") <= TARGETS["anchors_initial"] and
         mean("anchors_final_mean_m") <= TARGETS["anchors_final"]),
    ]
    timed = [m for m in rows if "timing" in m]
    if timed:
        print()
        print("| seed | commands late | loop jitter p50 / p99 / max [ms] | IMU arrival jitter p99 [ms] "
              "| IMU → POSE p50 / p99 [ms] | IMU → CONTROL_CMD p50 / p99 [ms] |")
        print("| ---: | ---: | ---: | ---: | ---: | ---: |")
        for m in timed:
            t = m["timing"]
            print(f"| {m['seed']} | {m.get('commands_late', '-')} | {t['jitter_p50_ms']:.2f} / {t['jitter_p99_ms']:.2f} / "
                  f"{t['jitter_max_ms']:.1f} | {t.get('imu_arrival_jitter_p99_ms', -1):.2f} | "
                  f"{t['imu_to_pose_ms']['p50']:.2f} / {t['imu_to_pose_ms']['p99']:.2f} | "
                  f"{t['imu_to_cmd_ms']['p50']:.2f} / {t['imu_to_cmd_ms']['p99']:.2f} |")
        if all(m.get("realtime") for m in timed):
            checks.append(("controller loop jitter p99 <= 5 ms on every seed (real time)",
                           max(m["timing"]["jitter_p99_ms"] for m in timed) <= 5.0))
    print()
    for what, ok in checks:
        print(f"- {'✓' if ok else '✗'} {what}")
    return 0 if all(ok for _, ok in checks) else 1


if __name__ == "__main__":
    sys.exit(main())
