"""scripts/bench_realdata.py (`./meshnav bench realdata`): one repetition on ISAS-Walk1 reports the
import, the run and their sum against issue 9's 5 s target, and bad arguments are refused with a
message. No time is asserted (speed is a benchmark's figure, docs/results.md)."""

import os
import re
import subprocess
import sys
import unittest

from realdata_support import BIN, ISAS_BAG, REPO, require

SCRIPT = os.path.join(REPO, "scripts", "bench_realdata.py")


def bench(*args):
    p = subprocess.run([sys.executable, SCRIPT, "--bin", BIN, *args], capture_output=True, text=True, timeout=300)
    return p.returncode, p.stdout, p.stderr


class BenchRealdataTest(unittest.TestCase):
    def test_one_repetition_reports_import_run_and_the_target(self):
        require(ISAS_BAG)
        code, out, err = bench("--runs", "1", "--bag", ISAS_BAG)
        self.assertEqual(code, 0, err)
        m = re.search(r"median of 1: import ([0-9.]+) s, run ([0-9.]+) s, import \+ run ([0-9.]+) s "
                      r"\(target <= 5 s: (met|NOT met)\)", out)
        self.assertIsNotNone(m, out)
        imp, run, total = (float(m.group(i)) for i in (1, 2, 3))
        self.assertGreater(imp, 0.0)
        self.assertGreater(run, 0.0)
        self.assertAlmostEqual(total, imp + run, delta=0.011)

    def test_a_missing_bag_is_refused_with_its_path(self):
        code, _, err = bench("--bag", "/nonexistent/ISAS-Walk1.bag")
        self.assertNotEqual(code, 0)
        self.assertIn("/nonexistent/ISAS-Walk1.bag not found", err)

    def test_zero_repetitions_are_refused(self):
        code, _, err = bench("--runs", "0")
        self.assertNotEqual(code, 0)
        self.assertIn("--runs must be at least 1", err)


if __name__ == "__main__":
    unittest.main()
