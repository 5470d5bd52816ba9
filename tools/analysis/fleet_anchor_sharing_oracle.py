#!/usr/bin/env python3
"""What sharing the vehicles' anchor beliefs with their estimators could bring (issue 38 item 2;
docs/decisions/016-fleet-sharing.md, "Anchor beliefs into the estimators: measured first").

For each seed folder of `./meshnav fleet-scale-table` (OUT/seedN: sim/ and the fleet run fleet/):
  * beliefs: for every fly-by anchor (an anchor with a covariance in shared_anchors.csv), the error
    against the truth of each vehicle's final belief (fleet/vK/anchors.csv), of the fleet's
    covariance-intersection belief (fleet/shared_anchors.csv) and of the best vehicle's: what any
    scheme that hands the vehicles a fused belief could move their anchors by;
  * poses (with --run): the oracle of perfect sharing, every anchor known at its true position from
    the start (each vehicle's setup.yaml rewritten from its truth.yaml, `meshnav_run --fleet
    --no-calibration` with the table's estimator config), each vehicle's position RMSE against the
    fleet run's (result.json): what perfect anchors could move the vehicles' poses by.

A seed folder is any folder with sim/ (meshnav_sim's fleet) and fleet/ (`meshnav_run --fleet
sim/fleet.yaml --out fleet`); without fleet-scale-table's result.json the fleet run is evaluated here.
The paper's hall with 3 vehicles (decision 016's second row):
  build/bin/meshnav_sim --fleet 3 --seed 1 --out D/sim && build/bin/meshnav_run --fleet D/sim/fleet.yaml --out D/fleet
  /usr/bin/python3 tools/analysis/fleet_anchor_sharing_oracle.py D --run --config config/estimator.yaml

Usage: /usr/bin/python3 tools/analysis/fleet_anchor_sharing_oracle.py OUT/seedN [...]
           [--run --bin build/bin --config config/fleet_scale.yaml --work DIR] [--self-test]
"""

import argparse
import csv
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile

import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def final_rows(path):
    """id -> the last row of an anchors.csv-format file."""
    rows = {}
    with open(path) as f:
        for r in csv.DictReader(f):
            rows[int(r["id"])] = r
    return rows


def error(row, truth):
    return math.dist([float(row[k]) for k in "xyz"], truth)


def vehicles(seed_dir):
    with open(os.path.join(seed_dir, "sim", "fleet.yaml")) as f:
        return [v["name"] for v in yaml.safe_load(f)["vehicles"]]


def beliefs(seed_dir):
    """(shared CI error, mean vehicle error, best vehicle error) per fly-by anchor."""
    names = vehicles(seed_dir)
    with open(os.path.join(seed_dir, "sim", names[0], "truth.yaml")) as f:
        truth = yaml.safe_load(f)["anchor_positions"]
    shared = final_rows(os.path.join(seed_dir, "fleet", "shared_anchors.csv"))
    per_vehicle = [final_rows(os.path.join(seed_dir, "fleet", n, "anchors.csv")) for n in names]
    out = []
    for i, row in shared.items():
        if float(row["pxx"]) == 0.0:
            continue  # a known anchor
        errs = [error(v[i], truth[i]) for v in per_vehicle if i in v and float(v[i]["pxx"]) > 0.0]
        if errs:
            out.append((error(row, truth[i]), sum(errs) / len(errs), min(errs)))
    return out


def known_anchor_setup(setup_text, truth):
    """setup.yaml's text with abs_anchor_positions replaced by every anchor of `truth` (id -> xyz)."""
    lines = setup_text.split("\n")
    out, i = [], 0
    while i < len(lines):
        out.append(lines[i])
        if lines[i].startswith("abs_anchor_positions:"):
            i += 1
            while i < len(lines) and lines[i].startswith("  "):
                i += 1
            out += ["  %d: [%r, %r, %r]" % (k, *truth[k]) for k in sorted(truth)]
            continue
        i += 1
    return "\n".join(out)


def evaluated_rmse(bin_dir, dataset, run):
    """Position RMSE of `run` against `dataset` (meshnav_eval, metrics.json beside the run)."""
    js = os.path.join(run, "metrics.json")
    subprocess.run([os.path.join(bin_dir, "meshnav_eval"), "--dataset", dataset, "--run", run, "--no-plots",
                    "--no-baseline", "--json", js], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    with open(js) as f:
        return json.load(f)["pose"]["position"]["rmse_m"]


def fleet_run_rmse(seed_dir, bin_dir):
    """Each vehicle's RMSE in the fleet run: fleet-scale-table's result.json, else evaluated here."""
    result = os.path.join(seed_dir, "result.json")
    if os.path.isfile(result):
        with open(result) as f:
            return [v["fleet_rmse"] for v in json.load(f)["vehicles"]]
    return [evaluated_rmse(bin_dir, os.path.join(seed_dir, "sim", n), os.path.join(seed_dir, "fleet", n))
            for n in vehicles(seed_dir)]


def oracle_run(seed_dir, work, bin_dir, config):
    """Each vehicle's position RMSE with every anchor known at its truth."""
    names = vehicles(seed_dir)
    sim = os.path.join(work, "sim")
    os.makedirs(sim, exist_ok=True)
    for n in names:
        src, dst = os.path.join(seed_dir, "sim", n), os.path.join(sim, n)
        os.makedirs(dst, exist_ok=True)
        for f in os.listdir(src):
            if f != "setup.yaml" and not os.path.exists(os.path.join(dst, f)):
                os.symlink(os.path.abspath(os.path.join(src, f)), os.path.join(dst, f))
        with open(os.path.join(src, "truth.yaml")) as f:
            truth = yaml.safe_load(f)["anchor_positions"]
        with open(os.path.join(src, "setup.yaml")) as f, open(os.path.join(dst, "setup.yaml"), "w") as g:
            g.write(known_anchor_setup(f.read(), truth))
    shutil.copy(os.path.join(seed_dir, "sim", "fleet.yaml"), os.path.join(sim, "fleet.yaml"))
    run = os.path.join(work, "run")
    subprocess.run([os.path.join(bin_dir, "meshnav_run"), "--fleet", os.path.join(sim, "fleet.yaml"),
                    "--no-calibration", "--allow-lost", "--config", config, "--out", run],
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return [evaluated_rmse(bin_dir, os.path.join(sim, n), os.path.join(run, n)) for n in names]


def self_test():
    setup = "imu_id: 1\nrel_tag_positions:\n  100: [0, 0, 0]\nabs_anchor_positions:  # known\n  102: [1, 2, 3]\nbaro_id: 2\n"
    got = yaml.safe_load(known_anchor_setup(setup, {101: [0.5, 0, 1], 102: [1, 2, 3]}))
    assert got["abs_anchor_positions"] == {101: [0.5, 0, 1], 102: [1, 2, 3]}, got
    assert got["rel_tag_positions"] == {100: [0, 0, 0]} and got["baro_id"] == 2, got
    with tempfile.TemporaryDirectory() as d:
        for sub in ("sim/v0", "sim/v1", "fleet/v0", "fleet/v1"):
            os.makedirs(os.path.join(d, sub))
        with open(os.path.join(d, "sim", "fleet.yaml"), "w") as f:
            f.write("vehicles:\n  - {name: v0, dataset: v0}\n  - {name: v1, dataset: v1}\n")
        with open(os.path.join(d, "sim", "v0", "truth.yaml"), "w") as f:
            f.write("anchor_positions:\n  101: [0, 0, 0]\n  106: [1, 0, 0]\n")
        head = "t,id,x,y,z,pxx,pxy,pxz,pyy,pyz,pzz\n"
        for path, x in (("fleet/shared_anchors.csv", 1.03), ("fleet/v0/anchors.csv", 1.02), ("fleet/v1/anchors.csv", 1.06)):
            with open(os.path.join(d, path), "w") as f:
                f.write(head + "1,101,0,0,0,0,0,0,0,0,0\n1,106,0.5,0,0,1,0,0,1,0,1\n140,106,%g,0,0,1e-3,0,0,1e-3,0,1e-3\n" % x)
        (s, m, b), = beliefs(d)
        assert abs(s - 0.03) < 1e-9 and abs(m - 0.04) < 1e-9 and abs(b - 0.02) < 1e-9, (s, m, b)
    print("fleet_anchor_sharing_oracle self-test: ok")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("seeds", nargs="*", help="OUT/seedN folders of ./meshnav fleet-scale-table")
    p.add_argument("--run", action="store_true", help="also run the known-anchor oracle (about 30 s per seed)")
    p.add_argument("--bin", default=os.path.join(ROOT, "build", "bin"))
    p.add_argument("--config", default=os.path.join(ROOT, "config", "fleet_scale.yaml"),
                   help="estimator config of the table's runs")
    p.add_argument("--work", help="folder for the oracle runs (default: a temporary one)")
    p.add_argument("--self-test", action="store_true")
    a = p.parse_args()
    if a.self_test:
        self_test()
        return 0
    if not a.seeds:
        p.error("no seed folder given")
    all_b, fleet_rmse, oracle_rmse = [], [], []
    for seed in a.seeds:
        b = beliefs(seed)
        all_b += b
        line = "%s: %d fly-by anchors: error shared (CI) %.4f m, each vehicle's %.4f m, best vehicle's %.4f m" % (
            seed, len(b), sum(x[0] for x in b) / len(b), sum(x[1] for x in b) / len(b), sum(x[2] for x in b) / len(b))
        if a.run:
            fr = fleet_run_rmse(seed, a.bin)
            work = os.path.join(a.work, os.path.basename(os.path.normpath(seed))) if a.work else tempfile.mkdtemp()
            orr = oracle_run(seed, work, a.bin, a.config)
            fleet_rmse += fr
            oracle_rmse += orr
            line += "; position RMSE fleet %.4f m, all anchors known exactly %.4f m" % (sum(fr) / len(fr), sum(orr) / len(orr))
            if not a.work:
                shutil.rmtree(work)
        print(line, flush=True)
    n = len(all_b)
    print("all: %d fly-by anchors: error shared (CI) %.4f m, each vehicle's %.4f m, best vehicle's %.4f m" % (
        n, sum(x[0] for x in all_b) / n, sum(x[1] for x in all_b) / n, sum(x[2] for x in all_b) / n))
    if a.run:
        print("all: %d vehicles: position RMSE fleet %.4f m, all anchors known exactly %.4f m" % (
            len(fleet_rmse), sum(fleet_rmse) / len(fleet_rmse), sum(oracle_rmse) / len(oracle_rmse)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
