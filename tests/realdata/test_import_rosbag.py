"""./meshnav import rosbag on the shared ISAS-Walk1 bag (checked against the bag read independently)
and on small synthetic bags with bad and unknown messages."""

import math
import os
import tempfile
import unittest

import realdata_support as rs


def _stamp(h):
    return f"{h.stamp.secs}.{h.stamp.nsecs:09d}"


class IsasWalk1(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rs.require(rs.ISAS_BAG)
        cls.tmp, cls.out, cls.code, cls.log = rs.import_to_temp("isas", "rosbag", "--bag", rs.ISAS_BAG)
        import rosbag
        cls.imu, cls.fresh, cls.stale, cls.vive = [], [], 0, []
        with rosbag.Bag(rs.ISAS_BAG) as bag:
            for topic, msg, _ in bag.read_messages():
                if topic == "/waveshare_sense_hat_b":
                    cls.imu.append((_stamp(msg.header), msg.linear_acceleration.z))
                elif topic == "/rtls_flares":
                    for r in msg.ranges:
                        if r.ra == 1:
                            cls.fresh.append((_stamp(msg.header), r.id, r.range))
                        else:
                            cls.stale += 1
                elif topic == "/vive/transform/tracker_1_ref":
                    cls.vive.append((_stamp(msg.header), msg.transform.translation.x))

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_import_succeeds_and_reports_stale_repeats(self):
        self.assertEqual(self.code, 0, self.log)
        c = rs.counters(self.log)
        self.assertEqual(c["uwb:stale_dropped"], 584)
        self.assertEqual(c["uwb:stale_dropped"], self.stale)
        self.assertEqual(c["uwb:ranges_in_messages"], 4850)
        self.assertIn("not imported: /rtls_pose", self.log)

    def test_ranges_are_exactly_the_fresh_ones_with_the_recordings_stamps(self):
        rows = rs.read_csv(os.path.join(self.out, "ranges.csv"))
        self.assertEqual(len(rows), 4266)
        got = [(r["t"], int(r["UWB_ID2"]), float(r["range_raw"])) for r in rows]
        self.assertEqual(sorted(got), sorted(self.fresh))
        self.assertEqual({(r["UWB_ID1"], r["type_ID1"], r["type_ID2"], r["R"]) for r in rows}, {("1000", "T", "A", "0")})
        self.assertEqual({g[1] for g in got}, {7475, 20276, 9524, 10548, 15155})

    def test_imu_and_truth_keep_header_stamps_in_full_precision(self):
        imu = rs.read_csv(os.path.join(self.out, "imu.csv"))
        self.assertEqual(len(imu), 4839)
        self.assertEqual([(r["t"], float(r["lin_acc_z"])) for r in imu], sorted(self.imu, key=lambda x: float(x[0])))
        self.assertEqual(imu[0]["t"], "1664959676.974539702")
        gt = rs.read_csv(os.path.join(self.out, "groundtruth.csv"))
        self.assertEqual(len(gt), 3168)
        self.assertEqual([(r["#t"], float(r["tx"])) for r in gt], self.vive)

    def test_setup_and_truth_yaml(self):
        setup = rs.read_yaml(os.path.join(self.out, "setup.yaml"))
        self.assertEqual(setup["rel_tag_positions"], {1000: [0.1, -0.025, 0.0]})
        self.assertEqual(sorted(setup["abs_anchor_positions"]), [7475, 9524, 10548, 15155, 20276])
        self.assertEqual(setup["abs_anchor_positions"][20276], [5.5, 0.0, 0.0])
        self.assertNotIn("pair_biases", setup)
        self.assertNotIn("baro", setup)
        self.assertNotIn("initial_pose", setup)
        self.assertAlmostEqual(setup["noise"]["imu_gyro_noise_density"], 10 * math.radians(0.015))
        truth = rs.read_yaml(os.path.join(self.out, "truth.yaml"))
        self.assertEqual(truth["truth_frame"], "vive/reference")
        self.assertIs(truth["align_required"], True)
        self.assertIn("ISAS-Walk1 README", self.log)  # where the lever arm came from

    def test_options_tag_id_lever_arm_and_truth_topic(self):
        out = os.path.join(self.tmp.name, "opts")
        code, log = rs.run_import("rosbag", "--bag", rs.ISAS_BAG, "--out", out, "--tag-id", "7",
                                  "--tag-lever-arm", "0,0,0.5", "--truth-topic", "/rtls_pose")
        self.assertEqual(code, 0, log)
        self.assertEqual({r["UWB_ID1"] for r in rs.read_csv(os.path.join(out, "ranges.csv"))}, {"7"})
        self.assertIn("  7: [0.0, 0.0, 0.5]", rs.read_text(os.path.join(out, "setup.yaml")))
        self.assertEqual(len(rs.read_csv(os.path.join(out, "groundtruth.csv"))), 970)
        code, log = rs.run_import("rosbag", "--bag", rs.ISAS_BAG, "--out", out, "--imu-topic", "/rtls_flares")
        self.assertEqual(code, 1)
        self.assertIn("expected one of sensor_msgs/Imu", log)


_HEADER = "uint32 seq\ntime stamp\nstring frame_id\n"
_POINT = "float64 x\nfloat64 y\nfloat64 z\n"
_SEP = "=" * 80 + "\n"
_STICK_DEF = ("std_msgs/Header header\nuint32 id\nfraunhofer_rtls_flare/Range[] ranges\n" + _SEP + "MSG: std_msgs/Header\n"
              + _HEADER + _SEP + "MSG: fraunhofer_rtls_flare/Range\nuint32 id\ngeometry_msgs/Point pos\nfloat32 range\n"
              "uint8 ra\n" + _SEP + "MSG: geometry_msgs/Point\n" + _POINT)
_CHATTER_DEF = "string data\n"


def _synthetic_bag(path):
    """A bag with one tag's ranges (fresh, stale, NaN, absurd, bad ra), an unknown topic, and no
    IMU, anchor list or truth. Returns nothing; the test checks the counters."""
    import genpy
    import genpy.dynamic
    import rosbag
    stick_t = genpy.dynamic.generate_dynamic("fraunhofer_rtls_flare/RTLSStick", _STICK_DEF)
    chat_t = genpy.dynamic.generate_dynamic("demo_msgs/Chatter", _CHATTER_DEF)
    Stick, Range, Point = (stick_t["fraunhofer_rtls_flare/RTLSStick"], stick_t["fraunhofer_rtls_flare/Range"],
                           stick_t["geometry_msgs/Point"])
    with rosbag.Bag(path, "w") as bag:
        for k in range(3):
            m = Stick()
            m.header.stamp = genpy.Time(100 + k, 123456789)
            m.id = 42
            m.ranges = [Range(id=5, pos=Point(1, 2, 3), range=2.5, ra=1), Range(id=6, pos=Point(4, 5, 6), range=3.0, ra=0),
                        Range(id=7, pos=Point(0, 0, 1), range=[float("nan"), 900.0, 1.5][k], ra=[1, 1, 3][k])]
            bag.write("/flares", m, genpy.Time(100 + k))
            bag.write("/chatter", chat_t["demo_msgs/Chatter"](data="hi"), genpy.Time(100 + k))


class SyntheticBag(unittest.TestCase):
    def test_bad_ranges_are_counted_and_unknown_topics_listed(self):
        with tempfile.TemporaryDirectory() as tmp:
            bag = os.path.join(tmp, "s.bag")
            _synthetic_bag(bag)
            code, log = rs.run_import("rosbag", "--bag", bag, "--out", os.path.join(tmp, "ds"))
            self.assertEqual(code, 0, log)
            c = rs.counters(log)
            self.assertEqual(c["uwb:stale_dropped"], 3)
            self.assertEqual(c["uwb:bad_range"], 2)  # NaN and 900 m
            self.assertEqual(c["uwb:bad_ra"], 1)
            self.assertIn("/flares #0 range 2: range nan m", log)
            self.assertIn("not imported: /chatter (demo_msgs/Chatter, 3 messages)", log)
            self.assertIn("truth topic: none", log)
            rows = rs.read_csv(os.path.join(tmp, "ds", "ranges.csv"))
            self.assertEqual([(r["t"], r["UWB_ID2"]) for r in rows],
                             [("100.123456789", "5"), ("101.123456789", "5"), ("102.123456789", "5")])
            self.assertFalse(os.path.exists(os.path.join(tmp, "ds", "groundtruth.csv")))
            # No anchor list: positions come from the ranges' pos fields (ids of kept ranges only).
            self.assertIn("5: [1.0, 2.0, 3.0]", rs.read_text(os.path.join(tmp, "ds", "setup.yaml")))

    def test_a_damaged_bag_is_a_clear_error_and_writes_nothing(self):
        # Issue 36: a damaged chunk gave a Python traceback. 4 KiB of 0xff in the middle of a copy of
        # ISAS-Walk1: the reader cannot go past it; the import stops with the place, exit 1.
        rs.require(rs.ISAS_BAG)
        with tempfile.TemporaryDirectory() as tmp:
            bad = os.path.join(tmp, "damaged.bag")
            with open(rs.ISAS_BAG, "rb") as f:
                data = bytearray(f.read())
            data[1600000:1600000 + 4096] = b"\xff" * 4096
            with open(bad, "wb") as f:
                f.write(data)
            out = os.path.join(tmp, "ds")
            code, log = rs.run_import("rosbag", "--bag", bad, "--out", out)
            self.assertEqual(code, 1, log)
            self.assertIn(f"{bad}: damaged after ", log)
            self.assertNotIn("Traceback", log)
            self.assertFalse(os.path.exists(out))

    def test_not_a_bag_is_a_clear_error(self):
        with tempfile.TemporaryDirectory() as tmp:
            bad = os.path.join(tmp, "bad.bag")
            with open(bad, "wb") as f:
                f.write(b"#ROSBAG V2.0\n" + b"\x00garbage" * 10)
            code, log = rs.run_import("rosbag", "--bag", bad, "--out", os.path.join(tmp, "ds"))
            self.assertEqual(code, 1)
            self.assertIn("cannot open as a ROS 1 bag", log)


if __name__ == "__main__":
    unittest.main()
