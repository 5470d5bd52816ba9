"""End to end on STAR-loc loop2d-s1 (issue 34): the folder is already in the dataset format;
`meshnav_run` and `meshnav_eval` with no alignment (Vicon is the anchors' frame). The evaluation
leaves out 6.34-7.32 s, where the Vicon truth contradicts the IMU's gyro (the dataset README's
dropout; eval/truth_consistency.h); the test asserts that it finds that stretch.
With the defaults it asserts the issue's targets (ATE <= 0.25 m, orientation <= 5 deg, position
ANEES <= 6; measured 2026-12-06: see MEASURED) and that the UWB clock's delay it states agrees with
the one measured against the truth. With issue 34's pair-bias and correlated-error
models turned off (uwb.uncalibrated_gamma_sigma_m 0, uwb.range_error_correlation_s 0: the models
before the issue) the filter is overconfident again (ANEES 88): the test holds that row too, so that
a change which makes the models inert shows. Plain multilateration scored as tag positions
(1.257 m) is the baseline either estimate must beat. When a model moves these figures, update
MEASURED and docs/results.md."""

import os
import re
import subprocess
import tempfile
import unittest

import realdata_support as rs

STARLOC_DIR = os.path.join(rs.SHARED, "data", "real-starloc-loop2d-s1")
# ATE [m], position ANEES, orientation RMSE [deg], multilateration ATE [m] (2026-12-06, defaults:
# the pair-bias, correlated-error and NLOS-mixture models, the gate on each range's own error;
# without the mixture 0.141 m, 4.66, 3.12 deg; before issue 34 0.542 m, 88, 12.85 deg).
MEASURED = {"ate": 0.122, "anees": 3.60, "ori": 3.40, "multilateration": 1.257}
# The IMU's stamps lead the ranges by about 30 ms (measured against the truth, issue 34): the UWB
# stamps' delay against the IMU clock is about -0.030 s. The estimator's state (prior sigma 0.03 s)
# found -52.5 ms, sigma 19.2 ms (2026-12-05).
CLOCK_DELAY_S = -0.030
MEASURED_WITHOUT_MODELS = {"ate": 0.545, "anees": 88.09, "ori": 12.65}
TARGET = {"ate": 0.25, "anees": 6.0, "ori": 5.0}  # issue 34
ATE_MARGIN_M = 0.05  # deterministic run; the margin absorbs compiler/libm differences
WITHOUT_MODELS = "uwb:\n  uncalibrated_gamma_sigma_m: 0.0\n  range_error_correlation_s: 0.0\n  nlos_fraction: 0.0\n"


class StarlocEndToEnd(unittest.TestCase):
    def run_and_evaluate(self, extra, expected_code=0):
        rs.require(STARLOC_DIR)
        exe_run, exe_eval = os.path.join(rs.BIN, "meshnav_run"), os.path.join(rs.BIN, "meshnav_eval")
        for exe in (exe_run, exe_eval):
            if not os.path.exists(exe):
                raise unittest.SkipTest(f"{exe} not built")
        with tempfile.TemporaryDirectory() as tmp:
            run = os.path.join(tmp, "run")
            r = subprocess.run([exe_run, "--dataset", STARLOC_DIR, "--out", run] + extra, capture_output=True,
                               text=True, timeout=300)
            self.assertEqual(r.returncode, expected_code, (r.stdout + r.stderr)[-3000:])
            self.log = r.stdout + r.stderr
            e = subprocess.run([exe_eval, "--dataset", STARLOC_DIR, "--run", run, "--no-plots"], capture_output=True,
                               text=True, timeout=120)
            with open(os.path.join(run, "status.txt")) as f:
                status = f.read()
        # Every run states the clock offset it used (issue 34): in status.txt and at the end of its log.
        clock = re.search(r"^uwb_clock_offset_s: (\S+)\nuwb_clock_offset_sigma_s: (\S+)$", status, re.M)
        self.assertIsNotNone(clock, status)
        self.assertRegex(r.stdout + r.stderr, r"UWB clock: stamps -?[0-9.]+ ms late against the IMU")
        self.clock = (float(clock.group(1)), float(clock.group(2)))
        self.assertEqual(e.returncode, 0, e.stdout + e.stderr)
        self.assertIn("alignment: none", e.stdout)
        ate = re.search(r"^meshnav\s+([0-9.]+)\s+[0-9.]+\s+[0-9.]+\s+(\d+)\s+none", e.stdout, re.M)
        ml = re.search(r"^multilateration\s+([0-9.]+)\s+[0-9.]+\s+[0-9.]+\s+(\d+)\s+none", e.stdout, re.M)
        pos = re.search(r"^position \[m\]\s+([0-9.]+)(?:\s+[0-9.]+){5}\s+([0-9.]+)", e.stdout, re.M)
        ori = re.search(r"^orientation \[deg\]\s+([0-9.]+)", e.stdout, re.M)
        for m in (ate, ml, pos, ori):
            self.assertIsNotNone(m, e.stdout)
        self.assertLess(float(ate.group(1)), float(ml.group(1)), "the estimate should beat plain multilateration")
        self.assertLess(abs(float(ml.group(1)) - MEASURED["multilateration"]), 0.05, e.stdout)
        # The Vicon dropout is found from the data, not from a list of times.
        fault = re.search(r"ground truth contradicts the gyro of imu.csv in 1 stretch\(es\): ([0-9.]+)–([0-9.]+) s",
                          e.stdout + e.stderr)
        self.assertIsNotNone(fault, e.stdout + e.stderr)
        self.assertTrue(6.2 <= float(fault.group(1)) <= 6.5 and 7.2 <= float(fault.group(2)) <= 7.4, fault.group(0))
        return float(ate.group(1)), float(pos.group(2)), float(ori.group(1)), e.stdout

    def test_defaults_reach_the_targets(self):
        ate, anees, ori, out = self.run_and_evaluate([])
        self.assertLess(ate, min(TARGET["ate"], MEASURED["ate"] + ATE_MARGIN_M), out)
        self.assertLess(anees, TARGET["anees"], out)
        self.assertLess(ori, TARGET["ori"], out)
        # The delay is a state the ranges inform (its sigma below the prior's 0.03 s) and agrees with
        # the lead measured against the truth within 3 sigma.
        delay_s, sigma_s = self.clock
        self.assertGreater(sigma_s, 0.0)
        self.assertLess(sigma_s, 0.025)
        self.assertLess(abs(delay_s - CLOCK_DELAY_S), 3.0 * sigma_s, self.clock)

    def test_without_the_range_error_models_the_filter_is_overconfident(self):
        with tempfile.NamedTemporaryFile("w", suffix=".yaml") as cfg:
            cfg.write(WITHOUT_MODELS)
            cfg.flush()
            # The UWB clock's delay takes up what the range model lacks and ends far beyond its prior
            # (257 ms, 8.6 sigma): meshnav_run says so and exits 4 (the run is not to be trusted).
            ate, anees, ori, out = self.run_and_evaluate(["--config", cfg.name], expected_code=4)
        self.assertRegex(self.log, r"the UWB clock's delay ended at \d+ ms, [0-9.]+ sigma from its prior")
        self.assertLess(ate, MEASURED_WITHOUT_MODELS["ate"] + 0.1, out)
        self.assertGreater(anees, 3.0 * TARGET["anees"], out)  # what the models are for
        self.assertLess(anees, 2.0 * MEASURED_WITHOUT_MODELS["anees"], out)

if __name__ == "__main__":
    unittest.main()
