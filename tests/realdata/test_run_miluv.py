"""End to end on MILUV (issue 9): `meshnav import miluv` then `meshnav_run` with its defaults and
`meshnav_eval` (no alignment: Vicon is the anchors' frame). With about one tag-anchor range every
1.2 s the estimator initializes only because the in-motion alignment reaches back by count and uses
the laser heights (estimator/height/). Asserted: it initializes in flight, the height sensor
holds z, and the position ATE stays at what was measured (2026-11-26: ifo001 5.16 m, ifo002
7.95 m). The issue's target (<= 0.20 m each) is NOT reached; docs/results.md says why."""

import os
import re
import subprocess
import tempfile
import unittest

import realdata_support as rs

# robot: (ATE measured [m], first estimate by [s] of recording time). With the in-motion
# alignment accepted only below σ_yaw 15° (was 25°): ifo001 5.158 -> 2.451 m (26.6 -> 27.1 s),
# ifo002 7.949 -> 3.290 m, initialized later (17.7 -> 59.4 s: earlier windows are refused).
# The ZUPT's ω row on the mean gyro reading since the last ZUPT (branch yaw): ifo001 unchanged,
# ifo002 3.290 -> 1.074 m (its stillness ZUPTs gated 5 -> 2, never lost; was lost 3 times).
MEASURED = {"ifo001": (2.451, 27.1), "ifo002": (1.074, 59.4)}
ATE_MARGIN_M = 0.5       # the run is deterministic; the margin absorbs compiler/libm differences
Z_RMSE_MAX_M = 0.25      # measured 0.159 m and 0.143 m: the rangefinder holds the height


def run_and_evaluate(robot, tmp):
    ds, run = os.path.join(tmp, robot), os.path.join(tmp, robot + "-run")
    code, log = rs.run_import("miluv", "--dir", rs.MILUV_DIR, "--robot", robot, "--out", ds)
    assert code == 0, log
    exe_run, exe_eval = os.path.join(rs.BIN, "meshnav_run"), os.path.join(rs.BIN, "meshnav_eval")
    for exe in (exe_run, exe_eval):
        if not os.path.exists(exe):
            raise unittest.SkipTest(f"{exe} not built")
    r = subprocess.run([exe_run, "--dataset", ds, "--out", run], capture_output=True, text=True, timeout=300)
    e = subprocess.run([exe_eval, "--dataset", ds, "--run", run], capture_output=True, text=True, timeout=120)
    return r, e


class MiluvEndToEnd(unittest.TestCase):
    def check(self, robot):
        rs.require(rs.MILUV_DIR)
        with tempfile.TemporaryDirectory() as tmp:
            r, e = run_and_evaluate(robot, tmp)
        log = r.stdout + r.stderr
        self.assertEqual(r.returncode, 0, log[-3000:])
        # Initialized in flight by the alignment, which used the heights (vertical constraint).
        m = re.search(r"initialized at t=([0-9.]+) from ranges", log)
        self.assertIsNotNone(m, log[-3000:])
        self.assertLess(float(m.group(1)), MEASURED[robot][1] + 0.5)
        self.assertRegex(log, r"the alignment used \d+ heights")
        self.assertRegex(log, r"dataset: \d+ imu, 0 baro, \d+ ranges, 0 flight states, 23[56]\d heights")
        self.assertIn("alignment: none", e.stdout)
        ate = re.search(r"^meshnav\s+([0-9.]+)\s+[0-9.]+\s+[0-9.]+\s+(\d+)\s+none", e.stdout, re.M)
        self.assertIsNotNone(ate, e.stdout)
        self.assertLess(float(ate.group(1)), MEASURED[robot][0] + ATE_MARGIN_M, e.stdout)
        pos = re.search(r"^position \[m\]\s+([0-9.]+)\s+[0-9.]+\s+[0-9.]+\s+[0-9.]+\s+[0-9.]+\s+([0-9.]+)", e.stdout, re.M)
        self.assertIsNotNone(pos, e.stdout)
        self.assertLess(float(pos.group(2)), Z_RMSE_MAX_M, e.stdout)

    def test_ifo001(self):
        self.check("ifo001")

    def test_ifo002(self):
        self.check("ifo002")


if __name__ == "__main__":
    unittest.main()
