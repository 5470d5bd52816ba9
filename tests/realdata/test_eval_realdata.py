"""meshnav_eval on imported real recordings: the alignment default follows truth.yaml and the
multilateration baseline reproduces the figure the ISAS-Walk1 README gives (0.256 m after SE(3)).
And meshnav_run on ISAS-Walk1 with its defaults (issue 9): the RTLS frame of this recording has its
z axis pointing down (docs/real_data.md, "What ISAS-Walk1 allows"): the in-motion alignment's
window finds so before the first pose (counter anchor_frame_z_down), the filter starts with gravity
along +z and reaches 0.164 m (0.250 m when the sign was taken a window after the start)."""

import os
import re
import subprocess
import tempfile
import unittest

import realdata_support as rs


def evaluate(dataset, *extra):
    exe = os.path.join(rs.BIN, "meshnav_eval")
    if not os.path.exists(exe):
        raise unittest.SkipTest(f"{exe} not built")
    p = subprocess.run([exe, "--dataset", dataset, *extra], capture_output=True, text=True, timeout=120)
    return p.returncode, p.stdout, p.stderr


def baseline_rmse(stdout):
    m = re.search(r"^multilateration\s+([0-9.]+)\s+([0-9.]+)\s+([0-9.]+)\s+(\d+)\s+(\S+)", stdout, re.M)
    return (float(m.group(1)), int(m.group(4)), m.group(5)) if m else None


class IsasBaseline(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rs.require(rs.ISAS_BAG)
        cls.tmp, cls.ds, code, log = rs.import_to_temp("isas", "rosbag", "--bag", rs.ISAS_BAG)
        assert code == 0, log

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_default_alignment_is_se3_and_baseline_matches_the_readme(self):
        code, out, err = evaluate(self.ds)
        self.assertEqual(code, 0, out + err)
        self.assertIn("alignment: se3 (default: truth.yaml says groundtruth.csv is in frame 'vive/reference'", out)
        rmse, n, mode = baseline_rmse(out)
        self.assertEqual(mode, "se3")
        self.assertGreater(n, 850)           # one fix per RTLS message with >= 4 fresh ranges
        self.assertLess(abs(rmse - 0.256), 0.03, out)

    def test_run_reports_the_upside_down_anchor_frame(self):
        exe = os.path.join(rs.BIN, "meshnav_run")
        if not os.path.exists(exe):
            raise unittest.SkipTest(f"{exe} not built")
        run = os.path.join(self.tmp.name, "run")
        p = subprocess.run([exe, "--dataset", self.ds, "--out", run], capture_output=True, text=True, timeout=300)
        self.assertEqual(p.returncode, 0, p.stderr[-2000:])
        self.assertIn("fits the IMU with the anchors' frame G upside down", p.stdout + p.stderr)
        self.assertIn("gravity is taken along +z of G", p.stdout + p.stderr)
        status = rs.read_yaml(os.path.join(run, "status.txt"))
        self.assertEqual(status["counters"].get("anchor_frame_z_down"), 1, status["counters"])
        # Decided on the alignment window before the first pose: no flip of a running filter.
        self.assertEqual(status["counters"].get("gravity_flip", 0), 0, status["counters"])
        code, out, err = evaluate(self.ds, "--run", run, "--no-plots", "--no-baseline")
        self.assertEqual(code, 0, out + err)
        ate = float(re.search(r"^meshnav\s+([0-9.]+)", out, re.M).group(1))
        # 0.164 m (2026-12-06; issue 34's target 0.20 m; 0.250 m while the sign was taken a window
        # after the start, 0.283 m before any gravity check)
        self.assertLess(ate, 0.19, out)

    def test_without_alignment_the_frames_differ_by_metres(self):
        code, out, _ = evaluate(self.ds, "--align", "none")
        rmse, _, mode = baseline_rmse(out)
        self.assertEqual(mode, "none")
        self.assertGreater(rmse, 1.0)
        code, out, _ = evaluate(self.ds, "--align", "yaw")
        self.assertLess(baseline_rmse(out)[0], 0.5)


class MiluvBaseline(unittest.TestCase):
    def test_sparse_ranges_give_no_fix_and_say_why(self):
        rs.require(rs.MILUV_DIR)
        with tempfile.TemporaryDirectory() as tmp:
            code, log = rs.run_import("miluv", "--dir", rs.MILUV_DIR, "--robot", "ifo001", "--out", tmp)
            self.assertEqual(code, 0, log)
            code, out, _ = evaluate(tmp)
            self.assertIn("alignment: none (default: ground truth in the estimate's frame", out)
            self.assertIn("multilateration: no fix", out)
            self.assertEqual(code, 1)  # nothing could be evaluated


class SkipRule(unittest.TestCase):
    def test_missing_shared_data_skips_and_fails_under_ci(self):
        saved = os.environ.pop("CI", None)
        try:
            with self.assertRaises(unittest.SkipTest) as skip:
                rs.require("/nonexistent/shared/data")
            self.assertIn("/nonexistent/shared/data", str(skip.exception))
            os.environ["CI"] = "1"
            with self.assertRaises(AssertionError):
                rs.require("/nonexistent/shared/data")
        finally:
            os.environ.pop("CI", None)
            if saved is not None:
                os.environ["CI"] = saved


if __name__ == "__main__":
    unittest.main()
