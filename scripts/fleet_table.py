#!/usr/bin/env python3
"""A simulated fleet against each of its vehicles flown alone (`./meshnav fleet-table`, docs/fleet.md).

For every seed: `meshnav_sim --fleet N --seed S` (N vehicles in the paper's hall among the same
anchors, vehicle k with seed S + k), then `meshnav_run --fleet` (one calibrator for all, one anchor
map), then `meshnav_run --dataset` on each vehicle's folder alone with the same mission, each run
scored by `meshnav_eval`. The table sets fleet and alone side by side per vehicle: position RMSE,
position ANEES, and the mean error of the fly-by anchors when they were first fused (initial) and
at the end (final). Exit status 1 when a run fails or exits non-zero.

Usage:
  fleet_table.py [--seeds 1-6] [--vehicles 2] [--mission FILE|auto] [--inter-vehicle-hz F] [--out DIR]
                 [--bin DIR] [--table-md FILE]
"""

import argparse
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import robustness  # noqa: E402  (run_command)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def parse_seeds(text):
    """'1-6' or '1,3,5' -> a list of ints; raises ValueError on anything else."""
    if "-" in text:
        a, b = (int(x) for x in text.split("-", 1))
        if b < a:
            raise ValueError(f"seed range {text} is empty")
        return list(range(a, b + 1))
    return [int(x) for x in text.split(",")]


def parse_args(argv):
    p = argparse.ArgumentParser(prog="meshnav fleet-table", description=__doc__.split("\n\n")[1],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--seeds", default="1-6", help="seeds A-B or A,B,... (default 1-6)")
    p.add_argument("--vehicles", type=int, default=2, help="vehicles in the fleet, 2-16 (default 2)")
    p.add_argument("--mission", default=os.path.join(ROOT, "config/missions/paper_s2.yaml"),
                   help="mission file for every run, or 'auto' for automatic calibration "
                        "(default config/missions/paper_s2.yaml: 106-110 calibrated at 80 s and 100 s)")
    p.add_argument("--out", default=os.path.join(ROOT, "out/fleet-table"), help="output root (default out/fleet-table)")
    p.add_argument("--bin", default=os.path.join(os.environ.get("MESHNAV_BUILD_DIR", os.path.join(ROOT, "build")), "bin"),
                   help="folder of meshnav_sim, meshnav_run, meshnav_eval (default build/bin)")
    p.add_argument("--table-md", default="", help="also write the table as Markdown to this file")
    p.add_argument("--inter-vehicle-hz", type=float, default=0.0,
                   help="the vehicles also range tag to tag at this rate (meshnav_sim --inter-vehicle-hz), fused in "
                        "the fleet run; alone, a vehicle counts them as unknown devices (default 0: none) [Hz]")
    a = p.parse_args(argv)
    try:
        a.seeds = parse_seeds(a.seeds)
    except ValueError as e:
        p.error(f"--seeds: {e}")
    if not 2 <= a.vehicles <= 16:
        p.error("--vehicles must be 2-16")
    if a.mission != "auto" and not os.path.isfile(a.mission):
        p.error(f"--mission: no such file {a.mission}")
    if not 0.0 <= a.inter_vehicle_hz <= 100.0:
        p.error("--inter-vehicle-hz must be in [0, 100]")
    return a


def evaluate(bin_dir, dataset, run, log, calibration):
    """meshnav_eval of one run; returns (position RMSE, ANEES, mean initial, mean final anchor error).
    `calibration`: the run's calibration.yaml (a fleet writes one for all vehicles, above theirs), so
    that the initial anchor error is the calibration's for fleet and alone runs alike."""
    js = os.path.join(run, "metrics.json")
    cal = ["--calibration", calibration] if os.path.isfile(calibration) else []
    rc = robustness.run_command([os.path.join(bin_dir, "meshnav_eval"), "--dataset", dataset, "--run", run,
                                 "--no-plots", "--no-baseline", "--json", js] + cal, log)
    if rc != 0:
        raise RuntimeError(f"meshnav_eval exited {rc} (log {log})")
    with open(js) as f:
        m = json.load(f)
    pos, anchors = m["pose"]["position"], m.get("anchors", {})
    return (pos["rmse_m"], pos["anees"], anchors.get("mean_initial_error_m", float("nan")),
            anchors.get("mean_final_error_m", float("nan")))


def run_seed(a, seed):
    """Simulate, run as a fleet and each vehicle alone, evaluate; a row per vehicle."""
    base = os.path.join(a.out, f"seed{seed}")
    sim = os.path.join(base, "sim")
    os.makedirs(base, exist_ok=True)
    mission = [] if a.mission == "auto" else ["--mission", a.mission]
    ranging = ["--inter-vehicle-hz", repr(a.inter_vehicle_hz)] if a.inter_vehicle_hz > 0 else []
    steps = [("sim", [os.path.join(a.bin, "meshnav_sim"), "--fleet", str(a.vehicles), "--seed", str(seed),
                      "--out", sim] + ranging),
             # --allow-lost: a vehicle that ends lost is evaluated (its error shows it) instead of
             # stopping the whole table.
             ("fleet", [os.path.join(a.bin, "meshnav_run"), "--fleet", os.path.join(sim, "fleet.yaml"),
                        "--out", os.path.join(base, "fleet"), "--allow-lost"] + mission)]
    for v in range(a.vehicles):
        steps.append((f"alone_v{v}", [os.path.join(a.bin, "meshnav_run"), "--dataset", os.path.join(sim, f"v{v}"),
                                      "--out", os.path.join(base, f"alone_v{v}"), "--allow-lost"] + mission))
    for name, cmd in steps:
        log = os.path.join(base, name + ".log")
        rc = robustness.run_command(cmd, log)
        if rc != 0:
            raise RuntimeError(f"seed {seed}: {name} exited {rc} (log {log})")
    rows = []
    for v in range(a.vehicles):
        ds = os.path.join(sim, f"v{v}")
        fleet = evaluate(a.bin, ds, os.path.join(base, "fleet", f"v{v}"), os.path.join(base, f"eval_fleet_v{v}.log"),
                         os.path.join(base, "fleet", "calibration.yaml"))
        alone = evaluate(a.bin, ds, os.path.join(base, f"alone_v{v}"), os.path.join(base, f"eval_alone_v{v}.log"),
                         os.path.join(base, f"alone_v{v}", "calibration.yaml"))
        rows.append((seed, v, fleet, alone))
    return rows


HEADER = ("| seed | vehicle | position RMSE [m] fleet / alone | position ANEES fleet / alone "
          "| anchors initial error [m] fleet / alone | anchors final error [m] fleet / alone |")


def table_lines(rows):
    lines = [HEADER, "| ---: | ---: | ---: | ---: | ---: | ---: |"]
    for seed, v, f, s in rows:
        lines.append(f"| {seed} | v{v} | {f[0]:.3f} / {s[0]:.3f} | {f[1]:.2f} / {s[1]:.2f} "
                     f"| {f[2]:.3f} / {s[2]:.3f} | {f[3]:.3f} / {s[3]:.3f} |")
    n = len(rows)
    mean = [[sum(r[k][i] for r in rows) / n for i in range(4)] for k in (2, 3)]
    lines.append(f"| mean | {n} | {mean[0][0]:.3f} / {mean[1][0]:.3f} | {mean[0][1]:.2f} / {mean[1][1]:.2f} "
                 f"| {mean[0][2]:.3f} / {mean[1][2]:.3f} | {mean[0][3]:.3f} / {mean[1][3]:.3f} |")
    return lines


def main(argv):
    a = parse_args(argv)
    rows = []
    for i, seed in enumerate(a.seeds):
        print(f"[fleet-table] seed {seed} ({i + 1}/{len(a.seeds)}): sim, fleet run, {a.vehicles} runs alone, eval",
              flush=True)
        try:
            rows += run_seed(a, seed)
        except (RuntimeError, KeyError, OSError, ValueError) as e:
            print(f"[fleet-table] FAILED: {e}", file=sys.stderr)
            return 1
    lines = table_lines(rows)
    print("\n".join(lines))
    if a.table_md:
        with open(a.table_md, "w") as f:
            f.write("\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
