#!/usr/bin/python3
"""What limits the refinement of fly-by anchors (issue 10): oracle batch estimates per anchor.

For every anchor of a run's calibration.yaml (the S2 mission: calibrated at t_cal, then a state of
the filter) this prints its initial (calibrated) and final (filter) error next to batch weighted
least-squares estimates of the same anchor from the same ranges:

  free   ranges after t_cal, TRUE tag positions, gamma ~ N(0, 0.25^2), position free
         (what the flight after the join tells on its own)
  joint  ranges after t_cal, TRUE tag positions, the calibration's joint prior on [p, gamma]
         (what a filter starting from the calibration could reach with a perfect trajectory)
  est    as joint, tag positions from the filter's estimate.csv (its own trajectory)
  all    every range from t = 0, TRUE tag positions, gamma ~ N(0, 0.25^2)  (the S1 bound)

Unknowns: p_AinG and one gamma per reference (tags and exactly known anchors; ranges to other
calibrated anchors are left out as in the filter). beta from truth.yaml, sigma_d 0.1 m, outliers
dropped with the truth (|z - beta d - gamma| > 0.4 m at the true values), Gauss-Newton to 1e-9 m.
Tag positions p_TinG = p_IinG + R_ItoG p_TinI (position interpolated, orientation of the nearer
sample).

  anchor_refinement_oracle.py --dataset DIR --run DIR        one run (a table per anchor)
  anchor_refinement_oracle.py --batch OUT                    OUT/seedNN/{dataset,run} of paper-table
  anchor_refinement_oracle.py --two-pass-dataset SRC DST --run DIR [--sigma 0.3]
      writes DST: SRC with the run's calibrated anchors as known-but-uncertain setup anchors
      (p_AinG = calibration, sigma per axis --sigma), tag-anchor gamma unknown (N(0, 0.25^2)) and
      the ranges between such an anchor and another anchor dropped; `meshnav_run --no-calibration`
      on DST estimates the anchors jointly with the pose from t = 0
      (docs/decisions/003-rerun-on-anchor-join.md).
  anchor_refinement_oracle.py --self-test                    noise-free ranges: exact recovery
"""

import argparse
import csv
import glob
import os
import sys

import numpy as np
import yaml

SIGMA_D = 0.1          # range noise sigma [m]
GAMMA_PRIOR = 0.25     # generic prior sigma of a pair bias [m] (the calibrator's)
OUTLIER_M = 0.4        # truth residual beyond which a range is an outlier [m]


def quat_to_rot(q):
    """R_ItoG from a unit quaternion (x, y, z, w)."""
    x, y, z, w = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def pose_at(traj, t):
    """p_IinG (linear) and R_ItoG (nearer sample) at t from rows t, x, y, z, qx, qy, qz, qw."""
    i = min(max(int(np.searchsorted(traj[:, 0], t)), 1), len(traj) - 1)
    t0, t1 = traj[i - 1, 0], traj[i, 0]
    a = 0.0 if t1 == t0 else (t - t0) / (t1 - t0)
    p = (1 - a) * traj[i - 1, 1:4] + a * traj[i, 1:4]
    return p, quat_to_rot(traj[i - 1 if a < 0.5 else i, 4:8])


def find_pair(pairs, a, b):
    for e in pairs or []:
        if {int(e["ids"][0]), int(e["ids"][1])} == {a, b}:
            return e
    raise KeyError(f"pair {a}-{b} not in truth.yaml")


def read_ranges(path):
    with open(path) as f:
        return [(float(r["t"]), float(r["range_raw"]), int(r["UWB_ID1"]), int(r["UWB_ID2"]))
                for r in csv.DictReader(f)]


def gather(anchor, refs, ranges, t_from, t_to, tags, known, traj, gt, truth):
    """Rows (reference index, reference position, z, beta) of the anchor's inlier ranges."""
    p_true = np.array(truth["anchor_positions"][anchor], float)
    rows = []
    for t, z, a, b in ranges:
        if not (t_from < t <= t_to) or anchor not in (a, b):
            continue
        o = b if a == anchor else a
        if o not in refs:
            continue
        if o in tags:
            p, R = pose_at(traj, t)
            pr = p + R @ tags[o]
            pg, Rg = pose_at(gt, t)
            pr_true = pg + Rg @ tags[o]
        else:
            pr = pr_true = known[o]
        tp = find_pair(truth["pair_biases"], anchor, o)
        if abs(z - tp["beta"] * np.linalg.norm(p_true - pr_true) - tp["gamma"]) > OUTLIER_M:
            continue
        rows.append((refs.index(o), pr, z, float(tp["beta"])))
    return rows


def solve(rows, n_ref, x0, prior_info, prior_mean):
    """Gauss-Newton on [p, gamma_1..n] with the prior (info matrix, mean); returns x, covariance."""
    x = x0.copy()
    for _ in range(20):
        H = prior_info.copy()
        g = prior_info @ (prior_mean - x)
        for k, pr, z, beta in rows:
            d = np.linalg.norm(x[:3] - pr)
            J = np.zeros(3 + n_ref)
            J[:3] = beta * (x[:3] - pr) / d
            J[3 + k] = 1.0
            r = z - beta * d - x[3 + k]
            H += np.outer(J, J) / SIGMA_D**2
            g += J * r / SIGMA_D**2
        dx = np.linalg.solve(H, g)
        x += dx
        if np.linalg.norm(dx) < 1e-9:
            break
    return x, np.linalg.inv(H)


def generic_prior(n_ref):
    info = np.zeros((3 + n_ref, 3 + n_ref))
    info[3:, 3:] = np.eye(n_ref) / GAMMA_PRIOR**2
    return info


def calibration_prior(entry, keep):
    """Information matrix and mean of the calibration's joint [p, gamma] prior, gamma rows `keep`."""
    ids = [int(r) for r in entry["ref_ids"]]
    n = len(ids)
    P = np.zeros((3 + n, 3 + n))
    P[:3, :3] = np.array(entry["p_AinG_cov"], float).reshape(3, 3)
    if "cov_gamma_p" in entry:
        c = np.array(entry["cov_gamma_p"], float).reshape(n, 3)
        P[3:, :3], P[:3, 3:] = c, c.T
        P[3:, 3:] = np.array(entry["cov_gamma"], float).reshape(n, n)
    else:
        P[3:, 3:] = np.diag(np.array(entry["sigma_const_biases"], float) ** 2)
    sel = [0, 1, 2] + [3 + ids.index(r) for r in keep]
    mean = np.concatenate([np.array(entry["p_AinG"], float),
                           np.array(entry["const_biases"], float)[[ids.index(r) for r in keep]]])
    return np.linalg.inv(P[np.ix_(sel, sel)]), mean


def analyse_run(dataset, run):
    setup = yaml.safe_load(open(os.path.join(dataset, "setup.yaml")))
    truth = yaml.safe_load(open(os.path.join(dataset, "truth.yaml")))
    truth["anchor_positions"] = {int(k): v for k, v in truth["anchor_positions"].items()}
    cal = yaml.safe_load(open(os.path.join(run, "calibration.yaml")))
    gt = np.loadtxt(os.path.join(dataset, "groundtruth.csv"), delimiter=",", comments="#")
    est = np.genfromtxt(os.path.join(run, "estimate.csv"), delimiter=",", skip_header=1)[:, :8]
    anchors_csv = np.genfromtxt(os.path.join(run, "anchors.csv"), delimiter=",", skip_header=1)
    ranges = read_ranges(os.path.join(dataset, "ranges.csv"))
    tags = {int(k): np.array(v, float) for k, v in setup["rel_tag_positions"].items()}
    known = {int(k): np.array(v, float) for k, v in setup["abs_anchor_positions"].items()}
    t_end = ranges[-1][0]
    out = []
    for entry in cal.get("anchors", []) or []:
        a = int(entry["id"])
        p_true = np.array(truth["anchor_positions"][a], float)
        t_cal = float(entry["t"])
        refs = [int(r) for r in entry["ref_ids"] if int(r) in tags or int(r) in known]
        n = len(refs)
        last = anchors_csv[anchors_csv[:, 1] == a][-1]
        res = {"id": a, "initial": np.linalg.norm(np.array(entry["p_AinG"], float) - p_true),
               "final": np.linalg.norm(last[2:5] - p_true)}
        info_c, mean_c = calibration_prior(entry, refs)
        x0 = mean_c.copy()
        after_true = gather(a, refs, ranges, t_cal, t_end, tags, known, gt, gt, truth)
        after_est = gather(a, refs, ranges, t_cal, t_end, tags, known, est, gt, truth)
        every = gather(a, refs, ranges, -np.inf, t_end, tags, known, gt, gt, truth)
        zero = np.concatenate([mean_c[:3], np.zeros(n)])
        for name, rows, info, mean in (("free", after_true, generic_prior(n), zero),
                                       ("joint", after_true, info_c, mean_c),
                                       ("est", after_est, info_c, mean_c),
                                       ("all", every, generic_prior(n), zero)):
            x, C = solve(rows, n, x0, info, mean)
            res[name] = np.linalg.norm(x[:3] - p_true)
            res[name + "_sigma"] = float(np.sqrt(np.trace(C[:3, :3])))
        res["n_after"] = len(after_true)
        out.append(res)
    return out


COLS = ("initial", "final", "free", "joint", "est", "all")


def print_rows(label, rows):
    for r in rows:
        print(f"{label:8s} {r['id']:5d} " + " ".join(f"{r[c]:7.3f}" for c in COLS) + f" {r['n_after']:6d}")


def mean_row(rows):
    return {c: float(np.mean([r[c] for r in rows])) for c in COLS}


def two_pass_dataset(src, dst, run, sigma):
    os.makedirs(dst, exist_ok=True)
    for f in ("imu.csv", "baro.csv", "flight_state.csv", "groundtruth.csv", "truth.yaml", "height.csv"):
        if os.path.exists(os.path.join(src, f)):
            with open(os.path.join(src, f), "rb") as i, open(os.path.join(dst, f), "wb") as o:
                o.write(i.read())
    setup = yaml.safe_load(open(os.path.join(src, "setup.yaml")))
    cal = yaml.safe_load(open(os.path.join(run, "calibration.yaml")))
    new = [int(e["id"]) for e in cal.get("anchors", []) or []]
    setup.setdefault("abs_anchor_sigmas", {})
    setup.setdefault("pair_biases", [])
    for e in cal.get("anchors", []) or []:
        a = int(e["id"])
        setup["abs_anchor_positions"][a] = [float(v) for v in e["p_AinG"]]
        setup["abs_anchor_sigmas"][a] = sigma
        for t in setup["rel_tag_positions"]:
            setup["pair_biases"].append({"ids": [int(t), a], "gamma": 0.0, "beta": 1.0, "sigma": SIGMA_D,
                                         "sigma_gamma": GAMMA_PRIOR, "sigma_beta": 0.0})
    with open(os.path.join(dst, "setup.yaml"), "w") as f:
        yaml.safe_dump(setup, f, default_flow_style=None)
    tags = {int(t) for t in setup["rel_tag_positions"]}
    with open(os.path.join(src, "ranges.csv")) as fi, open(os.path.join(dst, "ranges.csv"), "w", newline="") as fo:
        r, w = csv.reader(fi), csv.writer(fo)
        header = next(r)
        w.writerow(header)
        i1, i2 = header.index("UWB_ID1"), header.index("UWB_ID2")
        for row in r:
            a, b = int(row[i1]), int(row[i2])
            if a not in tags and b not in tags and (a in new or b in new):
                continue
            w.writerow(row)


def self_test():
    """Noise-free ranges from a helix: every estimate recovers p and gamma to 1e-6."""
    rng = np.random.default_rng(3)
    p_true = np.array([-1.8, 0.9, 3.2])
    refs = [100, 101]
    gamma = np.array([0.12, -0.3])
    known = np.array([1.0, -4.0, 0.7])
    rows = []
    for t in np.linspace(0, 60, 300):
        pr = np.array([1.5 * np.cos(0.3 * t), 1.5 * np.sin(0.3 * t), 0.5 + 0.1 * t])
        rows.append((0, pr, np.linalg.norm(p_true - pr) + gamma[0], 1.0))
        rows.append((1, known, np.linalg.norm(p_true - known) + gamma[1], 1.0))
    x0 = np.concatenate([p_true + rng.normal(0, 0.2, 3), [0.0, 0.0]])
    # gamma of the stationary reference is fixed only by its prior: give it the truth as the mean.
    info = np.diag([0, 0, 0, 0, 1e6])
    x, _ = solve(rows, 2, x0, info, np.concatenate([np.zeros(3), [0.0, gamma[1]]]))
    err = np.abs(x - np.concatenate([p_true, gamma])).max()
    print(f"self-test: max error {err:.2e}")
    return 0 if err < 1e-6 else 1


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dataset")
    ap.add_argument("--run")
    ap.add_argument("--batch")
    ap.add_argument("--two-pass-dataset", nargs=2, metavar=("SRC", "DST"))
    ap.add_argument("--sigma", type=float, default=0.3, help="position sigma of the two-pass prior [m]")
    ap.add_argument("--self-test", action="store_true")
    a = ap.parse_args()
    if a.self_test:
        return self_test()
    if a.two_pass_dataset:
        if not a.run:
            ap.error("--two-pass-dataset needs --run")
        two_pass_dataset(*a.two_pass_dataset, a.run, a.sigma)
        return 0
    runs = []
    if a.batch:
        for d in sorted(glob.glob(os.path.join(a.batch, "seed*"))):
            runs.append((os.path.basename(d), os.path.join(d, "dataset"), os.path.join(d, "run")))
    elif a.dataset and a.run:
        runs.append(("run", a.dataset, a.run))
    else:
        ap.error("give --dataset and --run, --batch, --two-pass-dataset or --self-test")
    print("errors [m]: initial = calibration, final = filter; oracles (see --help): free, joint, est, all")
    print(f"{'run':8s} {'id':>5s} " + " ".join(f"{c:>7s}" for c in COLS) + f" {'n_after':>6s}")
    every = []
    for label, ds, run in runs:
        rows = analyse_run(ds, run)
        print_rows(label, rows)
        every += rows
    m = mean_row(every)
    print(f"{'mean':8s} {'':5s} " + " ".join(f"{m[c]:7.3f}" for c in COLS) + f"   ({len(every)} anchors)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
