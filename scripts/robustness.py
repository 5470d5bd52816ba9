#!/usr/bin/python3
"""Robustness sweep (issue 8, item 2): random or listed scenarios through the whole pipeline.

Every scenario is simulated with meshnav_sim (docs/scenarios.md), flown with
`meshnav_run --no-calibration` (known anchors only; with --calibration auto, the unknown anchors
are calibrated fly-by and fused, as `meshnav_run` does without a mission) and evaluated with
`meshnav_eval --json`. Per run: position RMSE [m], max position error after the first 10 s [m],
orientation RMSE [deg], position ANEES, diverged (max error after 10 s > 1 m), recoveries (the
`recovery` counter of the run's status.txt, 0 when absent) and collinear (the estimator warned that
the known anchors' horizontal positions lie nearly on one line: a mirror image across the vertical
plane through it fits the ranges alike); with --calibration auto also the
anchors calibrated of those unknown, the largest final anchor error [m] and final anchor NEES
(3 dof), and a bad anchor (final error > 0.5 m) fails the sweep like a divergence. meshnav_run gets --allow-lost, so a run that ends lost is
still scored; a run that never initialized is REFUSED with the estimator's reason (the designed
answer when the data cannot fix the pose) and is not a divergence. Writes robustness.csv and
error_cdf.png into --out, prints a table, and exits 1 when any run diverged or a process failed
(2 on usage errors).

  robustness.py --runs N --seed S [--jobs 2] [--out DIR] [--strategy S] [--config FILE] [--duration SEC]
                [--calibration off|auto]
  robustness.py --scenarios FILE [--jobs 2] [--out DIR] [--strategy S]
"""

import argparse
import concurrent.futures
import csv
import json
import math
import os
import random
import subprocess
import sys
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TRAJECTORIES = ["spiral", "figure8", "lawnmower", "helix", "hover", "walk"]
LAYOUTS = ["paper", "walls", "one-wall", "ceiling", "random"]
IMU_GRADES = ["consumer", "fc", "tactical"]
DIVERGENCE_M = 1.0      # max position error after SKIP_S that counts as diverged [m]
SKIP_S = 10.0           # initial transient left out of the max error [s]
BAD_ANCHOR_M = 0.5      # final error of a calibrated anchor that counts as a bad anchor [m]
ANCHOR_NEES_BOUND = 13.93  # chi^2(3) at 99.7 %: a final anchor NEES above it is overconfident
SCENARIO_KEYS = {"name", "seed", "trajectory", "hall", "anchor_layout", "tags", "known", "unknown",
                 "sigma_range", "outliers", "drop", "imu_grade", "duration", "bias_max", "nlos", "range_correlation",
                 "range_time_offset", "imu_scale_sigma", "imu_misalignment", "vibration"}


# Largest sigma of the IMU axes' scale error [-] and misalignment [deg] the widened sweep draws per
# grade, a datasheet's order of magnitude: a phone's IMU about 1 % and 0.5 deg, a flight
# controller's (BMI088-like) 0.5 % and 0.25 deg, a tactical unit 0.05 % and 0.05 deg.
IMU_AXIS_ERRORS = {"consumer": (0.01, 0.5), "fc": (0.005, 0.25), "tactical": (0.0005, 0.05)}


def pick(rng, items):
    """One of `items`, from one uniform draw (independent of the random module's choice())."""
    return items[min(int(rng.random() * len(items)), len(items) - 1)]


def uniform(rng, lo, hi, digits):
    return round(lo + (hi - lo) * rng.random(), digits)


def draw_scenarios(runs, seed, duration_s, widened=False):
    """`runs` scenarios drawn deterministically from `seed` over the sweep's space. `widened`: the
    range errors of real hardware too (issue 34): NLOS excess 0.2 m + Exp(0.3 m) instead of
    U(0.5, 3) m, a pair's error correlated over U(0, 0.3) s, range stamps U(-0.05, 0.05) s late
    against the IMU clock, and IMU axes with scale errors and misalignments of sigma up to its grade's
    (IMU_AXIS_ERRORS); the other draws are the same."""
    rng = random.Random(seed)
    wide_rng = random.Random("widened-%d" % seed)  # its own stream: the other draws stay the plain sweep's
    clock_rng = random.Random("widened-clock-%d" % seed)  # and one more: the correlation draws stay as they were
    imu_rng = random.Random("widened-imu-%d" % seed)  # and the IMU's axes their own
    out = []
    for i in range(runs):
        layout = pick(rng, LAYOUTS)
        known = 3 + int(rng.random() * 3)
        sc = {
            "name": "run%03d" % (i + 1),
            "seed": 1 + int(rng.random() * 1_000_000),
            "trajectory": pick(rng, TRAJECTORIES),
            "hall": [uniform(rng, 6.0, 12.0, 1), uniform(rng, 6.0, 12.0, 1), uniform(rng, 3.0, 8.0, 1)],
            "anchor_layout": layout,
            "tags": 1 + int(rng.random() * 3),
            "known": known,
            "unknown": min(int(rng.random() * 5), 9 - known),
            "sigma_range": uniform(rng, 0.10, 0.20, 3),
            "outliers": uniform(rng, 0.0, 0.15, 3),
            "drop": uniform(rng, 0.0, 0.05, 3),
            "imu_grade": pick(rng, IMU_GRADES),
            "duration": duration_s,
        }
        if widened:
            sc["nlos"] = "exponential"
            sc["range_correlation"] = uniform(wide_rng, 0.0, 0.3, 3)
            sc["range_time_offset"] = uniform(clock_rng, -0.05, 0.05, 3)
            scale_max, misalignment_max_deg = IMU_AXIS_ERRORS[sc["imu_grade"]]
            sc["imu_scale_sigma"] = uniform(imu_rng, 0.0, scale_max, 5)
            sc["imu_misalignment"] = uniform(imu_rng, 0.0, misalignment_max_deg, 3)
        out.append(sc)
    return out


def load_scenarios(path):
    """Scenarios of a YAML file: `defaults: {...}` and `scenarios: [{name: ..., ...}, ...]`."""
    import yaml
    with open(path) as f:
        doc = yaml.safe_load(f)
    if not isinstance(doc, dict) or not isinstance(doc.get("scenarios"), list):
        raise ValueError("%s: expected a mapping with a 'scenarios' list" % path)
    defaults = doc.get("defaults") or {}
    out = []
    for k, entry in enumerate(doc["scenarios"]):
        sc = dict(defaults)
        sc.update(entry)
        unknown = set(sc) - SCENARIO_KEYS
        if unknown:
            raise ValueError("%s: scenario %d: unknown keys %s" % (path, k + 1, sorted(unknown)))
        if "name" not in sc:
            raise ValueError("%s: scenario %d has no name" % (path, k + 1))
        out.append(sc)
    names = [s["name"] for s in out]
    if len(set(names)) != len(names):
        raise ValueError("%s: scenario names must be unique" % path)
    return out


def sim_args(sc):
    """meshnav_sim options of a scenario."""
    flags = [("seed", "seed"), ("trajectory", "trajectory"), ("anchor_layout", "anchor-layout"), ("tags", "tags"),
             ("known", "known"), ("unknown", "unknown"), ("sigma_range", "sigma-range"), ("outliers", "outliers"),
             ("drop", "drop"), ("imu_grade", "imu-grade"), ("duration", "duration"), ("bias_max", "bias-max"),
             ("nlos", "nlos"), ("range_correlation", "range-correlation"), ("range_time_offset", "range-time-offset"),
             ("imu_scale_sigma", "imu-scale-sigma"), ("imu_misalignment", "imu-misalignment"),
             ("vibration", "vibration")]
    args = []
    for key, flag in flags:
        if key in sc and sc[key] is not None:
            args += ["--" + flag, str(sc[key])]
    if sc.get("hall"):
        args += ["--hall", ",".join(str(v) for v in sc["hall"])]
    return args


def read_errors(path):
    """(t, position error norm) of every evaluated sample of meshnav_eval's errors.csv."""
    rows = []
    with open(path) as f:
        for r in csv.DictReader(f):
            rows.append((float(r["t"]), float(r["ep_norm_m"])))
    return rows


def read_counter(path, name):
    """Counter `name` of status.txt (counters: block), 0 when absent or the file is missing."""
    if not os.path.exists(path):
        return 0
    in_counters = False
    with open(path) as f:
        for line in f:
            if line.startswith("counters:"):
                in_counters = True
                continue
            if in_counters and not line.startswith("  "):
                in_counters = False
            if in_counters and line.strip().startswith(name + ":"):
                return int(float(line.split(":", 1)[1]))
    return 0


def read_recoveries(path):
    """The `recovery` counter of status.txt, 0 when absent."""
    return read_counter(path, "recovery")


def anchor_metrics(m):
    """Calibrated anchors of meshnav_eval's JSON: their count, largest final error [m] and NEES."""
    est = [a for a in (m.get("anchors") or {}).get("per_anchor", []) if not a.get("known", True)]
    errs = [a["final"]["error_m"] for a in est if a.get("final") and a["final"].get("error_m") is not None]
    nees = [a["final"]["nees"] for a in est if a.get("final") and a["final"].get("nees") is not None]
    return {"anchors_calibrated": len(est), "anchor_err_max_m": max(errs) if errs else float("nan"),
            "anchor_nees_max": max(nees) if nees else float("nan"),
            "anchor_errors_m": errs, "anchor_nees": nees}


def metrics_of(metrics_json, errors_csv, status_txt):
    """The sweep's figures of one evaluated run; raises when the run has no pose metrics."""
    with open(metrics_json) as f:
        m = json.load(f)
    pose = m.get("pose")
    if not pose:
        raise RuntimeError("meshnav_eval found no pose estimates to evaluate")
    errors = read_errors(errors_csv)
    t0 = errors[0][0] if errors else 0.0
    late = [e for t, e in errors if t - t0 >= SKIP_S]
    max_late = max(late) if late else float("nan")
    return {
        "pos_rmse_m": pose["position"]["rmse_m"],
        "max_err_after_10s_m": max_late,
        "ori_rmse_deg": pose["orientation"]["rmse_deg"],
        "pos_anees": pose["position"].get("anees", float("nan")),
        "diverged": not (max_late <= DIVERGENCE_M),
        "recoveries": read_recoveries(status_txt),
        # The estimator's start-up warning (estimator/uwb/anchor_layout.h): the known anchors lie
        # nearly on one line, so the position across the vertical plane through it is weakly fixed.
        "collinear": read_counter(status_txt, "known_anchors_nearly_collinear") > 0,
        "errors": late,
        **anchor_metrics(m),
    }


def read_refusal(status_txt):
    """The estimator's reason when it never initialized (status.txt `initialized: false`), else None.

    A refusal is the designed answer when the data cannot fix the pose (one tag at rest, coplanar
    anchors mirroring it, no motion): it is reported as REFUSED, not as a divergence."""
    fields = {}
    with open(status_txt) as f:
        for line in f:
            if ":" in line and not line.startswith(" "):
                k, v = line.split(":", 1)
                fields[k.strip()] = v.strip().strip('"')
    if fields.get("initialized") == "false":
        return fields.get("health_reason", "no reason given")
    return None


def run_command(cmd, log_path):
    with open(log_path, "w") as log:
        log.write("$ " + " ".join(cmd) + "\n")
        log.flush()
        return subprocess.call(cmd, stdout=log, stderr=subprocess.STDOUT)


def run_scenario(sc, out_root, bin_dir, strategy, config=None, calibration="off"):
    """Simulate, run, evaluate one scenario; returns a result dict (never raises)."""
    base = os.path.join(out_root, sc["name"])
    dataset, run = os.path.join(base, "dataset"), os.path.join(base, "run")
    os.makedirs(base, exist_ok=True)
    start = time.time()
    result = {"scenario": sc, "ok": False, "refused": False, "error": "", "wall_s": 0.0}
    steps = [
        ("meshnav_sim", [os.path.join(bin_dir, "meshnav_sim"), "--out", dataset] + sim_args(sc)),
        # --allow-lost: a run that ends lost is still evaluated (and counts as diverged by its error).
        ("meshnav_run", [os.path.join(bin_dir, "meshnav_run"), "--dataset", dataset, "--out", run, "--allow-lost"]
         + (["--no-calibration"] if calibration == "off" else [])
         + (["--strategy", strategy] if strategy else []) + (["--config", config] if config else [])),
        ("meshnav_eval", [os.path.join(bin_dir, "meshnav_eval"), "--dataset", dataset, "--run", run, "--no-plots",
                          "--json", os.path.join(run, "metrics.json")]),
    ]
    for name, cmd in steps:
        rc = run_command(cmd, os.path.join(base, name + ".log"))
        if rc != 0:
            result["error"] = "%s exited %d (see %s)" % (name, rc, os.path.join(base, name + ".log"))
            break
        if name == "meshnav_run":
            refusal = read_refusal(os.path.join(run, "status.txt"))
            if refusal is not None:
                result["refused"] = True
                result["error"] = "never initialized: " + refusal
                break
    else:
        try:
            result.update(metrics_of(os.path.join(run, "metrics.json"), os.path.join(run, "errors.csv"),
                                     os.path.join(run, "status.txt")))
            result["ok"] = True
        except (OSError, ValueError, KeyError, RuntimeError) as e:
            result["error"] = "evaluation: %s" % e
    result["wall_s"] = time.time() - start
    return result


def hall_text(sc):
    return "x".join("%g" % v for v in sc["hall"]) if sc.get("hall") else "paper"


def fmt(v, digits):
    return "nan" if v is None or (isinstance(v, float) and math.isnan(v)) else ("%.*f" % (digits, v))


COLUMNS = ["name", "trajectory", "hall_m", "layout", "tags", "known", "unknown", "sigma_m", "outliers", "drop",
           "imu", "pos_rmse_m", "max_err_10s_m", "ori_rmse_deg", "pos_anees", "diverged", "recoveries",
           "collinear", "status"]
# With --calibration auto, before "status": anchors calibrated of those unknown, the largest final
# anchor error and final anchor NEES of the run.
ANCHOR_COLUMNS = ["anchors", "anchor_err_max_m", "anchor_nees_max"]


def columns(calibration):
    return COLUMNS[:-1] + ANCHOR_COLUMNS + COLUMNS[-1:] if calibration == "auto" else COLUMNS


def is_bad_anchor_run(r):
    return r["ok"] and r.get("anchor_err_max_m", float("nan")) > BAD_ANCHOR_M


def row_of(r, calibration="off"):
    row = base_row_of(r)
    if calibration != "auto":
        return row
    sc, ok = r["scenario"], r["ok"]
    anchors = ["%d/%d" % (r["anchors_calibrated"], sc.get("unknown", 5)), fmt(r["anchor_err_max_m"], 3),
               fmt(r["anchor_nees_max"], 1)] if ok else ["-", "-", "-"]
    return row[:-1] + anchors + row[-1:]


def base_row_of(r):
    sc = r["scenario"]
    ok = r["ok"]
    return [sc["name"], sc.get("trajectory", "spiral"), hall_text(sc), sc.get("anchor_layout", "paper"),
            str(sc.get("tags", 2)), str(sc.get("known", 4)), str(sc.get("unknown", 5)),
            fmt(sc.get("sigma_range", 0.1), 3), fmt(sc.get("outliers", 0.05), 3), fmt(sc.get("drop", 0.02), 3),
            sc.get("imu_grade", "fc"),
            fmt(r["pos_rmse_m"], 3) if ok else "-", fmt(r["max_err_after_10s_m"], 3) if ok else "-",
            fmt(r["ori_rmse_deg"], 2) if ok else "-", fmt(r["pos_anees"], 1) if ok else "-",
            ("yes" if r["diverged"] else "no") if ok else "-", str(r["recoveries"]) if ok else "-",
            ("yes" if r["collinear"] else "no") if ok else "-",
            "ok" if ok else ("REFUSED: " if r.get("refused") else "FAILED: ") + r["error"]]


def print_table(results, calibration="off"):
    cols = columns(calibration)
    rows = [cols] + [row_of(r, calibration) for r in results]
    widths = [max(len(row[i]) for row in rows) for i in range(len(cols))]
    text_columns = {0, 1, 2, 3, 10, len(cols) - 1}  # left-aligned; numbers right-aligned
    for k, row in enumerate(rows):
        cells = [c.ljust(w) if i in text_columns else c.rjust(w) for i, (c, w) in enumerate(zip(row, widths))]
        print("  ".join(cells).rstrip())
        if k == 0:
            print("  ".join("-" * w for w in widths))


def write_csv(results, path, calibration="off"):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(columns(calibration) + ["seed", "duration_s", "wall_s"])
        for r in results:
            sc = r["scenario"]
            w.writerow(row_of(r, calibration) + [sc.get("seed", 1), sc.get("duration", ""), "%.1f" % r["wall_s"]])


def write_cdf_png(results, path):
    """CDF of the position error norm after the first 10 s: one thin line per run, all runs pooled bold."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("robustness: matplotlib is missing, %s not written" % path, file=sys.stderr)
        return False
    fig, ax = plt.subplots(figsize=(8, 5))
    pooled = []
    for r in results:
        if not r["ok"] or not r["errors"]:
            continue
        e = sorted(r["errors"])
        pooled += e
        ax.plot(e, [(i + 1) / len(e) for i in range(len(e))], lw=0.8, alpha=0.6,
                label="%s (%s)" % (r["scenario"]["name"], r["scenario"].get("trajectory", "spiral")))
    if pooled:
        pooled.sort()
        ax.plot(pooled, [(i + 1) / len(pooled) for i in range(len(pooled))], "k", lw=2.2, label="all runs")
    ax.axvline(DIVERGENCE_M, color="r", ls="--", lw=1, label="divergence threshold %.0f m" % DIVERGENCE_M)
    ax.set_xscale("log")
    ax.set_xlabel("position error after the first %.0f s [m]" % SKIP_S)
    ax.set_ylabel("fraction of samples")
    ax.set_title("meshnav robustness sweep: position error CDF")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2, loc="lower right")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return True


def parse_args(argv):
    p = argparse.ArgumentParser(prog="meshnav robustness", description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--runs", type=int, help="number of random scenarios (with --seed)")
    p.add_argument("--seed", type=int, default=1, help="seed of the scenario draw (default 1)")
    p.add_argument("--scenarios", help="YAML file with a fixed list of scenarios (instead of --runs)")
    p.add_argument("--jobs", type=int, default=2, help="runs in parallel (default 2)")
    p.add_argument("--out", default=os.path.join(ROOT, "out", "robustness"), help="output folder (default out/robustness)")
    p.add_argument("--strategy", help="meshnav_run --strategy, checked by meshnav_run (default: its own)")
    p.add_argument("--config", help="estimator options YAML for meshnav_run --config (default: its built-in defaults)")
    p.add_argument("--widened", action="store_true",
                   help="with --runs: draw real hardware's range errors too (NLOS excess 0.2 m + Exp(0.3 m), "
                        "errors correlated over U(0, 0.3) s, range stamps U(-0.05, 0.05) s late against the IMU, "
                        "IMU axis scale errors and misalignments up to the grade's (consumer 1 %% and 0.5 deg); "
                        "docs/robustness.md)")
    p.add_argument("--duration", type=float, default=90.0, help="sequence length of drawn scenarios [s] (default 90)")
    p.add_argument("--calibration", choices=["off", "auto"], default="off",
                   help="off: known anchors only (default); auto: the unknown anchors are calibrated fly-by and "
                        "fused, and the anchors are scored too")
    p.add_argument("--bin", default=os.path.join(os.environ.get("MESHNAV_BUILD_DIR", os.path.join(ROOT, "build")), "bin"),
                   help="folder of meshnav_sim, meshnav_run, meshnav_eval (default build/bin)")
    p.add_argument("--list", action="store_true", help="print the scenarios as YAML and exit")
    a = p.parse_args(argv)
    if (a.runs is None) == (a.scenarios is None):
        p.error("give either --runs N (with --seed S) or --scenarios FILE")
    if a.runs is not None and a.runs < 1:
        p.error("--runs must be >= 1")
    if a.jobs < 1:
        p.error("--jobs must be >= 1")
    return a


def percentile(values, q):
    """q-th percentile (0..100) with linear interpolation between order statistics."""
    v = sorted(values)
    if not v:
        return float("nan")
    k = (len(v) - 1) * q / 100.0
    lo, hi = int(k), min(int(k) + 1, len(v) - 1)
    return v[lo] + (v[hi] - v[lo]) * (k - lo)


def anchor_summary_lines(results):
    """With --calibration auto: anchors calibrated of those unknown, final anchor errors and NEES."""
    scored = [r for r in results if r["ok"]]
    unknown = sum(int(r["scenario"].get("unknown", 5)) for r in scored)
    errs = [e for r in scored for e in r.get("anchor_errors_m", [])]
    nees = [n for r in scored for n in r.get("anchor_nees", [])]
    if not errs:
        return ["anchors: none calibrated of %d unknown" % unknown]
    return ["anchors: %d calibrated of %d unknown in the scored runs; final error median %.3f m, 95th percentile "
            "%.3f m, max %.3f m; final NEES <= %.2f for %.1f %%; %d runs with a bad anchor (final error > %.1f m)"
            % (len(errs), unknown, percentile(errs, 50), percentile(errs, 95), max(errs), ANCHOR_NEES_BOUND,
               100.0 * sum(n <= ANCHOR_NEES_BOUND for n in nees) / max(1, len(nees)),
               sum(is_bad_anchor_run(r) for r in results), BAD_ANCHOR_M)]


def summary_lines(results):
    """The issue-8 target figures over the scored runs: median and 95th percentile of the
    position RMSE, median position ANEES, median orientation RMSE of runs with two or more tags."""
    scored = [r for r in results if r["ok"]]
    if not scored:
        return ["no scored run"]
    rmse = [r["pos_rmse_m"] for r in scored]
    anees = [r["pos_anees"] for r in scored if r["pos_anees"] == r["pos_anees"]]
    ori2 = [r["ori_rmse_deg"] for r in scored if int(r["scenario"].get("tags", 2)) >= 2]
    return ["scored runs: %d; position RMSE median %.3f m, 95th percentile %.3f m, max %.3f m"
            % (len(scored), percentile(rmse, 50), percentile(rmse, 95), max(rmse)),
            "position ANEES median %.2f (3 if consistent); orientation RMSE median with >= 2 tags %.2f deg (%d runs)"
            % (percentile(anees, 50), percentile(ori2, 50), len(ori2))]


def collinear_lines(results):
    """How many of the diverged runs had known anchors nearly on one line (none when nothing diverged)."""
    diverged = [r for r in results if r["ok"] and r["diverged"]]
    if not diverged:
        return []
    return ["%d of the %d diverged runs have nearly collinear known anchors (column collinear; "
            "docs/robustness.md, \"Nearly collinear known anchors\")" % (sum(r["collinear"] for r in diverged),
                                                                         len(diverged))]


def main(argv):
    a = parse_args(argv)
    try:
        scenarios = load_scenarios(a.scenarios) if a.scenarios else draw_scenarios(a.runs, a.seed, a.duration, a.widened)
    except (OSError, ValueError) as e:
        print("robustness: %s" % e, file=sys.stderr)
        return 2
    if a.list:
        import yaml
        print(yaml.safe_dump({"scenarios": scenarios}, sort_keys=False, default_flow_style=None), end="")
        return 0
    for b in ("meshnav_sim", "meshnav_run", "meshnav_eval"):
        if not os.access(os.path.join(a.bin, b), os.X_OK):
            print("robustness: %s is missing (build first: ./meshnav build)" % os.path.join(a.bin, b), file=sys.stderr)
            return 2
    if a.strategy:  # meshnav_run knows the strategies this build has; ask it once, not 200 times
        probe = subprocess.run([os.path.join(a.bin, "meshnav_run"), "--strategy", a.strategy, "--print-config"],
                               capture_output=True, text=True)
        if probe.returncode != 0:
            print("robustness: %s" % (probe.stderr.strip().splitlines() or ["bad --strategy"])[0], file=sys.stderr)
            return 2
    os.makedirs(a.out, exist_ok=True)
    print("robustness: %d scenarios, %d in parallel, results in %s" % (len(scenarios), a.jobs, a.out), flush=True)
    results, lock = [None] * len(scenarios), threading.Lock()
    with concurrent.futures.ThreadPoolExecutor(max_workers=a.jobs) as pool:
        futures = {pool.submit(run_scenario, sc, a.out, a.bin, a.strategy, a.config, a.calibration): i
                   for i, sc in enumerate(scenarios)}
        for done, fut in enumerate(concurrent.futures.as_completed(futures), 1):
            i = futures[fut]
            r = results[i] = fut.result()
            with lock:
                state = (("DIVERGED" if r["diverged"] else "ok") if r["ok"]
                         else ("REFUSED: " if r["refused"] else "FAILED: ") + r["error"])
                figures = ("rmse %.3f m, max after 10 s %.3f m, " % (r["pos_rmse_m"], r["max_err_after_10s_m"])
                           if r["ok"] else "")
                print("[%d/%d] %s (%s): %s%s, %.0f s" % (done, len(scenarios), r["scenario"]["name"],
                      r["scenario"].get("trajectory", "spiral"), figures, state, r["wall_s"]), flush=True)
    print()
    print_table(results, a.calibration)
    write_csv(results, os.path.join(a.out, "robustness.csv"), a.calibration)
    png = os.path.join(a.out, "error_cdf.png")
    wrote_png = write_cdf_png(results, png)
    print()
    for line in summary_lines(results) + (anchor_summary_lines(results) if a.calibration == "auto" else []):
        print(line)
    n_refused = sum(r["refused"] for r in results)
    n_failed = sum(not r["ok"] and not r["refused"] for r in results)
    n_div = sum(r["ok"] and r["diverged"] for r in results)
    print("\n%d runs: %d diverged (max position error after %.0f s > %.0f m), %d failed, %d refused to "
          "initialize (pose not determined by the data); wrote %s%s"
          % (len(results), n_div, SKIP_S, DIVERGENCE_M, n_failed, n_refused, os.path.join(a.out, "robustness.csv"),
             " and " + png if wrote_png else ""))
    for line in collinear_lines(results):
        print(line)
    n_bad_anchor = sum(is_bad_anchor_run(r) for r in results) if a.calibration == "auto" else 0
    return 1 if (n_div or n_failed or n_bad_anchor) else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
