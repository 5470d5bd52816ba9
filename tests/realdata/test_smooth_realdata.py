"""The whole-recording smoother on real recordings (issue 35): `meshnav_run` with its defaults,
then `meshnav_smooth`, then `meshnav_eval`, which scores estimate_smoothed.csv beside the filter.
Asserted on each: the issue's target for the smoothed estimate, the figure measured when it was
built (MEASURED, 2026-12-06, NLOS mixture on in filter and smoother; a deterministic run: the margin absorbs compiler/libm differences),
that the smoother beats the filter of the same run, and that its output names what it found
(gravity's direction, the filter's re-initializations). When a change moves these figures,
update MEASURED and docs/results.md."""

import os
import re
import subprocess
import tempfile
import unittest

import realdata_support as rs

STARLOC_DIR = os.path.join(rs.SHARED, "data", "real-starloc-loop2d-s1")
# smoothed position RMSE [m] (the filter's in brackets), 2026-12-06
MEASURED = {"starloc": 0.119, "isas": 0.050, "ifo002": 0.214}  # (0.122, 0.164, 1.007)
TARGET = {"starloc": 0.20, "isas": 0.16}  # issue 35; MILUV: half the filter's figure
MARGIN_M = 0.02


def smooth_and_evaluate(test, ds, tmp, align):
    exes = [os.path.join(rs.BIN, b) for b in ("meshnav_run", "meshnav_smooth", "meshnav_eval")]
    for exe in exes:
        if not os.path.exists(exe):
            raise unittest.SkipTest(f"{exe} not built")
    run = os.path.join(tmp, "run")
    r = subprocess.run([exes[0], "--dataset", ds, "--out", run], capture_output=True, text=True, timeout=300)
    test.assertEqual(r.returncode, 0, (r.stdout + r.stderr)[-3000:])
    s = subprocess.run([exes[1], "--dataset", ds, "--run", run], capture_output=True, text=True, timeout=300)
    test.assertEqual(s.returncode, 0, (s.stdout + s.stderr)[-3000:])
    test.assertRegex(s.stdout + s.stderr, r"chunk 1 \[")  # progress
    summary = rs.read_yaml(os.path.join(run, "smoother.yaml"))
    test.assertTrue(all(c["converged"] and c["covariance_ok"] for c in summary["chunks"]), summary)
    e = subprocess.run([exes[2], "--dataset", ds, "--run", run, "--no-plots", "--align", align], capture_output=True,
                       text=True, timeout=120)
    test.assertEqual(e.returncode, 0, e.stdout + e.stderr)
    filt = re.search(r"^position \[m\]\s+([0-9.]+)", e.stdout, re.M)
    smoothed = re.search(r"^position \[m\], smoothed\s+([0-9.]+)(?:\s+[0-9.]+){5}\s+([0-9.]+)", e.stdout, re.M)
    test.assertIsNotNone(filt, e.stdout)
    test.assertIsNotNone(smoothed, e.stdout)
    metrics = rs.read_yaml(os.path.join(run, "metrics.yaml"))
    test.assertAlmostEqual(metrics["pose_smoothed"]["position"]["rmse_m"], float(smoothed.group(1)), places=3)
    return float(filt.group(1)), float(smoothed.group(1)), float(smoothed.group(2)), summary


class SmoothRealData(unittest.TestCase):
    def test_starloc(self):
        rs.require(STARLOC_DIR)
        with tempfile.TemporaryDirectory() as tmp:
            f, s, anees, _ = smooth_and_evaluate(self, STARLOC_DIR, tmp, "none")
        self.assertLess(s, min(TARGET["starloc"], MEASURED["starloc"] + MARGIN_M))
        self.assertLess(s, f)

    def test_isas_walk1(self):
        rs.require(rs.ISAS_BAG)
        tmp, ds, code, log = rs.import_to_temp("isas", "rosbag", "--bag", rs.ISAS_BAG)
        with tmp:
            self.assertEqual(code, 0, log)
            f, s, anees, summary = smooth_and_evaluate(self, ds, tmp.name, "se3")
        self.assertLess(s, min(TARGET["isas"], MEASURED["isas"] + MARGIN_M))
        self.assertLess(s, 0.5 * f)
        # The anchors' frame has z down (docs/real_data.md): found from the data before the filter's
        # first pose (the alignment window compares both signs), so the filter starts along it and
        # is never re-initialized for it.
        self.assertEqual(summary["chunks"][0]["gravity_z_sign"], 1)
        self.assertEqual(summary["chunks"][0]["filter_reinitializations"], 0)
        self.assertLess(anees, 4.0)

    def test_miluv_ifo002(self):
        rs.require(rs.MILUV_DIR)
        with tempfile.TemporaryDirectory() as tmp:
            ds = os.path.join(tmp, "ifo002")
            code, log = rs.run_import("miluv", "--dir", rs.MILUV_DIR, "--robot", "ifo002", "--out", ds)
            self.assertEqual(code, 0, log)
            f, s, anees, summary = smooth_and_evaluate(self, ds, tmp, "none")
        self.assertLess(s, min(0.5 * f, MEASURED["ifo002"] + MARGIN_M))
        self.assertGreater(summary["chunks"][0]["heights"], 100)  # the rangefinder is fused


if __name__ == "__main__":
    unittest.main()
