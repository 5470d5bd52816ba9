"""End to end on STAR-loc loop2d-s1 (issue 34, item 7): the folder is already in the dataset
format; `meshnav_run` with its defaults and `meshnav_eval` with no alignment (Vicon is the anchors'
frame). Asserted: the figures measured on 2026-12-05 (position ATE 0.542 m, ANEES 88, orientation
12.85 deg; plain multilateration scored as tag positions 1.256 m) within a margin, and that the
estimate beats multilateration. The issue's targets (<= 0.25 m, ANEES <= 6, <= 5 deg) are NOT
reached; docs/results.md says so. When a model moves these figures, update MEASURED and the doc."""

import os
import re
import subprocess
import tempfile
import unittest

import realdata_support as rs

STARLOC_DIR = os.path.join(rs.SHARED, "data", "real-starloc-loop2d-s1")
# ATE [m], position ANEES, orientation RMSE [deg], multilateration ATE [m] (2026-12-05, main at 5954736).
MEASURED = {"ate": 0.542, "anees": 88.14, "ori": 12.85, "multilateration": 1.256}
ATE_MARGIN_M = 0.1  # deterministic run; the margin absorbs compiler/libm differences


class StarlocEndToEnd(unittest.TestCase):
    def test_defaults_no_alignment(self):
        rs.require(STARLOC_DIR)
        exe_run, exe_eval = os.path.join(rs.BIN, "meshnav_run"), os.path.join(rs.BIN, "meshnav_eval")
        for exe in (exe_run, exe_eval):
            if not os.path.exists(exe):
                raise unittest.SkipTest(f"{exe} not built")
        with tempfile.TemporaryDirectory() as tmp:
            run = os.path.join(tmp, "run")
            r = subprocess.run([exe_run, "--dataset", STARLOC_DIR, "--out", run], capture_output=True, text=True,
                               timeout=300)
            self.assertEqual(r.returncode, 0, (r.stdout + r.stderr)[-3000:])
            e = subprocess.run([exe_eval, "--dataset", STARLOC_DIR, "--run", run, "--no-plots"], capture_output=True,
                               text=True, timeout=120)
        self.assertEqual(e.returncode, 0, e.stdout + e.stderr)
        self.assertIn("alignment: none", e.stdout)
        ate = re.search(r"^meshnav\s+([0-9.]+)\s+[0-9.]+\s+[0-9.]+\s+(\d+)\s+none", e.stdout, re.M)
        ml = re.search(r"^multilateration\s+([0-9.]+)\s+[0-9.]+\s+[0-9.]+\s+(\d+)\s+none", e.stdout, re.M)
        pos = re.search(r"^position \[m\]\s+([0-9.]+)(?:\s+[0-9.]+){5}\s+([0-9.]+)", e.stdout, re.M)
        ori = re.search(r"^orientation \[deg\]\s+([0-9.]+)", e.stdout, re.M)
        for m in (ate, ml, pos, ori):
            self.assertIsNotNone(m, e.stdout)
        self.assertLess(float(ate.group(1)), MEASURED["ate"] + ATE_MARGIN_M, e.stdout)
        self.assertLess(float(ate.group(1)), float(ml.group(1)), "the estimate should beat plain multilateration")
        self.assertLess(abs(float(ml.group(1)) - MEASURED["multilateration"]), 0.05, e.stdout)
        # Overconfident today (issue 34): the ANEES is reported, and a model that fixes it moves it down.
        self.assertLess(float(pos.group(2)), 2.0 * MEASURED["anees"], e.stdout)
        self.assertLess(float(ori.group(1)), MEASURED["ori"] + 3.0, e.stdout)


if __name__ == "__main__":
    unittest.main()
