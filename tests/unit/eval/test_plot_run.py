"""plot_run.py: anchor tracks over time (error norm and NEES against the true position) and the
anchor_errors.png they give; exact values on a hand-made anchors.csv. The truth mapped into the
estimate's frame with meshnav_eval's alignment, and range residuals along the estimate with the
tag lever arm, on hand-made files with exact answers."""
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
        tmp = tempfile.TemporaryDirectory(prefix="meshnav_plot_run_")
        self.addCleanup(tmp.cleanup)
        self.dir = tmp.name
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


class AlignedTruth(unittest.TestCase):
    def test_truth_mapped_back_with_the_inverse_of_the_fit(self):
        # p_T = R p_E + t with R = 90 deg about z, t = (1, 2, 3): p_E = (1, 0, 0) is p_T = (1, 3, 3).
        alignment = plot_run.read_alignment("0,-1,0,1,0,0,0,0,1,1,2,3")
        gt = {"t": np.array([0.0]), "tx": np.array([1.0]), "ty": np.array([3.0]), "tz": np.array([3.0])}
        p = plot_run.truth_in_estimate_frame(gt, alignment)
        np.testing.assert_allclose([p["tx"][0], p["ty"][0], p["tz"][0]], [1.0, 0.0, 0.0], atol=1e-12)
        self.assertEqual(gt["tx"][0], 1.0)  # the input is left as it was
        self.assertIs(plot_run.truth_in_estimate_frame(gt, None), gt)

    def test_bad_alignment_text_is_refused(self):
        with self.assertRaises(ValueError):
            plot_run.read_alignment("1,0,0")
        with self.assertRaises(ValueError):
            plot_run.read_alignment("1,0,0,0,1,0,0,0,1,nan,0,0")

    def test_time_axis_from_the_first_sample_only_for_absolute_stamps(self):
        t, label = plot_run.time_axis(np.array([1664959676.5, 1664959677.0]))
        np.testing.assert_allclose(t, [0.0, 0.5])
        self.assertEqual(label, "t − 1664959676.500 [s]")
        t, label = plot_run.time_axis(np.array([3.0, 4.0]))
        np.testing.assert_allclose(t, [3.0, 4.0])
        self.assertEqual(label, "t [s]")


class RangeResiduals(unittest.TestCase):
    def setUp(self):
        tmp = tempfile.TemporaryDirectory(prefix="meshnav_plot_run_")
        self.addCleanup(tmp.cleanup)
        self.dir = tmp.name
        # Body at (0, 0, 0) then (2, 0, 0) over t 10..12, yawed 90 deg (q = (0, 0, sin 45, cos 45)):
        # the tag at p_TinI = (1, 0, 0) is at (0, 1, 0) + p_IinG.
        s = math.sqrt(0.5)
        write(os.path.join(self.dir, "estimate.csv"),
              "t,tx,ty,tz,qx,qy,qz,qw\n10,0,0,0,0,0,%.17g,%.17g\n12,2,0,0,0,0,%.17g,%.17g\n" % (s, s, s, s))
        # Anchor 7 at (1, 1, 5): at t 11 the tag is at (1, 1, 0), 5 m away. Rows: tag first; anchor
        # first (84/65 codes); an anchor-anchor row; an unknown anchor; one before the estimate.
        write(os.path.join(self.dir, "ranges.csv"),
              "t,range_raw,range_corr,R,UWB_ID1,UWB_ID2,type_ID1,type_ID2,LOS\n"
              "11,5.25,0,0,100,7,T,A,1\n"
              "11,4.9,0,0,7,100,65,84,1\n"
              "11,3,0,0,7,8,A,A,1\n"
              "11,3,0,0,100,9,T,A,1\n"
              "9,3,0,0,100,7,T,A,1\n")
        write(os.path.join(self.dir, "setup.yaml"),
              "rel_tag_positions:\n  100: [1, 0, 0]\nabs_anchor_positions:\n  7: [1, 1, 5]\n  8: [0, 0, 0]\n")

    def test_residuals_with_lever_arm_and_interpolated_position(self):
        tags, anchors = plot_run.read_setup_geometry(os.path.join(self.dir, "setup.yaml"))
        res = plot_run.range_residuals(plot_run.read_tag_anchor_ranges(os.path.join(self.dir, "ranges.csv")),
                                       plot_run.read_csv(os.path.join(self.dir, "estimate.csv")), tags, anchors)
        self.assertEqual(sorted(res), [7])
        t, r = res[7]
        np.testing.assert_allclose(t, [11.0, 11.0])
        np.testing.assert_allclose(r, [0.25, -0.1], atol=1e-12)
        self.assertEqual(plot_run.robust_stats(np.array([0.0, 1.0, 2.0, 10.0])), (1.5, 1.4826 * 1.0))

    def test_png_written(self):
        plot_run.plot_range_residuals(self.dir, {7: (np.array([1664959676.0, 1664959677.0]), np.array([0.1, -0.2]))})
        with open(os.path.join(self.dir, "range_residuals.png"), "rb") as f:
            self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")



class SmoothedBesideTheFilter(unittest.TestCase):
    """meshnav_eval passes --smoothed and --smoothed-errors when the run has estimate_smoothed.csv:
    the trajectory plots draw it beside the filter's and its position error gets a figure."""

    def test_smoothed_plots_written(self):
        tmp = tempfile.TemporaryDirectory(prefix="meshnav_plot_run_")
        self.addCleanup(tmp.cleanup)
        d = tmp.name
        header = "t,tx,ty,tz,qx,qy,qz,qw,pxx,pxy,pxz,pyy,pyz,pzz,qrr,qrp,qry,qpp,qpy,qyy\n"
        rows = "".join("%d,%g,%g,1,0,0,0,1,0.01,0,0,0.01,0,0.01,0.001,0,0,0.001,0,0.001\n" % (k, 0.1 * k, 0.2 * k)
                       for k in range(20))
        write(os.path.join(d, "estimate.csv"), header + rows)
        write(os.path.join(d, "estimate_smoothed.csv"), header + rows)
        err_header = ("t,ep_x_m,ep_y_m,ep_z_m,sigma3_p_x_m,sigma3_p_y_m,sigma3_p_z_m,eth_x_deg,eth_y_deg,eth_z_deg,"
                      "sigma3_th_x_deg,sigma3_th_y_deg,sigma3_th_z_deg,ep_norm_m,eth_angle_deg,nees_p,nees_theta,"
                      "flying,selected\n")
        err_rows = "".join("%d,0.01,0,0,0.3,0.3,0.3,0.1,0,0,1,1,1,0.01,0.1,0.01,0.03,1,1\n" % k for k in range(20))
        write(os.path.join(d, "errors.csv"), err_header + err_rows)
        write(os.path.join(d, "errors_smoothed.csv"), err_header + err_rows)
        out = os.path.join(d, "png")
        argv = sys.argv
        sys.argv = ["plot_run.py", "--out", out, "--estimate", os.path.join(d, "estimate.csv"), "--errors",
                    os.path.join(d, "errors.csv"), "--smoothed", os.path.join(d, "estimate_smoothed.csv"),
                    "--smoothed-errors", os.path.join(d, "errors_smoothed.csv")]
        try:
            self.assertEqual(plot_run.main(), 0)
        finally:
            sys.argv = argv
        for png in ("trajectory_xy.png", "trajectory_3d.png", "position_error.png", "position_error_smoothed.png"):
            self.assertTrue(os.path.exists(os.path.join(out, png)), png)


if __name__ == "__main__":
    unittest.main()
