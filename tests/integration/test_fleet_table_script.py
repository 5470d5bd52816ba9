"""Unit tests of scripts/fleet_table.py (no binaries needed): seed lists, the table and its mean
row, and usage errors; plus a run whose meshnav_sim fails ends with exit 1 and a message."""

import contextlib
import io
import os
import sys
import tempfile
import unittest

ROOT = os.environ.get("MESHNAV_SOURCE_DIR", os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import fleet_table  # noqa: E402


class SeedsTest(unittest.TestCase):
    def test_ranges_and_lists(self):
        self.assertEqual(fleet_table.parse_seeds("1-4"), [1, 2, 3, 4])
        self.assertEqual(fleet_table.parse_seeds("7"), [7])
        self.assertEqual(fleet_table.parse_seeds("3,1"), [3, 1])
        for bad in ("4-1", "a", "1-", ""):
            with self.assertRaises(ValueError, msg=bad):
                fleet_table.parse_seeds(bad)


class TableTest(unittest.TestCase):
    def test_a_row_per_vehicle_and_the_mean_over_all(self):
        rows = [(1, 0, (0.1, 3.0, 0.06, 0.05), (0.2, 4.0, 0.14, 0.06)),
                (1, 1, (0.3, 2.0, 0.08, 0.03), (0.4, 2.0, 0.06, 0.04))]
        lines = fleet_table.table_lines(rows)
        self.assertEqual(len(lines), 2 + 2 + 1)
        self.assertIn("| 1 | v0 | 0.100 / 0.200 | 3.00 / 4.00 | 0.060 / 0.140 | 0.050 / 0.060 |", lines)
        self.assertEqual(lines[-1], "| mean | 2 | 0.200 / 0.300 | 2.50 / 3.00 | 0.070 / 0.100 | 0.040 / 0.050 |")


class UsageTest(unittest.TestCase):
    def refused(self, argv):
        err = io.StringIO()
        with contextlib.redirect_stderr(err), self.assertRaises(SystemExit) as ctx:
            fleet_table.parse_args(argv)
        self.assertEqual(ctx.exception.code, 2)
        return err.getvalue()

    def test_bad_options_are_refused_naming_the_option(self):
        self.assertIn("--seeds", self.refused(["--seeds", "5-2"]))
        self.assertIn("--vehicles", self.refused(["--vehicles", "1"]))
        self.assertIn("--mission", self.refused(["--mission", "/nonexistent/mission.yaml"]))
        self.assertIn("--inter-vehicle-hz", self.refused(["--inter-vehicle-hz", "-1"]))
        self.assertEqual(fleet_table.parse_args(["--inter-vehicle-hz", "10"]).inter_vehicle_hz, 10.0)

    def test_a_failing_step_is_exit_1_with_its_log(self):
        with tempfile.TemporaryDirectory() as d:
            err = io.StringIO()
            with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
                rc = fleet_table.main(["--seeds", "1", "--bin", os.path.join(d, "nobin"), "--out", d,
                                       "--mission", "auto"])
            self.assertEqual(rc, 1)
            self.assertIn("FAILED", err.getvalue())


if __name__ == "__main__":
    unittest.main()
