"""./meshnav import csv --map FILE: a synthetic CSV set in a temporary folder (exact values and unit
conversions), refusals (mapping keys, columns, bad rows, units that look wrong), and the example
mappings of config/import/ on the shared recordings (STAR-loc round trip, t1-a3-loiter ranges only)."""

import csv
import math
import os
import tempfile
import unittest

import realdata_support as rs

EXAMPLES = os.path.join(rs.REPO, "config", "import")
STARLOC_DIR = os.path.join(rs.SHARED, "data", "real-starloc-loop2d-s1")
T1A3_DIR = os.path.join(rs.SHARED, "data", "real-t1-a3-loiter")
T1A3_FILES = ("a01_ranges.csv", "a02_ranges.csv", "a03_ranges.csv", "d01_ranges.csv")


def write(path, text):
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)


def dump_yaml(path, data):
    import yaml
    write(path, yaml.safe_dump(data, sort_keys=False))


# Synthetic recording: ranges in ms and mm with anchor names, IMU in us, g and deg/s without a
# header (whitespace, columns by index, one axis flipped), truth in ns and cm with the quaternion
# w first, barometer in hPa, anchors from a CSV in mm.
UWB_CSV = ("time_ms,tag,anchor,dist_mm,quality\n"
           "1500,T1,A1,2345,0.9\n"
           "1000,T1,A2,1234,0.8\n"       # earlier than its predecessor: sorted
           "2000,T1,7,3000,1\n"          # anchor 7: integer id, no position (unknown anchor)
           "2500,T1,A1,600000,1\n")      # 600 m: beyond 500 m, dropped and counted
IMU_TXT = "\n".join(f"{11000000 + 100000 * k} 0 0.5 1 90 0 -180" for k in range(11)) + "\n"
GT_CSV = ("stamp_ns,x_cm,y_cm,z_cm,qw,qx,qy,qz\n"
          "11000000000,150,-20,100,1,0,0,0\n"
          "11500000000,160,-20,100,0,0,0,1\n")
BARO_CSV = "t,p_hpa\n11.0,1013.25\n11.5,1013.2\n"
ANCHORS_CSV = "name;x_mm;y_mm;z_mm\nA1;1000;2000;3000\nA2;-500;0;2500\n"


def synthetic_mapping():
    return {
        "version": 1,
        "description": "synthetic test set",
        "ids": {"map": {"T1": 100, "A1": 101, "A2": 102}},
        "tags": {"T1": [0.1, 0.0, -0.05]},
        "anchors_file": {"path": "anchors.csv", "delimiter": ";", "unit": "mm",
                         "columns": {"id": "name", "x": "x_mm", "y": "y_mm", "z": "z_mm"}},
        "noise": {"imu_acc_noise_density": 0.002, "imu_gyro_noise_density": 0.0002},
        "ranges": {"path": "uwb.csv", "time_unit": "ms", "time_offset": 10.0, "range_unit": "mm",
                   "columns": {"t": "time_ms", "range_raw": "dist_mm", "tag_id": "tag", "anchor_id": "anchor"}},
        "imu": {"path": "imu.txt", "header": False, "delimiter": "whitespace", "time_unit": "us",
                "acc_unit": "g", "gyro_unit": "deg/s",
                "columns": {"t": 0, "lin_acc_x": 1, "lin_acc_y": {"column": 2, "scale": -1}, "lin_acc_z": 3,
                            "ang_vel_x": 4, "ang_vel_y": 5, "ang_vel_z": 6}},
        "groundtruth": {"path": "gt.csv", "time_unit": "ns", "position_unit": "cm", "frame": "mocap",
                        "align_required": True,
                        "columns": {"t": "stamp_ns", "tx": "x_cm", "ty": "y_cm", "tz": "z_cm",
                                    "qx": "qx", "qy": "qy", "qz": "qz", "qw": "qw"}},
        "baro": {"path": "baro.csv", "pressure_unit": "hPa", "columns": {"t": "t", "pressure": "p_hpa"}},
    }


class _Synthetic(unittest.TestCase):
    """The synthetic set in a temporary folder, and its import."""

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.src = os.path.join(self.tmp.name, "rec")
        os.makedirs(self.src)
        for name, text in (("uwb.csv", UWB_CSV), ("imu.txt", IMU_TXT), ("gt.csv", GT_CSV), ("baro.csv", BARO_CSV),
                           ("anchors.csv", ANCHORS_CSV)):
            write(os.path.join(self.src, name), text)
        self.map = os.path.join(self.src, "mapping.yaml")
        self.out = os.path.join(self.tmp.name, "ds")

    def tearDown(self):
        self.tmp.cleanup()

    def run_map(self, data, *extra):
        dump_yaml(self.map, data)
        return rs.run_import("csv", "--map", self.map, "--out", self.out, *extra)


class SyntheticSet(_Synthetic):
    """Exact values out, every conversion, sorting, drops."""

    def test_values_units_and_order(self):
        code, log = self.run_map(synthetic_mapping())
        self.assertEqual(code, 0, log)
        ranges = rs.read_csv(os.path.join(self.out, "ranges.csv"))
        # ms -> s plus the 10 s offset, exact text; sorted by time; mm -> m exact
        self.assertEqual([r["t"] for r in ranges], ["11", "11.5", "12"])
        self.assertEqual([float(r["range_raw"]) for r in ranges], [1.234, 2.345, 3.0])
        self.assertEqual([float(r["range_corr"]) for r in ranges], [1.234, 2.345, 3.0])
        self.assertEqual([(r["UWB_ID1"], r["UWB_ID2"], r["type_ID1"], r["type_ID2"]) for r in ranges],
                         [("100", "102", "T", "A"), ("100", "101", "T", "A"), ("100", "7", "T", "A")])
        self.assertEqual({(r["R"], r["LOS"]) for r in ranges}, {("0", "1")})
        c = rs.counters(log)
        self.assertEqual(c["uwb.csv:time_backwards_sorted"], 1)
        self.assertEqual(c["uwb.csv:absurd_range"], 1)
        self.assertIn("uwb.csv:5: range 600.0 m is beyond", log)
        self.assertIn("1 samples earlier than their predecessor", log)
        self.assertIn("unknown, for the calibrator): [7]", log)

        imu = rs.read_csv(os.path.join(self.out, "imu.csv"))
        self.assertEqual(len(imu), 11)
        self.assertEqual(imu[0]["t"], "11")           # us -> s
        self.assertEqual(imu[1]["t"], "11.1")
        r = {k: float(v) for k, v in imu[0].items()}
        self.assertEqual((r["lin_acc_x"], r["lin_acc_y"], r["lin_acc_z"]), (0.0, -4.903325, 9.80665))  # g, flipped y
        self.assertEqual((r["ang_vel_x"], r["ang_vel_y"], r["ang_vel_z"]), (math.pi / 2, 0.0, -math.pi))  # deg/s

        gt = rs.read_csv(os.path.join(self.out, "groundtruth.csv"))
        self.assertEqual([g["#t"] for g in gt], ["11", "11.5"])   # ns -> s
        self.assertEqual([float(gt[0][k]) for k in ("tx", "ty", "tz", "qx", "qy", "qz", "qw")],
                         [1.5, -0.2, 1.0, 0.0, 0.0, 0.0, 1.0])   # cm -> m, quaternion reordered
        self.assertEqual(float(gt[1]["qz"]), 1.0)
        baro = rs.read_csv(os.path.join(self.out, "baro.csv"))
        self.assertEqual([float(b["pressure"]) for b in baro], [101325.0, 101320.0])  # hPa -> Pa

        setup = rs.read_yaml(os.path.join(self.out, "setup.yaml"))
        self.assertEqual(setup["rel_tag_positions"], {100: [0.1, 0.0, -0.05]})
        self.assertEqual(setup["abs_anchor_positions"], {101: [1.0, 2.0, 3.0], 102: [-0.5, 0.0, 2.5]})  # mm -> m
        self.assertEqual(setup["imu_id"], 1)
        self.assertEqual(setup["noise"], {"imu_acc_noise_density": 0.002, "imu_gyro_noise_density": 0.0002})
        truth = rs.read_yaml(os.path.join(self.out, "truth.yaml"))
        self.assertEqual(truth["truth_frame"], "mocap")
        self.assertIs(truth["align_required"], True)
        self.assertEqual(truth["anchor_positions"], setup["abs_anchor_positions"])

    def test_ranges_only_ids_by_offset_and_types_from_the_lists(self):
        data = synthetic_mapping()
        for k in ("imu", "groundtruth", "baro", "anchors_file"):
            del data[k]
        write(os.path.join(self.src, "r.csv"), "0.5 1 2 4.25\n0.7 2 3 5.5\n0.9 3 1 6\n")
        data.update(ids={"offset": 10}, tags={1: [0, 0, 0]}, anchors={2: [1, 2, 3]})
        data["ranges"] = {"path": "r.csv", "header": False, "delimiter": "space",
                          "columns": {"t": 0, "UWB_ID1": 1, "UWB_ID2": 2, "range_raw": 3, "LOS": {"value": 0}}}
        code, log = self.run_map(data)
        self.assertEqual(code, 0, log)
        self.assertIn("no imu stream in the mapping", log)
        self.assertFalse(os.path.exists(os.path.join(self.out, "imu.csv")))
        rows = rs.read_csv(os.path.join(self.out, "ranges.csv"))
        self.assertEqual([(r["t"], r["UWB_ID1"], r["UWB_ID2"], r["type_ID1"], r["type_ID2"], r["LOS"]) for r in rows],
                         [("0.5", "11", "12", "T", "A", "0"), ("0.7", "12", "13", "A", "A", "0"),
                          ("0.9", "13", "11", "A", "T", "0")])
        setup = rs.read_yaml(os.path.join(self.out, "setup.yaml"))
        self.assertEqual(setup["rel_tag_positions"], {11: [0.0, 0.0, 0.0]})
        self.assertEqual(setup["abs_anchor_positions"], {12: [1.0, 2.0, 3.0]})


class DocsExample(_Synthetic):
    """The complete mapping of docs/formats.md ("Importing your own CSVs") imports as documented."""

    def test_the_documented_mapping(self):
        text = rs.read_text(os.path.join(rs.REPO, "docs", "formats.md"))
        section = text.split("## Importing your own CSVs", 1)[1]
        example = section.split("```yaml\n", 1)[1].split("```", 1)[0]
        self.assertIn("base: ../recordings/run07", example)
        write(self.map, example.replace("base: ../recordings/run07", "base: ."))  # the files beside it
        files = {"anchors.csv": "name;x_mm;y_mm;z_mm\n5;1000;2000;3000\n",
                 "uwb_left.csv": "time_ms,tag,anchor,dist_mm,std_mm,los\n1000,T1,A1,2000,100,1\n1100,T1,7,2500,,0\n",
                 "uwb_right.csv": "time_ms,tag,anchor,dist_mm,std_mm,los\n1050,T1,A1,2010,100,true\n",
                 "imu.txt": "".join(f"{1000000 + 20000 * k} 0 0.5 1 1 2 3\n" for k in range(11)),
                 "mocap.csv": "stamp,x,y,z,qx,qy,qz,qw\n1000000000,1,2,3,0,0,0,1\n",
                 "baro.csv": "t,p\n1.0,1013.25\n"}
        for name, content in files.items():
            write(os.path.join(self.src, name), content)
        code, log = rs.run_import("csv", "--map", self.map, "--out", self.out)
        self.assertEqual(code, 0, log)
        ranges = rs.read_csv(os.path.join(self.out, "ranges.csv"))
        self.assertEqual([(r["t"], r["UWB_ID1"], r["UWB_ID2"], float(r["range_raw"]), float(r["R"]), r["LOS"])
                          for r in ranges],
                         [("1", "100", "101", 2.0, 0.01, "1"), ("1.05", "100", "101", 2.01, 0.01, "1"),
                          ("1.1", "100", "107", 2.5, 0.0, "0")])   # sigma 100 mm -> R 0.01 m^2; empty: 0
        imu = rs.read_csv(os.path.join(self.out, "imu.csv"))
        self.assertEqual(imu[0]["t"], "0.97")                      # 1 s - 30 ms
        self.assertEqual([float(imu[0][k]) for k in ("lin_acc_y", "ang_vel_y")], [-4.903325, -math.radians(2)])
        setup = rs.read_yaml(os.path.join(self.out, "setup.yaml"))
        self.assertEqual(setup["abs_anchor_positions"], {101: [1.0, 2.0, 3.0], 105: [1.0, 2.0, 3.0]})
        self.assertIn("unknown, for the calibrator): [107]", log)


class Refusals(_Synthetic):
    """Every refusal exits 1 with a message naming the file and the line (or the key), no traceback."""

    def refused(self, data, *want, extra=()):
        code, log = self.run_map(data, *extra)
        self.assertEqual(code, 1, log)
        self.assertNotIn("Traceback", log)
        for w in want:
            self.assertIn(w, log)
        return log

    def test_unknown_keys_and_bad_values_name_the_mapping_and_the_key(self):
        data = synthetic_mapping()
        data["imu_noise"] = {"acc": 1}
        self.refused(data, self.map + ":", "unknown key 'imu_noise'")
        data = synthetic_mapping()
        data["ranges"]["colums"] = data["ranges"].pop("columns")
        self.refused(data, self.map + ":", "unknown key 'ranges.colums'")
        data = synthetic_mapping()
        data["imu"]["columns"]["gyro_x"] = 4
        self.refused(data, "unknown key 'imu.columns.gyro_x'")
        data = synthetic_mapping()
        data["ranges"]["range_unit"] = "furlong"
        self.refused(data, "key 'ranges.range_unit' must be one of m, cm, mm or a positive number")
        data = synthetic_mapping()
        data["noise"]["imu_acc_noise_density"] = -1
        self.refused(data, "key 'noise.imu_acc_noise_density' must be > 0")
        data = synthetic_mapping()
        data["imu"]["columns"]["lin_acc_x"] = "ax"   # a name in a table without header
        self.refused(data, "key 'imu.columns.lin_acc_x' names column 'ax' but the table has header: false")
        data = synthetic_mapping()
        del data["ranges"]
        self.refused(data, "key 'ranges' is required")
        data = synthetic_mapping()
        del data["tags"]
        self.refused(data, "key 'tags' is required")

    def test_the_line_of_the_key_is_named(self):
        write(self.map, "version: 1\ntags: {1: [0, 0, 0]}\nranges:\n  path: uwb.csv\n  time_unit: minutes\n"
                        "  columns: {t: time_ms, range_raw: dist_mm, tag_id: tag, anchor_id: anchor}\n")
        code, log = rs.run_import("csv", "--map", self.map, "--out", self.out)
        self.assertEqual(code, 1, log)
        self.assertIn(f"{self.map}:5: key 'ranges.time_unit' must be one of s, ms, us", log)

    def test_missing_column(self):
        data = synthetic_mapping()
        data["ranges"]["columns"]["range_raw"] = "distance"
        self.refused(data, os.path.join(self.src, "uwb.csv") + ":1: missing column 'distance'",
                     "header has: time_ms, tag, anchor, dist_mm, quality")
        data = synthetic_mapping()
        data["imu"]["columns"]["ang_vel_z"] = 9
        self.refused(data, "imu.txt:1: imu.columns.ang_vel_z is column index 9 (0-based), but the first row has 7 fields")

    def test_bad_rows_name_file_and_line(self):
        uwb = os.path.join(self.src, "uwb.csv")
        for row, why in (("1700,T1,A1,nan,1", "range_raw (column 'dist_mm') 'nan' is not a finite number"),
                         ("1700,T1,A1,,1", "range_raw (column 'dist_mm') is empty"),
                         ("17x0,T1,A1,2000,1", "t (column 'time_ms') '17x0' is not a number"),
                         ("1700,T1,B9,2000,1", "anchor_id (column 'anchor') 'B9' is neither an id >= 0 nor listed in ids.map"),
                         ("1700,T1,A1", "3 fields where the header has 5")):
            write(uwb, UWB_CSV.replace("2000,T1,7,3000,1", row))
            log = self.refused(synthetic_mapping(), f"{uwb}:4: {why}", "--skip-bad-rows")
            self.assertFalse(os.path.exists(os.path.join(self.out, "ranges.csv")), log)
        write(uwb, UWB_CSV)
        write(os.path.join(self.src, "imu.txt"), IMU_TXT + "12200000 0 0 1 nan 0 0\n")
        self.refused(synthetic_mapping(), "imu.txt:12: ang_vel_x (column index 4) 'nan' is not a finite number")

    def test_skip_bad_rows_counts_them(self):
        write(os.path.join(self.src, "uwb.csv"), UWB_CSV.replace("2000,T1,7,3000,1", "1700,T1,A1,NaN,1"))
        code, log = self.run_map(synthetic_mapping(), "--skip-bad-rows")
        self.assertEqual(code, 0, log)
        self.assertEqual(rs.counters(log)["uwb.csv:bad_row"], 1)
        self.assertIn("uwb.csv:4: range_raw (column 'dist_mm') 'NaN' is not a finite number; row skipped", log)
        self.assertEqual(len(rs.read_csv(os.path.join(self.out, "ranges.csv"))), 2)

    def test_units_that_look_wrong_are_refused_unless_forced(self):
        # (stream, key, wrong unit, message, exit code with --force: 1 when the values as declared
        # are beyond the plausibility limits, so that no row is left)
        cases = (
            ("imu", "gyro_unit", "rad/s", "looks like deg/s (gyro_unit: deg/s", 1),
            ("imu", "acc_unit", "m/s^2", "as an accelerometer in g reads (acc_unit: g", 0),
            ("ranges", "range_unit", "m", "looks like millimetres (range_unit: mm", 1),
            ("ranges", "time_unit", "s", "looks like a finer time unit (time_unit: ms would give", 0),
            ("baro", "pressure_unit", "Pa", "looks like hPa or mbar", 0),
        )
        for stream, key, declared, want, forced_code in cases:
            with self.subTest(key=key):
                data = synthetic_mapping()
                data[stream][key] = declared
                if key == "time_unit":   # ranges over 30 days in s; the IMU follows to keep the overlap
                    write(os.path.join(self.src, "uwb.csv"), UWB_CSV.replace("2500,T1,A1,600000", "36000000,T1,A1,6000"))
                self.refused(data, "the data does not fit the declared units", want, "--force to import as declared")
                code, log = self.run_map(data, "--force")
                write(os.path.join(self.src, "uwb.csv"), UWB_CSV)
                self.assertEqual(code, forced_code, log)
                self.assertIn("(--force: imported as declared)", log)
                self.assertNotIn("Traceback", log)

    def test_rates_beyond_a_gyroscope_full_scale_look_like_deg_s(self):
        data = synthetic_mapping()
        data["imu"]["gyro_unit"] = "rad/s"
        rates = ["1 0 0"] * 9 + ["100 0 0"] * 2      # median 1 "rad/s", but 100 beyond any MEMS full scale
        write(os.path.join(self.src, "imu.txt"),
              "".join(f"{11000000 + 100000 * k} 0 0.5 1 {r}\n" for k, r in enumerate(rates)))
        self.refused(data, "beyond the full scale of MEMS gyroscopes", "this looks like deg/s (gyro_unit: deg/s)")

    def test_streams_that_do_not_overlap_are_refused(self):
        data = synthetic_mapping()
        data["imu"]["time_offset"] = 1000.0
        self.refused(data, "do not overlap in time: check time_unit and time_offset")

    def test_stale_files_in_out_are_refused(self):
        os.makedirs(self.out)
        write(os.path.join(self.out, "height.csv"), "t,range_m\n")
        self.refused(synthetic_mapping(), "already holds height.csv")

    def test_help(self):
        code, _ = rs.run_import("csv", "--help")
        self.assertEqual(code, 0)


class StarlocRoundTrip(unittest.TestCase):
    """The STAR-loc folder is a dataset already; the example mapping reads it as CSVs and must
    give its files back."""

    @classmethod
    def setUpClass(cls):
        rs.require(STARLOC_DIR)
        cls.tmp, cls.out, code, cls.log = rs.import_to_temp(
            "ds", "csv", "--map", os.path.join(EXAMPLES, "starloc-loop2d-s1.yaml"))
        assert code == 0, cls.log

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def same_csv(self, name, time_col):
        with open(os.path.join(STARLOC_DIR, name), newline="") as f:
            src = list(csv.reader(f))
        with open(os.path.join(self.out, name), newline="") as f:
            got = list(csv.reader(f))
        self.assertEqual(got[0], src[0])
        self.assertEqual(len(got), len(src))
        for a, b in zip(got[1:], src[1:]):
            self.assertEqual(a[time_col], b[time_col])     # the time text, digit for digit
            for i, (x, y) in enumerate(zip(a, b)):
                if i == time_col:
                    continue
                try:
                    self.assertEqual(float(x), float(y), (name, a[0], src[0][i]))
                except ValueError:
                    self.assertEqual(x, y, (name, a[0], src[0][i]))
        return len(got) - 1

    def test_ranges_imu_and_truth_come_back(self):
        self.assertEqual(self.same_csv("ranges.csv", 0), 7602)
        self.assertEqual(self.same_csv("imu.csv", 0), 3989)
        self.assertEqual(self.same_csv("groundtruth.csv", 0), 3989)
        self.assertEqual(rs.counters(self.log), {"ranges:tag_anchor": 7602})

    def test_setup_and_truth(self):
        got = rs.read_yaml(os.path.join(self.out, "setup.yaml"))
        src = rs.read_yaml(os.path.join(STARLOC_DIR, "setup.yaml"))
        for k in ("imu_id", "rel_tag_positions", "abs_anchor_positions"):
            self.assertEqual(got[k], src[k], k)
        truth = rs.read_yaml(os.path.join(self.out, "truth.yaml"))
        want = rs.read_yaml(os.path.join(STARLOC_DIR, "truth.yaml"))
        for k in ("anchor_positions", "truth_frame", "align_required"):
            self.assertEqual(truth[k], want[k], k)


class T1A3Loiter(unittest.TestCase):
    """The t1-a3-loiter example: four CSVs of the toolbox's format, ranges only, ids + 100."""

    @classmethod
    def setUpClass(cls):
        rs.require(T1A3_DIR)
        cls.tmp, cls.out, code, cls.log = rs.import_to_temp(
            "ds", "csv", "--map", os.path.join(EXAMPLES, "t1-a3-loiter.yaml"))
        assert code == 0, cls.log

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_ranges_kept_and_dropped(self):
        src = [r for name in T1A3_FILES for r in rs.read_csv(os.path.join(T1A3_DIR, name))]
        plausible = [r for r in src if -0.5 <= float(r["range_raw"]) <= 500.0]
        rows = rs.read_csv(os.path.join(self.out, "ranges.csv"))
        self.assertEqual(len(src), 1735 + 1624 + 1532 + 1977)
        self.assertEqual(len(rows), len(plausible))
        c = rs.counters(self.log)
        dropped = sum(v for k, v in c.items() if k.endswith((":absurd_range", ":negative_range")))
        self.assertEqual(dropped, len(src) - len(plausible))
        self.assertEqual(c["ranges:tag_anchor"] + c["ranges:anchor_anchor"], len(rows))
        times = [float(r["t"]) for r in rows]
        self.assertEqual(times, sorted(times))
        # stamps as recorded; ids + 100; ASCII type codes as letters; the range as measured
        want = sorted((r["t"], int(r["UWB_ID1"]) + 100, int(r["UWB_ID2"]) + 100,
                       chr(int(r["type_ID1"])), chr(int(r["type_ID2"])), float(r["range_raw"])) for r in plausible)
        got = sorted((r["t"], int(r["UWB_ID1"]), int(r["UWB_ID2"]), r["type_ID1"], r["type_ID2"],
                      float(r["range_raw"])) for r in rows)
        self.assertEqual(got, want)
        self.assertEqual({(r["range_corr"] == r["range_raw"], r["R"], r["LOS"]) for r in rows}, {(True, "0", "1")})

    def test_ranges_only_setup(self):
        self.assertIn("no imu stream in the mapping: the dataset holds ranges only", self.log)
        self.assertEqual(sorted(os.listdir(self.out)), ["ranges.csv", "setup.yaml"])
        setup = rs.read_yaml(os.path.join(self.out, "setup.yaml"))
        config = rs.read_yaml(os.path.join(T1A3_DIR, "config.yaml"))
        self.assertEqual(setup["rel_tag_positions"], {k + 100: v for k, v in config["rel_tag_positions"].items()})
        self.assertEqual(setup["abs_anchor_positions"], {k + 100: v for k, v in config["abs_anchor_positions"].items()})
        self.assertEqual(setup["imu_id"], 1)


if __name__ == "__main__":
    unittest.main()
