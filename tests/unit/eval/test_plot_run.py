"""plot_run.py: anchor tracks over time (error norm and NEES against the true position) and the
anchor_errors.png they give; exact values on a hand-made anchors.csv."""
import math
import os
import sys
import tempfile
import unittest

import numpy as np

sys.path.insert(0, os.path.join(os.environ.get("MESHNAV_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", "..", "..")),
                                "eval", "plots"))
import plot_run  # noqa: E402


def write(path, text):
    with open(path, "w") as f:
        f.write(text)


class AnchorTracks(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp()
        write(os.path.join(self.dir, "anchors_eval.csv"),
              "id,known,has_truth,true_x,true_y,true_z,init_x,init_y,init_z,final_x,final_y,final_z\n"
              "101,1,1,0,0,0,0,0,0,0,0,0\n"
              "106,0,1,1,2,3,0,0,0,0,0,0\n"
              "107,0,0,0,0,0,0,0,0,0,0,0\n")
        # 106: error [0.3, 0, 0] with P = diag(0.01, 0.04, 0.09) -> NEES 9; then [0, 0.2, 0.3] -> 1 + 1 = 2;
        # a row with a singular covariance -> NEES nan. 101 known and 107 without truth are skipped.
        write(os.path.join(self.dir, "anchors.csv"),
              "t,id,x,y,z,pxx,pxy,pxz,pyy,pyz,pzz\n"
              "10.0,101,0,0,0,0,0,0,0,0,0\n"
              "10.0,106,1.3,2,3,0.01,0,0,0.04,0,0.09\n"
              "11.0,106,1,2.2,3.3,0.01,0,0,0.04,0,0.09\n"
              "12.0,106,1,2,3.4,0,0,0,0,0,0\n"
              "10.0,107,5,5,5,1,0,0,1,0,1\n")

    def tracks(self):
        return plot_run.anchor_tracks(plot_run.read_csv(os.path.join(self.dir, "anchors.csv")),
                                      plot_run.read_csv(os.path.join(self.dir, "anchors_eval.csv")))

    def test_error_and_nees_per_estimated_anchor(self):
        tr = self.tracks()
        self.assertEqual(sorted(tr), [106])
        t, err, nees = tr[106]
        np.testing.assert_allclose(t, [10.0, 11.0, 12.0])
        np.testing.assert_allclose(err, [0.3, math.hypot(0.2, 0.3), 0.4], atol=1e-12)
        self.assertAlmostEqual(nees[0], 9.0, places=9)
        self.assertAlmostEqual(nees[1], 2.0, places=9)
        self.assertTrue(math.isnan(nees[2]))

    def test_png_written(self):
        plot_run.plot_anchor_errors(self.dir, self.tracks())
        png = os.path.join(self.dir, "anchor_errors.png")
        self.assertTrue(os.path.exists(png))
        with open(png, "rb") as f:
            self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")


if __name__ == "__main__":
    unittest.main()
