#!/usr/bin/env python3
"""A fleet among a hundred anchors in TDMA cells (`./meshnav fleet-scale-table`, docs/fleet.md "Scale").

For every seed: `meshnav_sim --vehicles N --anchors M --hall X,Y,Z` (the generated mission.yaml
calibrates the fly-by anchors), then
  fleet    `meshnav_run --fleet` with the inter-vehicle ranges (one calibrator, one anchor map);
  alone    each vehicle's dataset run by itself (the anchors calibrated from its own tags only);
  outage   the same fleet simulated again with --outage V,T0,T1 (the anchors do not answer vehicle V's
           tags over T0-T1; V is the vehicle with the most tag-to-tag ranges in that window in the
           first simulation, i.e. the one with the most neighbours, chosen before any run), run with
           and without (--no-inter-vehicle-ranges) the inter-vehicle ranges.
Every run uses --config (default config/fleet_scale.yaml) and --allow-lost, and is scored by
`meshnav_eval --no-baseline` (no alignment). Rows per seed:
  * each vehicle's position RMSE / ANEES in the fleet (target <= 0.12 m) and alone;
  * the outage vehicle's RMSE and largest error over T0-T1, with / without inter-vehicle ranges
    (target <= 0.30 m with, and diverging without);
  * fly-by anchors calibrated with the tags of >= 2 vehicles (calibration.yaml ref_ids): their error
    when first calibrated in the fleet against the same anchor calibrated in the alone runs of the
    vehicles that saw it (target: fleet <= 0.7 x alone);
  * final anchor NEES (3 dof, <= 13.93) of every vehicle's last estimate of every fly-by anchor in
    the fleet run, and of those calibrated from >= 2 vehicles (target >= 90 %).
Exit status 1 when a step fails.

Usage:
  fleet_scale_table.py [--seeds 1-12] [--vehicles 5] [--anchors 100] [--hall 40,40,10] [--outage-window 60,80]
                       [--config FILE] [--out DIR] [--bin DIR] [--table-md FILE] [--keep-going]
"""

import argparse
import csv
import json
import math
import os
import sys
import time

import yaml

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import robustness  # noqa: E402  (run_command)
from fleet_table import parse_seeds  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
NEES_BOUND = 13.93


def parse_args(argv):
    p = argparse.ArgumentParser(prog="meshnav fleet-scale-table", description=__doc__.split("\n\n")[1],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--seeds", default="1-12", help="seeds A-B or A,B,... (default 1-12)")
    p.add_argument("--vehicles", type=int, default=5, help="vehicles, 2-16 (default 5)")
    p.add_argument("--anchors", type=int, default=100, help="anchors, 4-400 (default 100)")
    p.add_argument("--hall", default="40,40,10", help="hall X,Y,Z [m] (default 40,40,10)")
    p.add_argument("--duration", type=float, default=0.0, help="sequence length [s] (default: the simulator's 140 s)")
    p.add_argument("--outage-window", default="60,80", help="T0,T1 of the outage [s] (default 60,80)")
    p.add_argument("--config", default=os.path.join(ROOT, "config/fleet_scale.yaml"),
                   help="estimator options of every run (default config/fleet_scale.yaml)")
    p.add_argument("--out", default=os.path.join(ROOT, "out/fleet-scale-table"), help="output root")
    p.add_argument("--bin", default=os.path.join(os.environ.get("MESHNAV_BUILD_DIR", os.path.join(ROOT, "build")), "bin"),
                   help="folder of meshnav_sim, meshnav_run, meshnav_eval (default build/bin)")
    p.add_argument("--table-md", default="", help="also write the tables as Markdown to this file")
    p.add_argument("--keep-going", action="store_true", help="a failed seed is reported and skipped")
    p.add_argument("--from-results", action="store_true",
                   help="only print the tables from the seeds' OUT/seedN/result.json of an earlier run")
    a = p.parse_args(argv)
    try:
        a.seeds = parse_seeds(a.seeds)
        a.window = [float(x) for x in a.outage_window.split(",")]
        if len(a.window) != 2 or not 0 <= a.window[0] < a.window[1]:
            raise ValueError("--outage-window must be T0,T1 with 0 <= T0 < T1")
    except ValueError as e:
        p.error(str(e))
    if not 2 <= a.vehicles <= 16:
        p.error("--vehicles must be 2-16")
    if not os.path.isfile(a.config):
        p.error(f"--config: no such file {a.config}")
    return a


def run(cmd, log):
    rc = robustness.run_command(cmd, log)
    if rc != 0:
        raise RuntimeError(f"{os.path.basename(cmd[0])} exited {rc} (log {log})")


def vehicle_of(tag):
    """Tags 99/100/105 + 1000 k belong to vehicle k (meshnav_sim --vehicles)."""
    return tag // 1000


def peer_vehicles(sim, n, victim, t0, t1):
    """Per other vehicle, the tag-to-tag ranges it exchanged with `victim` in [t0, t1]."""
    counts = {}
    for v in range(n):
        with open(os.path.join(sim, f"v{v}", "ranges.csv")) as f:
            for row in csv.DictReader(f):
                if row["type_ID1"] == "T" and row["type_ID2"] == "T" and t0 <= float(row["t"]) <= t1:
                    a, b = vehicle_of(int(row["UWB_ID1"])), vehicle_of(int(row["UWB_ID2"]))
                    if victim in (a, b):
                        other = b if a == victim else a
                        counts[other] = counts.get(other, 0) + 1
    return counts


def tag_to_tag_counts(sim, n, t0, t1):
    """Tag-to-tag ranges in [t0, t1] per vehicle, either end (each is in its initiator's ranges.csv)."""
    counts = [0] * n
    for v in range(n):
        with open(os.path.join(sim, f"v{v}", "ranges.csv")) as f:
            for row in csv.DictReader(f):
                if row["type_ID1"] == "T" and row["type_ID2"] == "T" and t0 <= float(row["t"]) <= t1:
                    counts[vehicle_of(int(row["UWB_ID1"]))] += 1
                    counts[vehicle_of(int(row["UWB_ID2"]))] += 1
    return counts


def evaluate(a, dataset, run_dir, calibration, log):
    js = os.path.join(run_dir, "metrics.json")
    cal = ["--calibration", calibration] if os.path.isfile(calibration) else []
    run([os.path.join(a.bin, "meshnav_eval"), "--dataset", dataset, "--run", run_dir, "--no-plots", "--no-baseline",
         "--json", js] + cal, log)
    with open(js) as f:
        return json.load(f)


def window_errors(errors_csv, t0, t1):
    """RMSE, largest position error and mean position NEES over [t0, t1] from meshnav_eval's errors.csv."""
    se, worst, n, nees, n_nees = 0.0, 0.0, 0, 0.0, 0
    with open(errors_csv) as f:
        for row in csv.DictReader(f):
            t = float(row["t"])
            if t0 <= t <= t1:
                e = float(row["ep_norm_m"])
                se += e * e
                worst = max(worst, e)
                n += 1
                if row.get("nees_p"):
                    nees += float(row["nees_p"])
                    n_nees += 1
    return (math.sqrt(se / n) if n else float("nan")), worst, (nees / n_nees if n_nees else float("nan"))


def shared_anchor_nees(shared_csv, truth_yaml, fly_by_ids):
    """id -> NEES of the fleet's shared (CI) belief of each fly-by anchor against the truth (meshnav_run's
    shared_anchors.csv: the covariance intersection of every vehicle's final belief)."""
    if not os.path.isfile(shared_csv):
        return {}
    with open(truth_yaml) as f:
        truth = (yaml.safe_load(f) or {}).get("anchor_positions", {})
    out = {}
    with open(shared_csv) as f:
        for row in csv.DictReader(f):
            i = int(row["id"])
            if i not in fly_by_ids or i not in truth:
                continue
            e = [float(row[k]) - float(x) for k, x in zip("xyz", truth[i])]
            P = [[float(row["pxx"]), float(row["pxy"]), float(row["pxz"])],
                 [float(row["pxy"]), float(row["pyy"]), float(row["pyz"])],
                 [float(row["pxz"]), float(row["pyz"]), float(row["pzz"])]]
            out[i] = quad_inv(P, e)
    return out


def quad_inv(P, e):
    """e^T P^-1 e for a 3x3 symmetric positive definite P (Cramer's rule)."""
    a, b, c = P[0]
    _, d, f_ = P[1]
    g = P[2][2]
    det = a * (d * g - f_ * f_) - b * (b * g - f_ * c) + c * (b * f_ - d * c)
    inv = [[d * g - f_ * f_, c * f_ - b * g, b * f_ - c * d],
           [c * f_ - b * g, a * g - c * c, b * c - a * f_],
           [b * f_ - c * d, b * c - a * f_, a * d - b * b]]
    return sum(e[i] * inv[i][j] * e[j] for i in range(3) for j in range(3)) / det


def contributors(calibration):
    """Fly-by anchor id -> set of vehicles whose tags are references of its calibration."""
    if not os.path.isfile(calibration):
        return {}
    with open(calibration) as f:
        doc = yaml.safe_load(f) or {}
    out = {}
    for an in doc.get("anchors") or []:
        tags = [r for r in an.get("ref_ids", []) if r % 1000 in (99, 100, 105)]
        out[int(an["id"])] = {vehicle_of(t) for t in tags}
    return out


def fly_by(metrics):
    """id -> (initial error, final error, final NEES) of the fly-by anchors in one eval."""
    out = {}
    for an in metrics.get("anchors", {}).get("per_anchor", []):
        if an["known"]:
            continue
        out[an["id"]] = (an["initial"]["error_m"], an["final"]["error_m"], an["final"]["nees"])
    return out


def run_seed(a, seed):
    base = os.path.join(a.out, f"seed{seed}")
    os.makedirs(base, exist_ok=True)
    sim, sim_out = os.path.join(base, "sim"), os.path.join(base, "sim_outage")
    scale = ["--vehicles", str(a.vehicles), "--anchors", str(a.anchors), "--hall", a.hall, "--seed", str(seed)]
    if a.duration > 0:
        scale += ["--duration", repr(a.duration)]
    binp = lambda name: os.path.join(a.bin, name)  # noqa: E731
    run([binp("meshnav_sim")] + scale + ["--out", sim], os.path.join(base, "sim.log"))
    t0, t1 = a.window
    counts = tag_to_tag_counts(sim, a.vehicles, t0, t1)
    victim = max(range(a.vehicles), key=lambda v: (counts[v], -v))
    run([binp("meshnav_sim")] + scale + ["--outage", f"{victim},{t0!r},{t1!r}", "--out", sim_out],
        os.path.join(base, "sim_outage.log"))
    common = ["--allow-lost", "--config", a.config]
    mission = lambda d: ["--mission", os.path.join(d, "mission.yaml")]  # noqa: E731
    runs = [("fleet", [binp("meshnav_run"), "--fleet", os.path.join(sim, "fleet.yaml")] + mission(sim)),
            ("outage_with", [binp("meshnav_run"), "--fleet", os.path.join(sim_out, "fleet.yaml")] + mission(sim_out)),
            ("outage_without", [binp("meshnav_run"), "--fleet", os.path.join(sim_out, "fleet.yaml"),
                                "--no-inter-vehicle-ranges"] + mission(sim_out))]
    runs += [(f"alone_v{v}", [binp("meshnav_run"), "--dataset", os.path.join(sim, f"v{v}")] + mission(sim))
             for v in range(a.vehicles)]
    wall = {}
    for name, cmd in runs:
        start = time.time()
        run(cmd + ["--out", os.path.join(base, name)] + common, os.path.join(base, name + ".log"))
        wall[name] = time.time() - start
    res = {"seed": seed, "victim": victim, "peer_ranges": counts[victim], "wall": wall, "vehicles": [],
           "peers": peer_vehicles(sim, a.vehicles, victim, t0, t1)}
    fleet_cal = os.path.join(base, "fleet", "calibration.yaml")
    fleet_from = contributors(fleet_cal)
    for v in range(a.vehicles):
        ds = os.path.join(sim, f"v{v}")
        mf = evaluate(a, ds, os.path.join(base, "fleet", f"v{v}"), fleet_cal, os.path.join(base, f"eval_fleet_v{v}.log"))
        alone_dir = os.path.join(base, f"alone_v{v}")
        ma = evaluate(a, ds, alone_dir, os.path.join(alone_dir, "calibration.yaml"),
                      os.path.join(base, f"eval_alone_v{v}.log"))
        res["vehicles"].append({"fleet_rmse": mf["pose"]["position"]["rmse_m"], "fleet_anees": mf["pose"]["position"]["anees"],
                                "alone_rmse": ma["pose"]["position"]["rmse_m"], "alone_anees": ma["pose"]["position"]["anees"],
                                "fleet_anchors": fly_by(mf), "alone_anchors": fly_by(ma),
                                "alone_from": contributors(os.path.join(alone_dir, "calibration.yaml"))})
    for mode in ("with", "without"):
        run_dir = os.path.join(base, f"outage_{mode}")
        evaluate(a, os.path.join(sim_out, f"v{victim}"), os.path.join(run_dir, f"v{victim}"),
                 os.path.join(run_dir, "calibration.yaml"), os.path.join(base, f"eval_outage_{mode}.log"))
        res[f"outage_{mode}"] = window_errors(os.path.join(run_dir, f"v{victim}", "errors.csv"), t0, t1)
    # Fly-by anchors: fleet calibration (same for every vehicle: take v0's eval initial error, from calibration.yaml).
    multi, single, nees_all, nees_multi = [], [], [], []
    for an, vs in fleet_from.items():
        fleet_err = next((veh["fleet_anchors"][an][0] for veh in res["vehicles"] if an in veh["fleet_anchors"]), None)
        alone_errs = [res["vehicles"][v]["alone_anchors"][an][0] for v in vs
                      if an in res["vehicles"][v]["alone_anchors"] and an in res["vehicles"][v]["alone_from"]]
        if len(vs) >= 2 and fleet_err is not None and alone_errs:
            multi.append(fleet_err)
            single.append(sum(alone_errs) / len(alone_errs))
        for veh in res["vehicles"]:
            if an in veh["fleet_anchors"] and veh["fleet_anchors"][an][2] is not None:
                ok = veh["fleet_anchors"][an][2] <= NEES_BOUND
                nees_all.append(ok)
                if len(vs) >= 2:
                    nees_multi.append(ok)
    shared = shared_anchor_nees(os.path.join(base, "fleet", "shared_anchors.csv"), os.path.join(sim, "v0", "truth.yaml"),
                                set(fleet_from))
    res["anchors"] = {"n_calibrated": len(fleet_from), "n_multi": sum(1 for vs in fleet_from.values() if len(vs) >= 2),
                      "multi_fleet": multi, "multi_alone": single, "nees_all": nees_all, "nees_multi": nees_multi,
                      "shared_nees": [shared[i] for i in sorted(shared)],
                      "shared_nees_multi": [shared[i] for i in sorted(shared) if len(fleet_from.get(i, ())) >= 2]}
    with open(os.path.join(base, "result.json"), "w") as f:
        json.dump(res, f, indent=1, default=str)
    return res


def mean(xs):
    return sum(xs) / len(xs) if xs else float("nan")


def ok_of(nees):
    """'k / n': how many of the NEES values are <= NEES_BOUND."""
    return f"{sum(1 for x in nees if x <= NEES_BOUND)} / {len(nees)}"


def tables(results, a):
    t0, t1 = a.window
    lines = ["Position per vehicle (fleet with inter-vehicle ranges / alone), RMSE [m] and ANEES:", "",
             "| seed | " + " | ".join(f"v{v} RMSE" for v in range(a.vehicles)) + " | worst | ANEES fleet per vehicle (mean) |",
             "| ---: |" + " ---: |" * (a.vehicles + 2)]
    for r in results:
        cells = [f"{veh['fleet_rmse']:.3f} / {veh['alone_rmse']:.3f}" for veh in r["vehicles"]]
        worst = max(veh["fleet_rmse"] for veh in r["vehicles"])
        per_vehicle = " ".join(f"{veh['fleet_anees']:.2f}" for veh in r["vehicles"])
        lines.append(f"| {r['seed']} | " + " | ".join(cells) +
                     f" | {worst:.3f} | {per_vehicle} "
                     f"({mean([veh['fleet_anees'] for veh in r['vehicles']]):.2f}) |")
    allv = [veh for r in results for veh in r["vehicles"]]
    lines.append(f"| all | {sum(1 for v in allv if v['fleet_rmse'] <= 0.12)} of {len(allv)} vehicles <= 0.12 m; "
                 f"mean {mean([v['fleet_rmse'] for v in allv]):.3f} / {mean([v['alone_rmse'] for v in allv]):.3f} m |" +
                 " |" * (a.vehicles + 1))
    lines += ["", f"Outage: the anchors silent for one vehicle over {t0:g}-{t1:g} s, its position error there "
              "(RMSE / largest [m], mean position NEES) with and without inter-vehicle ranges:", "",
              "| seed | vehicle | tag-to-tag ranges in the window (per neighbour) | with | without |",
              "| ---: | ---: | ---: | ---: | ---: |"]
    for r in results:
        w, wo = r["outage_with"], r["outage_without"]
        per = ", ".join(f"v{k}: {n}" for k, n in sorted(r["peers"].items(), key=lambda kv: int(kv[0])))
        nees = lambda x: f", {x[2]:.2f}" if len(x) > 2 else ""  # noqa: E731 (result.json of older versions: 2 figures)
        lines.append(f"| {r['seed']} | v{r['victim']} | {r['peer_ranges']} ({per}) | {w[0]:.3f} / {w[1]:.3f}{nees(w)} "
                     f"| {wo[0]:.3f} / {wo[1]:.3f}{nees(wo)} |")
    ok = sum(1 for r in results if r["outage_with"][0] <= 0.30)
    lines.append(f"| all | | | {ok} of {len(results)} <= 0.30 m, mean {mean([r['outage_with'][0] for r in results]):.3f} "
                 f"| mean {mean([r['outage_without'][0] for r in results]):.3f} |")
    lines += ["", "Fly-by anchors: calibrated from >= 2 vehicles' tags in the fleet against the same anchors from one "
              "vehicle alone (error when first calibrated [m]); final NEES <= 13.93 of every vehicle's last estimate:", "",
              "| seed | calibrated (from >= 2 vehicles) | error fleet / alone (ratio) | final NEES ok, all | final NEES ok, >= 2 vehicles "
              "| shared (CI) belief NEES ok, all / >= 2 vehicles |",
              "| ---: | ---: | ---: | ---: | ---: | ---: |"]
    for r in results:
        an = r["anchors"]
        mf, ma = mean(an["multi_fleet"]), mean(an["multi_alone"])
        lines.append(f"| {r['seed']} | {an['n_calibrated']} ({an['n_multi']}) | {mf:.3f} / {ma:.3f} ({mf / ma if ma else float('nan'):.2f}) "
                     f"| {sum(an['nees_all'])} / {len(an['nees_all'])} | {sum(an['nees_multi'])} / {len(an['nees_multi'])} "
                     f"| {ok_of(an.get('shared_nees', []))}; {ok_of(an.get('shared_nees_multi', []))} |")
    mf = [x for r in results for x in r["anchors"]["multi_fleet"]]
    ma = [x for r in results for x in r["anchors"]["multi_alone"]]
    na = [x for r in results for x in r["anchors"]["nees_all"]]
    nm = [x for r in results for x in r["anchors"]["nees_multi"]]
    sa = [x <= NEES_BOUND for r in results for x in r["anchors"].get("shared_nees", [])]
    sm = [x <= NEES_BOUND for r in results for x in r["anchors"].get("shared_nees_multi", [])]
    lines.append(f"| all | {len(mf)} compared | {mean(mf):.3f} / {mean(ma):.3f} ({mean(mf) / mean(ma) if ma else float('nan'):.2f}) "
                 f"| {100.0 * mean(na):.1f} % | {100.0 * mean(nm):.1f} % | {100.0 * mean(sa):.1f} % / {100.0 * mean(sm):.1f} % |")
    return lines


def main(argv):
    a = parse_args(argv)
    results = []
    if a.from_results:
        for seed in a.seeds:
            path = os.path.join(a.out, f"seed{seed}", "result.json")
            if not os.path.isfile(path):
                print(f"[fleet-scale-table] no {path}", file=sys.stderr)
                continue
            with open(path) as f:
                r = json.load(f)
            if "peers" not in r:  # result.json of a version without the column
                r["peers"] = peer_vehicles(os.path.join(a.out, f"seed{seed}", "sim"), a.vehicles, r["victim"], *a.window)
            results.append(r)
    for i, seed in enumerate([] if a.from_results else a.seeds):
        print(f"[fleet-scale-table] seed {seed} ({i + 1}/{len(a.seeds)}): 2 simulations, 3 fleet runs, "
              f"{a.vehicles} runs alone, evaluation", flush=True)
        start = time.time()
        try:
            results.append(run_seed(a, seed))
        except (RuntimeError, KeyError, OSError, ValueError) as e:
            print(f"[fleet-scale-table] seed {seed} FAILED: {e}", file=sys.stderr)
            if not a.keep_going:
                return 1
            continue
        print(f"[fleet-scale-table] seed {seed} done in {time.time() - start:.0f} s (fleet run "
              f"{results[-1]['wall']['fleet']:.0f} s)", flush=True)
    if not results:
        return 1
    lines = tables(results, a)
    print("\n".join(lines))
    if a.table_md:
        with open(a.table_md, "w") as f:
            f.write("\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
