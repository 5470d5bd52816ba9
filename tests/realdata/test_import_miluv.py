"""./meshnav import miluv on the shared MILUV flight (ifo001, ifo002) and on a synthetic folder with
bad rows. The truth columns of uwb_range.csv must not reach any file the estimator reads."""

import os
import tempfile
import unittest

import realdata_support as rs

TRUTH_COLUMNS = ("gt_range", "bias", "bias_raw", "r_iw_a", "q_ai", "std")
#: Files of a dataset that the estimator or calibrator read (truth.yaml and groundtruth.csv are
#: evaluation only).
ESTIMATOR_FILES = ("imu.csv", "ranges.csv", "setup.yaml", "height.csv")


class MiluvRobot(unittest.TestCase):
    ROBOTS = {"ifo001": {"ranges": 148, "anchor": 65, "inter": 83, "imu": 15615, "mocap": 7844, "height": 2362},
              "ifo002": {"ranges": 149, "inter": 81}}

    @classmethod
    def setUpClass(cls):
        rs.require(rs.MILUV_DIR)
        cls.tmp = tempfile.TemporaryDirectory()
        cls.out, cls.logs = {}, {}
        for robot in cls.ROBOTS:
            cls.out[robot] = os.path.join(cls.tmp.name, robot)
            code, cls.logs[robot] = rs.run_import("miluv", "--dir", rs.MILUV_DIR, "--robot", robot, "--out", cls.out[robot])
            assert code == 0, cls.logs[robot]

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def source(self, robot, name):
        return rs.read_csv(os.path.join(rs.MILUV_DIR, robot, name))

    def test_row_counts_and_range_kinds(self):
        for robot, want in self.ROBOTS.items():
            rows = rs.read_csv(os.path.join(self.out[robot], "ranges.csv"))
            self.assertEqual(len(rows), want["ranges"], robot)
            inter = [r for r in rows if r["type_ID1"] == "T" and r["type_ID2"] == "T"]
            self.assertEqual(len(inter), want["inter"], robot)
            c = rs.counters(self.logs[robot])
            self.assertEqual(c["ranges:inter_robot"], want["inter"])
        d = os.path.join(self.out["ifo001"], "")
        self.assertEqual(len(rs.read_csv(d + "imu.csv")), self.ROBOTS["ifo001"]["imu"])
        self.assertEqual(len(rs.read_csv(d + "groundtruth.csv")), self.ROBOTS["ifo001"]["mocap"])
        self.assertEqual(len(rs.read_csv(d + "height.csv")), self.ROBOTS["ifo001"]["height"])

    def test_ranges_are_the_measured_column_with_recorded_stamps_and_mapped_ids(self):
        src = self.source("ifo001", "uwb_range.csv")
        rows = rs.read_csv(os.path.join(self.out["ifo001"], "ranges.csv"))
        by_time = {r["t"]: r for r in rows}
        for s in src:
            r = by_time[s["timestamp"]]  # the recorded stamp text, unchanged
            self.assertEqual(float(r["range_raw"]), float(s["range"]))
            ids = [int(s["from_id"]), int(s["to_id"])]
            want = [i + 100 if i <= 5 else i for i in ids]
            self.assertEqual([int(r["UWB_ID1"]), int(r["UWB_ID2"])], want)
            self.assertEqual([r["type_ID1"], r["type_ID2"]], ["A" if i <= 5 else "T" for i in ids])

    def test_truth_columns_never_reach_estimator_files(self):
        for robot in self.ROBOTS:
            src = self.source(robot, "uwb_range.csv")
            truth_texts = set()
            for s in src:
                for col in ("gt_range", "bias", "bias_raw", "std"):
                    truth_texts.add(repr(float(s[col])))   # as the importer would write a float
                    truth_texts.add(s[col])                # as published
            for name in ESTIMATOR_FILES:
                text = rs.read_text(os.path.join(self.out[robot], name))
                for col in TRUTH_COLUMNS:
                    self.assertNotIn(col, text.split("\n", 1)[0].split(","), f"{robot}/{name} header")
                self.assertNotIn("r_iw_a", text)
                self.assertNotIn("q_ai", text)
                fields = set(text.replace("\n", ",").replace("[", ",").replace("]", ",").replace(" ", "").split(","))
                leaked = fields & truth_texts
                self.assertFalse(leaked, f"{robot}/{name} carries truth values {sorted(leaked)[:5]}")
            self.assertEqual(rs.read_text(os.path.join(self.out[robot], "ranges.csv")).split("\n", 1)[0],
                             "t,range_raw,range_corr,R,UWB_ID1,UWB_ID2,type_ID1,type_ID2,LOS")

    def test_frames_setup_and_truth(self):
        setup = rs.read_yaml(os.path.join(self.out["ifo002"], "setup.yaml"))
        self.assertEqual(sorted(setup["rel_tag_positions"]), [20, 21])
        self.assertEqual(sorted(setup["abs_anchor_positions"]), [100, 101, 102, 103, 104, 105])
        self.assertEqual(setup["imu_id"], 1)
        self.assertNotIn("baro", setup)
        # MILUV's `range` column is calibrated (its raw range is `range_raw`): unlisted pairs exact.
        self.assertEqual(setup["noise"], {"sigma_gamma": 0.0})
        truth = rs.read_yaml(os.path.join(self.out["ifo002"], "truth.yaml"))
        self.assertIs(truth["align_required"], False)
        self.assertEqual(truth["anchor_positions"], setup["abs_anchor_positions"])
        gt = rs.read_csv(os.path.join(self.out["ifo002"], "groundtruth.csv"))
        mocap = self.source("ifo002", "mocap.csv")
        self.assertEqual(gt[0]["#t"], mocap[0]["timestamp"])
        self.assertEqual(float(gt[0]["qw"]), float(mocap[0]["pose.orientation.w"]))
        imu = rs.read_csv(os.path.join(self.out["ifo002"], "imu.csv"))
        src_imu = self.source("ifo002", "imu_px4.csv")
        self.assertEqual(imu[-1]["t"], src_imu[-1]["timestamp"])
        self.assertEqual(float(imu[-1]["lin_acc_z"]), float(src_imu[-1]["linear_acceleration.z"]))
        self.assertEqual(float(imu[-1]["ang_vel_x"]), float(src_imu[-1]["angular_velocity.x"]))


class MiluvBadInput(unittest.TestCase):
    def test_bad_rows_are_counted_with_file_and_line(self):
        with tempfile.TemporaryDirectory() as tmp:
            exp = os.path.join(tmp, "exp")
            os.makedirs(os.path.join(exp, "ifo001"))
            rs_path = os.path.join(exp, "ifo001")
            with open(os.path.join(exp, "anchors.yaml"), "w") as f:
                f.write("0: [1, 2, 3]\n1: [4, 5, 6]\n")
            with open(os.path.join(exp, "tags.yaml"), "w") as f:
                f.write("ifo001: {10: [0.1, 0, 0]}\nifo002: {20: [0, 0.1, 0]}\n")
            with open(os.path.join(rs_path, "uwb_range.csv"), "w") as f:
                f.write("range,from_id,to_id,gt_range,bias,timestamp\n"
                        "2.5,10,0,2.4,0.1,1.5\n"      # kept (tag-anchor)
                        "nan,10,1,2.4,0.1,1.6\n"      # not finite
                        "2.5,10,9,2.4,0.1,1.7\n"      # unknown partner
                        "2.5,20,1,2.4,0.1,1.8\n"      # another robot's range to an anchor
                        "3.5,20,10,3.4,0.1,abc\n"     # bad time
                        "3.5,20,10,3.4,0.1,1.9\n")    # kept (inter-robot)
            with open(os.path.join(rs_path, "imu_px4.csv"), "w") as f:
                f.write(",".join(["timestamp", "angular_velocity.x", "angular_velocity.y", "angular_velocity.z",
                                  "linear_acceleration.x", "linear_acceleration.y", "linear_acceleration.z"]) + "\n"
                        "0.5,0,0,0,0,0,9.8\n0.6,0,0,x,0,0,9.8\n")
            with open(os.path.join(rs_path, "mocap.csv"), "w") as f:
                f.write("timestamp,pose.position.x,pose.position.y,pose.position.z,pose.orientation.x,"
                        "pose.orientation.y,pose.orientation.z,pose.orientation.w\n0.5,0,0,0,0,0,0,1\n0.6,0,0,0,0,0,0,3\n")
            out = os.path.join(tmp, "ds")
            code, log = rs.run_import("miluv", "--dir", exp, "--robot", "ifo001", "--out", out)
            self.assertEqual(code, 0, log)
            c = rs.counters(log)
            self.assertEqual(c["uwb_range.csv:bad_value"], 2)
            self.assertEqual(c["uwb_range.csv:not_this_robot"], 2)
            self.assertEqual(c["imu_px4.csv:bad_value"], 1)
            self.assertEqual(c["mocap.csv:bad_quaternion"], 1)
            self.assertIn("uwb_range.csv:3: a needed value", log)
            rows = rs.read_csv(os.path.join(out, "ranges.csv"))
            self.assertEqual([(r["UWB_ID1"], r["UWB_ID2"], r["type_ID2"]) for r in rows], [("10", "100", "A"), ("20", "10", "T")])
            self.assertFalse(os.path.exists(os.path.join(out, "height.csv")))  # optional input absent

    def test_unknown_robot_and_clashing_ids_are_clear_errors(self):
        rs.require(rs.MILUV_DIR)
        with tempfile.TemporaryDirectory() as tmp:
            code, log = rs.run_import("miluv", "--dir", rs.MILUV_DIR, "--robot", "ifo009", "--out", tmp)
            self.assertEqual(code, 1)
            self.assertIn("no tags for robot 'ifo009'", log)
            code, log = rs.run_import("miluv", "--dir", rs.MILUV_DIR, "--robot", "ifo001", "--out", tmp,
                                      "--anchor-id-offset", "10")
            self.assertEqual(code, 1)
            self.assertIn("clash", log)


class MiluvAllRobots(unittest.TestCase):
    """`--robot all` (issue 38 item 4): one dataset per robot folder, the same as importing each
    alone, and a fleet.yaml that `meshnav run --fleet` takes, vehicles named as the robots; a robot
    folder added to the experiment is imported without code changes."""

    def test_every_robot_with_a_folder_and_a_fleet_file(self):
        rs.require(rs.MILUV_DIR)
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "fleet")
            code, log = rs.run_import("miluv", "--dir", rs.MILUV_DIR, "--robot", "all", "--out", out)
            self.assertEqual(code, 0, log)
            self.assertIn("ifo003", log)  # in tags.yaml, no folder here: said, and skipped
            fleet = rs.read_yaml(os.path.join(out, "fleet.yaml"))
            self.assertEqual(fleet, {"vehicles": [{"name": "ifo001", "dataset": "ifo001"},
                                                  {"name": "ifo002", "dataset": "ifo002"}]})
            for robot in ("ifo001", "ifo002"):
                alone = os.path.join(tmp, robot)
                code, log = rs.run_import("miluv", "--dir", rs.MILUV_DIR, "--robot", robot, "--out", alone)
                self.assertEqual(code, 0, log)
                for name in ("imu.csv", "ranges.csv", "groundtruth.csv", "height.csv", "setup.yaml"):
                    self.assertEqual(rs.read_text(os.path.join(out, robot, name)), rs.read_text(os.path.join(alone, name)),
                                     f"{robot}/{name}")

    def test_an_added_robot_folder_becomes_a_vehicle(self):
        rs.require(rs.MILUV_DIR)
        with tempfile.TemporaryDirectory() as tmp:
            exp = os.path.join(tmp, "exp")
            os.makedirs(exp)
            for name in ("anchors.yaml", "tags.yaml"):
                os.symlink(os.path.join(rs.MILUV_DIR, name), os.path.join(exp, name))
            # ifo003 is in tags.yaml; its folder here is ifo002's recording (the importer keeps only
            # ranges that involve ifo003's own tags, so it gets none of them: still a dataset).
            for robot, src in (("ifo001", "ifo001"), ("ifo003", "ifo002")):
                os.symlink(os.path.join(rs.MILUV_DIR, src), os.path.join(exp, robot))
            out = os.path.join(tmp, "fleet")
            code, log = rs.run_import("miluv", "--dir", exp, "--robot", "all", "--out", out)
            self.assertEqual(code, 0, log)
            names = [v["name"] for v in rs.read_yaml(os.path.join(out, "fleet.yaml"))["vehicles"]]
            self.assertEqual(names, ["ifo001", "ifo003"])
            self.assertTrue(os.path.isfile(os.path.join(out, "ifo003", "imu.csv")))

    def test_no_robot_folder_is_a_clear_error(self):
        rs.require(rs.MILUV_DIR)
        with tempfile.TemporaryDirectory() as tmp:
            for name in ("anchors.yaml", "tags.yaml"):
                os.symlink(os.path.join(rs.MILUV_DIR, name), os.path.join(tmp, name))
            code, log = rs.run_import("miluv", "--dir", tmp, "--robot", "all", "--out", os.path.join(tmp, "o"))
            self.assertEqual(code, 1, log)
            self.assertIn("no robot of", log)


if __name__ == "__main__":
    unittest.main()
