#!/usr/bin/env python3
"""What the data allows for issue 38's "anchors calibrated from >= 2 vehicles <= 0.7 x the error of the
same anchor from one vehicle" (docs/fleet.md, "What the data allows").

For every fly-by anchor that one seed of `./meshnav fleet-scale-table` (OUT/seedN) calibrated from the
tags of >= 2 vehicles (the fleet's calibration.yaml ref_ids), the anchor is calibrated again offline
with `meshnav_calibrate` (the calibrator's core, config/calibrator.yaml defaults)
  * from each of those vehicles alone (its tags and the anchor mesh, ranges up to the time its alone
    run calibrated the anchor), and
  * from all of them together (every contributing vehicle's tags and the mesh once, ranges up to the
    time of the fleet's calibration),
each with the vehicles' poses taken from
  * truth:    each vehicle's groundtruth.csv (the oracle: no pose error at all), and
  * estimate: the runs' estimate.csv (alone_vK for one vehicle, fleet/vK for all): the check that the
              offline calibration reproduces the pipeline's ratio.
The ratio is computed as fleet_scale_table.py computes it: mean over the anchors of the multi-vehicle
error divided by the mean over the anchors of the mean single-vehicle error.

meshnav_calibrate places tags with one pose history, so several vehicles are given to it as one
dataset whose vehicles follow each other in time: vehicle k's tag ranges and poses are shifted by
k * 1000 s (the anchor is static, so the shift changes nothing but the order), the anchor mesh
(identical in every vehicle's dataset) is taken once, unshifted.

Usage: /usr/bin/python3 tools/analysis/fleet_anchor_oracle.py OUT/seedN [OUT/seedM ...] [--bin DIR]
                                                            [--json FILE] [--self-test]
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
SHIFT_S = 1000.0
TAG_SUFFIXES = (99, 100, 105)  # meshnav_sim --vehicles: tags 99/100/105 + 1000 k


def vehicle_of(tag):
    return tag // 1000


def load_yaml(path):
    with open(path) as f:
        return yaml.load(f, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader)) or {}


def calibrations(path):
    """id -> (t [s], set of contributing vehicles) of a calibration.yaml (the first entry of each id)."""
    out = {}
    if not os.path.isfile(path):
        return out
    for an in load_yaml(path).get("anchors") or []:
        i = int(an["id"])
        if i in out:
            continue
        tags = [r for r in an.get("ref_ids", []) if r % 1000 in TAG_SUFFIXES]
        out[i] = (float(an["t"]), {vehicle_of(t) for t in tags})
    return out


_RANGES = {}


def read_ranges(path, anchor):
    """(header, rows) of ranges.csv, only rows with `anchor` at one end (each file read once)."""
    if path not in _RANGES:
        by_id = {}
        with open(path) as f:
            r = csv.reader(f)
            header = next(r)
            i1, i2 = header.index("UWB_ID1"), header.index("UWB_ID2")
            for row in r:
                for i in {int(row[i1]), int(row[i2])}:
                    by_id.setdefault(i, []).append(row)
        _RANGES[path] = (header, by_id)
    header, by_id = _RANGES[path]
    return header, by_id.get(anchor, [])


def shifted(row, dt):
    return [repr(float(row[0]) + dt)] + row[1:] if dt else row


def write_pose_file(src, dst, dt, append):
    """Copy a pose file (groundtruth.csv or estimate.csv), its first column shifted by dt."""
    with open(src) as f:
        lines = f.read().splitlines()
    body = [ln for ln in lines[1:] if ln.strip()]
    with open(dst, "a" if append else "w") as f:
        if not append:
            f.write(lines[0] + "\n")
        for ln in body:
            t, rest = ln.split(",", 1)
            f.write(f"{float(t) + dt!r},{rest}\n")


def merged_dataset(d, sim, vehicles, anchor, t_end, poses, mesh=True):
    """A dataset folder `d` holding `vehicles` (list of (index, pose file)) one after another in time:
    their tag ranges to `anchor` up to t_end, the mesh ranges of `anchor` once (none without `mesh`),
    the union of their setups."""
    os.makedirs(d, exist_ok=True)
    setup = load_yaml(os.path.join(sim, f"v{vehicles[0][0]}", "setup.yaml"))
    rows = None
    for k, (v, pose_file) in enumerate(vehicles):
        vs = load_yaml(os.path.join(sim, f"v{v}", "setup.yaml"))
        if k:
            setup["rel_tag_positions"].update(vs.get("rel_tag_positions") or {})
            have = {frozenset(b["ids"]) for b in setup.get("pair_biases") or []}
            setup.setdefault("pair_biases", []).extend(b for b in vs.get("pair_biases") or []
                                                      if frozenset(b["ids"]) not in have)
        header, rs = read_ranges(os.path.join(sim, f"v{v}", "ranges.csv"), anchor)
        t1, t2 = header.index("type_ID1"), header.index("type_ID2")
        if rows is None:
            rows = [header] + [r for r in rs if mesh and r[t1] == "A" and r[t2] == "A" and float(r[0]) <= t_end]
        i1, i2 = header.index("UWB_ID1"), header.index("UWB_ID2")
        own_tag = lambda r: any(typ == "T" and vehicle_of(int(i)) == v  # noqa: E731
                                for typ, i in ((r[t1], r[i1]), (r[t2], r[i2])))
        rows += [shifted(r, k * SHIFT_S) for r in rs if own_tag(r) and float(r[0]) <= t_end]
        write_pose_file(pose_file, os.path.join(d, poses), k * SHIFT_S, append=k > 0)
    # Tag-to-tag rows never involve the anchor; the mesh first, then each vehicle in its time slot.
    body = sorted(rows[1:], key=lambda r: float(r[0]))
    with open(os.path.join(d, "ranges.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(rows[0])
        w.writerows(body)
    with open(os.path.join(d, "setup.yaml"), "w") as f:
        yaml.safe_dump(setup, f, default_flow_style=None, sort_keys=False)
    return d


def calibrate(bin_dir, d, anchor, poses_name):
    """(p_AinG, σ = sqrt(trace of its covariance) [m]) from meshnav_calibrate; (None, None) when refused."""
    out = os.path.join(d, f"cal_{poses_name}.yaml")
    cmd = [os.path.join(bin_dir, "meshnav_calibrate"), "--dataset", d, "--anchors", str(anchor), "--out", out,
           "--poses", os.path.join(d, poses_name)]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        return None, None
    for an in load_yaml(out).get("anchors") or []:
        if int(an["id"]) == anchor and an.get("p_AinG") is not None:
            cov = [float(x) for x in an["p_AinG_cov"]]
            return [float(x) for x in an["p_AinG"]], math.sqrt(cov[0] + cov[4] + cov[8])
    return None, None


def tag_ranges(d):
    """Tag-to-anchor rows of a merged dataset's ranges.csv."""
    with open(os.path.join(d, "ranges.csv")) as f:
        return sum(1 for r in csv.DictReader(f) if "T" in (r["type_ID1"], r["type_ID2"]))


def error(p, truth):
    return math.dist(p, truth) if p is not None else None


def one_seed(seed_dir, bin_dir, work, modes=("truth", "estimate"), mesh=True):
    """Per anchor calibrated in the fleet from >= 2 vehicles: its error [m] and the calibrator's σ [m]
    from all contributing vehicles (`*_multi`) and from each alone (`*_single`, by vehicle; None when
    meshnav_calibrate refused), for each pose source in `modes`, and the tag ranges each used."""
    sim = os.path.join(seed_dir, "sim")
    truth = {int(k): v for k, v in load_yaml(os.path.join(sim, "v0", "truth.yaml"))["anchor_positions"].items()}
    fleet = calibrations(os.path.join(seed_dir, "fleet", "calibration.yaml"))
    n = len([x for x in os.listdir(sim) if x.startswith("v") and os.path.isdir(os.path.join(sim, x))])
    alone = {v: calibrations(os.path.join(seed_dir, f"alone_v{v}", "calibration.yaml")) for v in range(n)}
    rows = []
    for anchor, (t_fleet, vs) in sorted(fleet.items()):
        if len(vs) < 2:
            continue
        # As fleet_scale_table.py: the vehicles that contributed in the fleet and calibrated it alone
        # from their own tags.
        singles = [v for v in sorted(vs) if anchor in alone[v] and v in alone[v][anchor][1]]
        if not singles:
            continue
        row = {"anchor": anchor, "vehicles": sorted(vs), "singles": singles}
        for mode, fleet_pose, alone_pose in (("truth", lambda v: os.path.join(sim, f"v{v}", "groundtruth.csv"),
                                              lambda v: os.path.join(sim, f"v{v}", "groundtruth.csv")),
                                             ("estimate", lambda v: os.path.join(seed_dir, "fleet", f"v{v}", "estimate.csv"),
                                              lambda v: os.path.join(seed_dir, f"alone_v{v}", "estimate.csv"))):
            if mode not in modes:
                row[f"{mode}_multi"], row[f"{mode}_multi_sigma"] = None, None
                row[f"{mode}_single"], row[f"{mode}_single_sigma"] = {}, {}
                continue
            name = "groundtruth.csv" if mode == "truth" else "estimate.csv"
            d = merged_dataset(os.path.join(work, f"a{anchor}_{mode}_all"), sim,
                               [(v, fleet_pose(v)) for v in sorted(vs)], anchor, t_fleet, name, mesh)
            p, sigma = calibrate(bin_dir, d, anchor, name)
            row[f"{mode}_multi"], row[f"{mode}_multi_sigma"] = error(p, truth[anchor]), sigma
            row["tag_ranges_multi"] = tag_ranges(d)
            errs, sigmas, counts = {}, {}, {}
            for v in singles:
                d = merged_dataset(os.path.join(work, f"a{anchor}_{mode}_v{v}"), sim, [(v, alone_pose(v))],
                                   anchor, alone[v][anchor][0], name, mesh)
                p, sigmas[v] = calibrate(bin_dir, d, anchor, name)
                errs[v], counts[v] = error(p, truth[anchor]), tag_ranges(d)
            row[f"{mode}_single"], row[f"{mode}_single_sigma"], row["tag_ranges_single"] = errs, sigmas, counts
        rows.append(row)
    return rows


def ratio(rows, mode, what=""):
    """fleet_scale_table.py's ratio over the anchors whose every calibration succeeded (what: "" the
    errors, "_sigma" the calibrator's own σ)."""
    multi, single = [], []
    for r in rows:
        s = [e for e in r[f"{mode}_single{what}"].values() if e is not None]
        if r[f"{mode}_multi{what}"] is None or not s:
            continue
        multi.append(r[f"{mode}_multi{what}"])
        single.append(sum(s) / len(s))
    if not multi:
        return float("nan"), float("nan"), float("nan"), 0
    m, s = sum(multi) / len(multi), sum(single) / len(single)
    return m, s, m / s, len(multi)


def sigma_cell(rows):
    m, s, r, n = ratio(rows, "truth", "_sigma")
    return f"{m:.3f} / {s:.3f} ({r:.2f})"


def counts_cell(rows):
    multi = [r["tag_ranges_multi"] for r in rows]
    single = [x for r in rows for x in r["tag_ranges_single"].values()]
    return f"{sum(multi) / max(1, len(multi)):.0f} / {sum(single) / max(1, len(single)):.0f}"


def pipeline_ratio(seed_dir):
    """The ratio of the table from result.json (fleet_scale_table.py's multi_fleet / multi_alone)."""
    with open(os.path.join(seed_dir, "result.json")) as f:
        an = json.load(f)["anchors"]
    m, s = sum(an["multi_fleet"]) / len(an["multi_fleet"]), sum(an["multi_alone"]) / len(an["multi_alone"])
    return m, s, m / s, len(an["multi_fleet"])


def self_test(bin_dir):
    """merged_dataset on a tiny two-vehicle folder: shifted times, one mesh, the union of the tags."""
    with tempfile.TemporaryDirectory() as tmp:
        sim = os.path.join(tmp, "sim")
        for v in (0, 1):
            d = os.path.join(sim, f"v{v}")
            os.makedirs(d)
            with open(os.path.join(d, "setup.yaml"), "w") as f:
                yaml.safe_dump({"imu_id": 1, "rel_tag_positions": {1000 * v + 100: [0.1, 0, 0]},
                                "pair_biases": [{"ids": [101, 102], "gamma": 0.1},
                                                {"ids": [1000 * v + 100, 102], "gamma": 0.2}]}, f)
            with open(os.path.join(d, "ranges.csv"), "w") as f:
                f.write("t,range_raw,range_corr,R,UWB_ID1,UWB_ID2,type_ID1,type_ID2,LOS\n")
                f.write("1.0,5,5,0.01,101,102,A,A,1\n")
                f.write(f"2.0,4,4,0.01,{1000 * v + 100},101,T,A,1\n")
                f.write(f"9.0,4,4,0.01,{1000 * v + 100},101,T,A,1\n")
            with open(os.path.join(d, "groundtruth.csv"), "w") as f:
                f.write("#t,tx,ty,tz,qx,qy,qz,qw\n0.0,0,0,0,0,0,0,1\n10.0,1,0,0,0,0,0,1\n")
        d = merged_dataset(os.path.join(tmp, "m"), sim, [(0, os.path.join(sim, "v0", "groundtruth.csv")),
                                                        (1, os.path.join(sim, "v1", "groundtruth.csv"))],
                           101, 5.0, "groundtruth.csv")
        with open(os.path.join(d, "ranges.csv")) as f:
            rows = list(csv.DictReader(f))
        assert [(float(r["t"]), r["UWB_ID1"]) for r in rows] == [(1.0, "101"), (2.0, "100"), (1002.0, "1100")], rows
        with open(os.path.join(d, "groundtruth.csv")) as f:
            ts = [float(ln.split(",")[0]) for ln in f.read().splitlines()[1:]]
        assert ts == [0.0, 10.0, 1000.0, 1010.0], ts
        d2 = merged_dataset(os.path.join(tmp, "n"), sim, [(1, os.path.join(sim, "v1", "groundtruth.csv"))],
                            101, 5.0, "groundtruth.csv", mesh=False)
        with open(os.path.join(d2, "ranges.csv")) as f:
            assert [(float(r["t"]), r["UWB_ID1"]) for r in csv.DictReader(f)] == [(2.0, "1100")]
        setup = load_yaml(os.path.join(d, "setup.yaml"))
        assert set(setup["rel_tag_positions"]) == {100, 1100}, setup
        # The anchor pair both setups list is given once (the setup loader refuses a repeated pair).
        assert sorted(tuple(b["ids"]) for b in setup["pair_biases"]) == [(100, 102), (101, 102), (1100, 102)], setup
    print("fleet_anchor_oracle self-test: ok")
    return 0


def main(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("seeds", nargs="*", help="OUT/seedN folders of ./meshnav fleet-scale-table")
    p.add_argument("--bin", default=os.path.join(os.environ.get("MESHNAV_BUILD_DIR", os.path.join(ROOT, "build")), "bin"))
    p.add_argument("--json", default="", help="also write every anchor's figures here")
    p.add_argument("--truth-only", action="store_true", help="only the true poses (no check against the estimates)")
    p.add_argument("--no-mesh", action="store_true",
                   help="leave out the anchor mesh (the ranges every calibration of the anchor shares): tags only")
    p.add_argument("--self-test", action="store_true")
    a = p.parse_args(argv)
    if a.self_test:
        return self_test(a.bin)
    if not a.seeds:
        p.error("give at least one OUT/seedN folder")
    allrows = {}
    print("| seed | anchors | pipeline: fleet / alone (ratio) | offline, estimates | offline, **true poses** "
          "| true poses: the calibrator's σ | tag ranges per anchor: all / one vehicle (mean) |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    for seed_dir in a.seeds:
        work = tempfile.mkdtemp(prefix="fleet_anchor_oracle_")
        try:
            rows = one_seed(seed_dir, a.bin, work, ("truth",) if a.truth_only else ("truth", "estimate"),
                            mesh=not a.no_mesh)
        finally:
            shutil.rmtree(work, ignore_errors=True)
        allrows[seed_dir] = rows
        pm, ps, pr, pn = pipeline_ratio(seed_dir)
        em, es, er, en = ratio(rows, "estimate")
        tm, ts, tr, tn = ratio(rows, "truth")
        print(f"| {os.path.basename(os.path.normpath(seed_dir))} | {pn} | {pm:.3f} / {ps:.3f} ({pr:.2f}) | "
              f"{em:.3f} / {es:.3f} ({er:.2f}, {en}) | {tm:.3f} / {ts:.3f} ({tr:.2f}, {tn}) | "
              f"{sigma_cell(rows)} | {counts_cell(rows)} |", flush=True)
    flat = [r for rows in allrows.values() for r in rows]
    em, es, er, en = ratio(flat, "estimate")
    tm, ts, tr, tn = ratio(flat, "truth")
    print(f"| all | | | {em:.3f} / {es:.3f} ({er:.2f}, {en}) | {tm:.3f} / {ts:.3f} ({tr:.2f}, {tn}) | "
          f"{sigma_cell(flat)} | {counts_cell(flat)} |")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(allrows, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
