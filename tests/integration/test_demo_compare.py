"""Unit tests of scripts/demo_compare.py, the comparison at the end of `./meshnav demo --real`
(no binaries needed): the table from two metrics files, and a clear message with exit 1 (no
traceback) when a run has no pose metrics (the estimator never initialized: meshnav_eval writes
`pose: null`), a metrics file is missing or is not one."""

import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.environ.get("MESHNAV_SOURCE_DIR", os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
SCRIPT = os.path.join(ROOT, "scripts", "demo_compare.py")

METRICS = """alignment:
  mode: se3
baseline:
  n_evaluated: 224
  position_rmse_m: 1.31914
pose:
  n_evaluated: %d
  position:
    rmse_m: %s
"""


class DemoCompareTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()

    def tearDown(self):
        self.dir.cleanup()

    def write(self, name, text):
        path = os.path.join(self.dir.name, name)
        with open(path, "w") as f:
            f.write(text)
        return path

    def compare(self, lcm, run):
        return subprocess.run([sys.executable, SCRIPT, lcm, run], capture_output=True, text=True, timeout=30)

    def test_table_of_both_runs_and_the_baseline(self):
        r = self.compare(self.write("lcm.yaml", METRICS % (6000, "0.215")), self.write("run.yaml", METRICS % (6100, "0.205")))
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("after se3 alignment", r.stdout)
        self.assertRegex(r.stdout, r"meshnav over LCM \(estimator process\) +0\.215 m   \(6000 estimates\)")
        self.assertRegex(r.stdout, r"meshnav in one process \(meshnav_run\) +0\.205 m   \(6100 estimates\)")
        self.assertRegex(r.stdout, r"plain multilateration of the ranges +1\.319 m   \(224 fixes\)")
        self.assertIn("LCM minus in-process: +0.010 m", r.stdout)

    def test_no_pose_metrics_is_a_message_and_exit_1(self):
        # The estimator process never initialized (the sanitizer run of integration.demo_real): pose: null.
        lcm = self.write("lcm.yaml", "alignment:\n  mode: se3\nbaseline: null\npose: null\n")
        r = self.compare(lcm, self.write("run.yaml", METRICS % (6100, "0.205")))
        self.assertEqual(r.returncode, 1)
        self.assertNotIn("Traceback", r.stderr)
        self.assertIn("no pose metrics for the LCM run (estimator process) in " + lcm, r.stderr)
        self.assertIn("did the estimator initialize?", r.stderr)
        self.assertEqual(r.stdout, "")
        # The in-process run likewise.
        run = self.write("run_null.yaml", "pose: null\n")
        r = self.compare(self.write("lcm2.yaml", METRICS % (6000, "0.215")), run)
        self.assertEqual(r.returncode, 1)
        self.assertIn("no pose metrics for the in-process run (meshnav_run) in " + run, r.stderr)

    def test_missing_or_foreign_files_are_named(self):
        missing = os.path.join(self.dir.name, "nothing.yaml")
        r = self.compare(missing, self.write("run.yaml", METRICS % (1, "0.2")))
        self.assertEqual(r.returncode, 1)
        self.assertIn("cannot read " + missing, r.stderr)
        self.assertNotIn("Traceback", r.stderr)
        r = self.compare(self.write("list.yaml", "- 1\n- 2\n"), self.write("run2.yaml", METRICS % (1, "0.2")))
        self.assertEqual(r.returncode, 1)
        self.assertIn("is not a meshnav_eval metrics file", r.stderr)
        r = self.compare(self.write("bad.yaml", "pose: {position: {}}\n"), self.write("run3.yaml", METRICS % (1, "0.2")))
        self.assertEqual(r.returncode, 1)
        self.assertIn("without position.rmse_m", r.stderr)
        self.assertNotIn("Traceback", r.stderr)


if __name__ == "__main__":
    unittest.main()
