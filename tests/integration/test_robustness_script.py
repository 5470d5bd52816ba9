"""Unit tests of scripts/robustness.py (no binaries needed): the scenario draw, the fixed list,
the meshnav_sim arguments, the metrics of one run, and usage errors."""

import os
import sys
import tempfile
import unittest

ROOT = os.environ.get("MESHNAV_SOURCE_DIR", os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import robustness  # noqa: E402


class DrawTest(unittest.TestCase):
    def test_same_seed_same_scenarios_other_seed_other_scenarios(self):
        a, b, c = robustness.draw_scenarios(20, 7, 60), robustness.draw_scenarios(20, 7, 60), robustness.draw_scenarios(20, 8, 60)
        self.assertEqual(a, b)
        self.assertNotEqual(a, c)
        self.assertEqual(robustness.draw_scenarios(5, 7, 60), a[:5])  # a prefix does not depend on N

    def test_draws_stay_in_the_sweep_space(self):
        scs = robustness.draw_scenarios(300, 3, 75)
        for sc in scs:
            self.assertIn(sc["trajectory"], robustness.TRAJECTORIES)
            self.assertIn(sc["anchor_layout"], robustness.LAYOUTS)
            self.assertIn(sc["imu_grade"], robustness.IMU_GRADES)
            self.assertTrue(6.0 <= sc["hall"][0] <= 12.0 and 6.0 <= sc["hall"][1] <= 12.0 and 3.0 <= sc["hall"][2] <= 8.0)
            self.assertTrue(1 <= sc["tags"] <= 3 and 3 <= sc["known"] <= 5 and sc["known"] + sc["unknown"] <= 9)
            self.assertTrue(0.10 <= sc["sigma_range"] <= 0.20 and 0.0 <= sc["outliers"] <= 0.15 and 0.0 <= sc["drop"] <= 0.05)
            self.assertEqual(sc["duration"], 75)
        # Every value of every choice occurs.
        for key, values in (("trajectory", robustness.TRAJECTORIES), ("anchor_layout", robustness.LAYOUTS),
                            ("tags", [1, 2, 3]), ("known", [3, 4, 5])):
            self.assertEqual({sc[key] for sc in scs}, set(values), key)

    def test_widened_draws_the_same_scenarios_with_real_range_errors(self):
        # --widened (issue 34): the standard draw plus the NLOS excess, the errors' correlation time,
        # the stamps' delay and the IMU's axis errors of real hardware, passed to meshnav_sim; the
        # other keys are those of the plain draw.
        plain, wide = robustness.draw_scenarios(50, 3, 75), robustness.draw_scenarios(50, 3, 75, widened=True)
        for p, w in zip(plain, wide):
            self.assertEqual({k: v for k, v in w.items() if k not in ("nlos", "range_correlation", "range_time_offset",
                                                                       "imu_scale_sigma", "imu_misalignment")}, p)
            self.assertEqual(w["nlos"], "exponential")
            self.assertTrue(0.0 <= w["range_correlation"] <= 0.3)
            args = robustness.sim_args(w)
            self.assertEqual(args[args.index("--nlos") + 1], "exponential")
            self.assertEqual(float(args[args.index("--range-correlation") + 1]), w["range_correlation"])
            self.assertTrue(-0.05 <= w["range_time_offset"] <= 0.05)
            self.assertEqual(float(args[args.index("--range-time-offset") + 1]), w["range_time_offset"])
            scale_max, misalignment_max = robustness.IMU_AXIS_ERRORS[w["imu_grade"]]
            self.assertTrue(0.0 <= w["imu_scale_sigma"] <= scale_max and 0.0 <= w["imu_misalignment"] <= misalignment_max)
            self.assertEqual(float(args[args.index("--imu-misalignment") + 1]), w["imu_misalignment"])
        self.assertGreater(len({w["range_correlation"] for w in wide}), 40)
        self.assertGreater(len({w["range_time_offset"] for w in wide}), 40)


class FixedListTest(unittest.TestCase):
    def test_fixed12_covers_every_kind_layout_and_tag_count_with_outliers(self):
        scs = robustness.load_scenarios(os.path.join(ROOT, "config", "robustness", "fixed12.yaml"))
        self.assertEqual(len(scs), 12)
        self.assertEqual(len({s["name"] for s in scs}), 12)
        self.assertEqual({s["trajectory"] for s in scs}, set(robustness.TRAJECTORIES))
        self.assertEqual({s["anchor_layout"] for s in scs}, set(robustness.LAYOUTS))
        self.assertEqual({s["tags"] for s in scs}, {1, 2, 3})
        self.assertTrue(all(s["outliers"] > 0 for s in scs))
        self.assertTrue(all(60 <= s["duration"] <= 90 for s in scs))

    def test_unknown_keys_and_duplicate_names_are_rejected(self):
        with tempfile.TemporaryDirectory(prefix="meshnav_robustness_test_") as d:
            path = os.path.join(d, "scenarios.yaml")
            with open(path, "w") as g:
                g.write("scenarios:\n  - {name: a, trajectroy: walk}\n")
            with self.assertRaisesRegex(ValueError, "trajectroy"):
                robustness.load_scenarios(path)
            with open(path, "w") as g:
                g.write("scenarios:\n  - {name: a}\n  - {name: a}\n")
            with self.assertRaisesRegex(ValueError, "unique"):
                robustness.load_scenarios(path)

    def test_sim_arguments(self):
        args = robustness.sim_args({"name": "x", "seed": 4, "trajectory": "walk", "hall": [10, 8, 3], "outliers": 0.1,
                                    "anchor_layout": "one-wall", "imu_grade": "consumer"})
        self.assertEqual(args, ["--seed", "4", "--trajectory", "walk", "--anchor-layout", "one-wall", "--outliers", "0.1",
                                "--imu-grade", "consumer", "--hall", "10,8,3"])


class MetricsTest(unittest.TestCase):
    def write(self, d, name, text):
        p = os.path.join(d, name)
        with open(p, "w") as f:
            f.write(text)
        return p

    def test_divergence_counts_only_after_the_first_ten_seconds(self):
        with tempfile.TemporaryDirectory() as d:
            m = self.write(d, "m.json", '{"pose": {"position": {"rmse_m": 0.5, "anees": 3.1}, "orientation": {"rmse_deg": 2.0}}}')
            status = self.write(d, "status.txt", "strategy: dp\ncounters:\n  gated_range: 3\n  recovery: 2\nmean_step_us:\n  x: 1\n")
            early_big = self.write(d, "e1.csv", "t,ep_norm_m\n5.0,0.1\n9.0,3.0\n15.0,0.9\n40.0,0.2\n")
            r = robustness.metrics_of(m, early_big, status)
            self.assertFalse(r["diverged"])
            self.assertAlmostEqual(r["max_err_after_10s_m"], 0.9)
            self.assertEqual(r["recoveries"], 2)
            self.assertFalse(r["collinear"])
            line = self.write(d, "line.txt", "counters:\n  known_anchors_nearly_collinear: 1\n  recovery: 1\n")
            self.assertTrue(robustness.metrics_of(m, early_big, line)["collinear"])
            self.assertEqual(robustness.read_counter(line, "recovery"), 1)
            self.assertEqual(robustness.read_counter(line, "gated_range"), 0)
            self.assertEqual(r["pos_rmse_m"], 0.5)
            late_big = self.write(d, "e2.csv", "t,ep_norm_m\n5.0,0.1\n15.0,1.01\n")
            self.assertTrue(robustness.metrics_of(m, late_big, os.path.join(d, "missing.txt"))["diverged"])
            self.assertEqual(robustness.read_recoveries(os.path.join(d, "missing.txt")), 0)
            nan = self.write(d, "e3.csv", "t,ep_norm_m\n5.0,0.1\n15.0,nan\n")
            self.assertTrue(robustness.metrics_of(m, nan, status)["diverged"])  # a NaN estimate is not converged
            empty_pose = self.write(d, "n.json", '{"pose": null}')
            with self.assertRaises(RuntimeError):
                robustness.metrics_of(empty_pose, early_big, status)


class AnchorMetricsTest(unittest.TestCase):
    """--calibration auto: the calibrated anchors of meshnav_eval's JSON, the columns, a bad anchor."""

    def eval_json(self, final_errors):
        anchors = [{"id": 101, "known": True, "final": {"error_m": 0.0, "nees": None}}]
        anchors += [{"id": 106 + i, "known": False, "final": {"error_m": e, "nees": 2.0 + 10 * i}}
                    for i, e in enumerate(final_errors)]
        return {"pose": {"position": {"rmse_m": 0.1, "anees": 3.0}, "orientation": {"rmse_deg": 1.0}},
                "anchors": {"per_anchor": anchors}}

    def test_known_anchors_are_not_scored_and_the_worst_calibrated_one_is(self):
        m = robustness.anchor_metrics(self.eval_json([0.05, 0.62]))
        self.assertEqual(m["anchors_calibrated"], 2)
        self.assertAlmostEqual(m["anchor_err_max_m"], 0.62)
        self.assertAlmostEqual(m["anchor_nees_max"], 12.0)
        none = robustness.anchor_metrics(self.eval_json([]))
        self.assertEqual(none["anchors_calibrated"], 0)
        self.assertNotEqual(none["anchor_err_max_m"], none["anchor_err_max_m"])  # NaN: nothing to score

    def test_a_bad_anchor_fails_the_run_and_shows_in_the_columns(self):
        sc = {"name": "r", "unknown": 3}
        good = dict(ok=True, scenario=sc, pos_rmse_m=0.1, max_err_after_10s_m=0.2, ori_rmse_deg=1.0, pos_anees=3.0,
                    diverged=False, recoveries=0, collinear=True, refused=False, error="",
                    **robustness.anchor_metrics(self.eval_json([0.05, 0.1])))
        bad = dict(good, **robustness.anchor_metrics(self.eval_json([0.05, 0.62])))
        self.assertFalse(robustness.is_bad_anchor_run(good))
        self.assertTrue(robustness.is_bad_anchor_run(bad))
        cols = robustness.columns("auto")
        row = robustness.row_of(bad, "auto")
        self.assertEqual(len(row), len(cols))
        self.assertEqual(row[cols.index("anchors")], "2/3")
        self.assertEqual(row[cols.index("anchor_err_max_m")], "0.620")
        self.assertEqual(row[cols.index("collinear")], "yes")
        self.assertEqual(robustness.row_of(bad, "off"), robustness.base_row_of(bad))  # the table without anchors
        self.assertIn("1 runs with a bad anchor", robustness.anchor_summary_lines([good, bad])[0])

    def test_the_diverged_runs_with_collinear_anchors_are_counted(self):
        sc = {"name": "r"}
        run = dict(ok=True, scenario=sc, diverged=True, collinear=True)
        runs = [run, dict(run, collinear=False), dict(run, diverged=False), dict(run, ok=False)]
        self.assertEqual(robustness.collinear_lines(runs),
                         ['1 of the 2 diverged runs have nearly collinear known anchors (column collinear; '
                          'docs/robustness.md, "Nearly collinear known anchors")'])
        self.assertEqual(robustness.collinear_lines([dict(run, diverged=False)]), [])


class UsageTest(unittest.TestCase):
    def test_usage_errors_and_missing_binaries(self):
        with self.assertRaises(SystemExit) as e:
            robustness.main([])
        self.assertEqual(e.exception.code, 2)
        with self.assertRaises(SystemExit):
            robustness.main(["--runs", "2", "--scenarios", "x.yaml"])
        with tempfile.TemporaryDirectory() as d:
            self.assertEqual(robustness.main(["--runs", "1", "--bin", d, "--out", d]), 2)

    def test_a_strategy_meshnav_run_does_not_have_is_refused_before_any_run(self):
        # The strategies are meshnav_run's (estimator/core/strategy_list.h): a stand-in binary that
        # refuses every --strategy, as meshnav_run does for an unknown name, stops the sweep at once.
        with tempfile.TemporaryDirectory() as d:
            for b in ("meshnav_sim", "meshnav_run", "meshnav_eval"):
                path = os.path.join(d, b)
                with open(path, "w") as f:
                    f.write("#!/bin/sh\necho \"$0: --strategy: 'ukf' is not one of centralized|dp|dah\" >&2\nexit 2\n")
                os.chmod(path, 0o755)
            out = os.path.join(d, "out")
            self.assertEqual(robustness.main(["--runs", "1", "--bin", d, "--out", out, "--strategy", "ukf"]), 2)
            self.assertFalse(os.path.exists(out))


class RefusalTest(unittest.TestCase):
    """A run that never initialized is REFUSED with the estimator's reason, not a divergence."""

    def test_refusal_reason_comes_from_status_txt(self):
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "status.txt")
            with open(path, "w") as f:
                f.write('strategy: centralized\ninitialized: false\nhealth: initializing\n'
                        'health_reason: "motion alignment: ambiguous"\ncounters:\n  x: 1\n')
            self.assertEqual(robustness.read_refusal(path), "motion alignment: ambiguous")
            with open(path, "w") as f:
                f.write('strategy: centralized\ninitialized: true\nhealth: ok\nhealth_reason: ""\n')
            self.assertIsNone(robustness.read_refusal(path))

