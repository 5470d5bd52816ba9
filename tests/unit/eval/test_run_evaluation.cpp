/// End-to-end evaluation of a small synthetic run folder: files in, metrics/tables/CSVs out.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "common/dataset.h"
#include "common/estimate_io.h"
#include "common/setup.h"
#include "eval/plotting.h"
#include "eval/report.h"
#include "eval/run_evaluation.h"
#include "tests/support/test_util.h"

namespace fs = std::filesystem;
using namespace meshnav;
using namespace meshnav::eval;

namespace {

class RunEvaluationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = tmp_.path();
    ds_ = root_ / "dataset";
    run_ = root_ / "run";
    fs::create_directories(ds_);
    fs::create_directories(run_);
  }

  /// 10 s of ground truth at 60 Hz (circle), estimates at 20 Hz with a constant 0.2 m x offset and
  /// σ = 0.2 m (NEES 1 per sample), two calibrated anchors and a known one.
  void writeAll(bool with_truth = true, bool anchor_106_in_setup_with_sigma = false) {
    std::vector<PoseSample> gt;
    for (int k = 0; k <= 600; ++k) {
      const double t = k / 60.0;
      gt.push_back({Timestamp::fromSec(t), Eigen::Vector3d(std::cos(t), std::sin(t), 2.0),
                    Eigen::Quaterniond(Eigen::AngleAxisd(t, Eigen::Vector3d::UnitZ()))});
    }
    writeTumCsv(gt, (ds_ / "groundtruth.csv").string());
    writeFlightStateCsv({{Timestamp::fromSec(0.0), true}, {Timestamp::fromSec(1.0), false}},
                        (ds_ / "flight_state.csv").string());
    SystemSetup setup;
    setup.rel_tag_positions[100] = Eigen::Vector3d(0.1, 0, 0);
    setup.abs_anchor_positions[101] = Eigen::Vector3d(0, 0, 0);
    if (anchor_106_in_setup_with_sigma) {  // known-but-uncertain: refined online, so "estimated"
      setup.abs_anchor_positions[106] = Eigen::Vector3d(1, 1, 1.4);
      setup.abs_anchor_sigmas_m[106] = 0.2;
    }
    saveSetup(setup, (ds_ / "setup.yaml").string());
    if (with_truth) {
      Truth truth;
      truth.anchor_positions = {{101, {0, 0, 0}}, {106, {1, 1, 1}}, {107, {2, 0, 1}}};
      saveTruth(truth, (ds_ / "truth.yaml").string());
    }
    {
      EstimateCsvWriter w((run_ / "estimate.csv").string());
      for (int k = 0; k < 200; ++k) {
        const double t = 0.025 + k * 0.05;
        PoseEstimate e;
        e.t = Timestamp::fromSec(t);
        e.p_IinG = Eigen::Vector3d(std::cos(t) - 0.2, std::sin(t), 2.0);
        e.q_ItoG = Eigen::Quaterniond(Eigen::AngleAxisd(t, Eigen::Vector3d::UnitZ()));
        e.cov_p_m2 = Eigen::Matrix3d::Identity() * 0.04;
        e.cov_theta_rad2 = Eigen::Matrix3d::Identity() * 1e-4;
        w.write(e);
      }
    }
    AnchorsCsvWriter a((run_ / "anchors.csv").string());
    auto row = [&](double t, SensorId id, Eigen::Vector3d p, double var) {
      AnchorEstimate x;
      x.t = Timestamp::fromSec(t);
      x.id = id;
      x.p_AinG = p;
      x.cov_p_m2 = Eigen::Matrix3d::Identity() * var;
      a.write(x);
    };
    row(0.0, 101, {0, 0, 0}, 0.0);
    row(5.0, 106, {1, 1, 1.4}, 0.04);  // initial error 0.4, NEES 4
    row(9.0, 106, {1, 1, 1.1}, 0.01);  // final error 0.1
    row(6.0, 107, {2, 0.3, 1}, 0.01);  // error 0.3, NEES 9
  }

  meshnav::test::TempDir tmp_{"eval_test"};  // removed after each test
  fs::path root_, ds_, run_;
};

}  // namespace

TEST_F(RunEvaluationTest, TimesThatDoNotFitAreSkippedCountedAndFlagged) {
  // Issue 12, finding 2: a ground-truth time of 1e308 became INT64_MIN, sorted first and left one
  // associated sample (RMSE 0.037 m, exit 0). Now the row is refused; everything else is evaluated.
  writeAll();
  EvalOptions opt;
  const RunEvaluation clean = evaluateRun(ds_.string(), run_.string(), opt);
  EXPECT_EQ(skippedTimeRows(clean), 0);
  std::ofstream(ds_ / "groundtruth.csv", std::ios::app) << "1e308,1,0,2,0,0,0,1\n-1e308,1,0,2,0,0,0,1\n";
  std::ofstream(run_ / "estimate.csv", std::ios::app)
      << "1e300,0,0,2,0,0,0,1,0.04,0,0,0.04,0,0.04,1e-4,0,0,1e-4,0,1e-4\n";
  const RunEvaluation ev = evaluateRun(ds_.string(), run_.string(), opt);
  EXPECT_EQ(ev.diagnostics.at("groundtruth.csv:bad_time"), 2);
  EXPECT_EQ(ev.diagnostics.at("estimate.csv:bad_time"), 1);
  EXPECT_EQ(skippedTimeRows(ev), 3);
  EXPECT_EQ(ev.trajectory.n_selected, clean.trajectory.n_selected);
  EXPECT_EQ(ev.trajectory.position.rmse, clean.trajectory.position.rmse);
}

TEST_F(RunEvaluationTest, AnExcludedWindowIsLeftOutOfTheFiguresAndCounted) {
  // A sensor outage scored apart (realdata_stress.py's range gaps): the estimates of 4-6 s are 3 m
  // off; with the window excluded the run is scored on the rest alone (0.2 m, as without them).
  writeAll();
  {
    EstimateCsvWriter w((run_ / "estimate.csv").string());
    for (int k = 0; k < 200; ++k) {
      const double t = 0.025 + k * 0.05;
      PoseEstimate e;
      e.t = Timestamp::fromSec(t);
      e.p_IinG = Eigen::Vector3d(std::cos(t) - (t >= 4.0 && t <= 6.0 ? 3.0 : 0.2), std::sin(t), 2.0);
      e.q_ItoG = Eigen::Quaterniond(Eigen::AngleAxisd(t, Eigen::Vector3d::UnitZ()));
      e.cov_p_m2 = Eigen::Matrix3d::Identity() * 0.04;
      e.cov_theta_rad2 = Eigen::Matrix3d::Identity() * 1e-4;
      w.write(e);
    }
  }
  EvalOptions opt;
  const RunEvaluation all = evaluateRun(ds_.string(), run_.string(), opt);
  EXPECT_GT(all.trajectory.position.rmse, 1.0);
  opt.exclude_windows_s = {{3.99, 6.01}};
  const RunEvaluation ev = evaluateRun(ds_.string(), run_.string(), opt);
  EXPECT_NEAR(ev.trajectory.position.rmse, 0.2, 1e-3);
  EXPECT_EQ(ev.trajectory.n_associated, 200 - 40);
  EXPECT_EQ(ev.diagnostics.at("eval:excluded_truth_pose"), 121);  // 60 Hz truth over 4.00-6.00 s
  EXPECT_NE(std::find_if(ev.notes.begin(), ev.notes.end(),
                         [](const std::string& n) { return n.find("--exclude") != std::string::npos; }),
            ev.notes.end());
  // A window shorter than the interpolation gap (0.2 s) is excluded too, not bridged by the truth
  // around it; one that holds no truth (seconds where the files hold other stamps) says so.
  opt.exclude_windows_s = {{4.0, 4.1}, {500.0, 600.0}};
  const RunEvaluation short_window = evaluateRun(ds_.string(), run_.string(), opt);
  EXPECT_EQ(short_window.trajectory.n_associated, 200 - 2);  // 4.025 and 4.075 s
  EXPECT_EQ(short_window.diagnostics.at("eval:excluded_estimate"), 2);
  EXPECT_NE(std::find_if(short_window.notes.begin(), short_window.notes.end(),
                         [](const std::string& n) { return n.find("holds no ground-truth pose") != std::string::npos; }),
            short_window.notes.end());
}

TEST_F(RunEvaluationTest, MetricsTablesAndFiles) {
  writeAll();
  EvalOptions opt;
  opt.only_flying = true;  // drops t < 1 s
  const RunEvaluation ev = evaluateRun(ds_.string(), run_.string(), opt);
  EXPECT_TRUE(ev.has_ground_truth);
  EXPECT_TRUE(ev.has_flight_state);
  EXPECT_EQ(ev.trajectory.n_associated, 200);
  EXPECT_EQ(ev.trajectory.n_selected, 180);
  EXPECT_NEAR(ev.trajectory.position.rmse, 0.2, 1e-4);  // GT interpolated linearly on a circle
  EXPECT_NEAR(ev.trajectory.position.anees, 1.0, 2e-3);
  EXPECT_NEAR(ev.trajectory.orientation.rmse, 0.0, 1e-3);
  ASSERT_TRUE(ev.anchors);
  EXPECT_EQ(ev.anchors->n_estimated, 2);
  EXPECT_NEAR(ev.anchors->mean_initial_error_m, 0.35, 1e-6);
  EXPECT_NEAR(ev.anchors->mean_final_error_m, 0.2, 1e-6);
  EXPECT_NEAR(*ev.anchors->anchors[1].initial_nees, 4.0, 1e-4);

  const std::string report = formatRunReport(ev);
  EXPECT_NE(report.find("position [m]"), std::string::npos);
  EXPECT_NE(report.find("0.200"), std::string::npos);
  EXPECT_NE(report.find("106"), std::string::npos);

  writeMetricsYaml(ev, (run_ / "metrics.yaml").string());
  const YAML::Node m = YAML::LoadFile((run_ / "metrics.yaml").string());
  EXPECT_NEAR(m["pose"]["position"]["rmse_m"].as<double>(), 0.2, 1e-4);
  EXPECT_EQ(m["pose"]["n_evaluated"].as<int>(), 180);
  EXPECT_NEAR(m["anchors"]["mean_initial_error_m"].as<double>(), 0.35, 1e-5);
  EXPECT_EQ(m["anchors"]["per_anchor"].size(), 3u);
  EXPECT_TRUE(m["anchors"]["per_anchor"][0]["initial"]["nees"].IsNull());  // known, zero covariance

  writeMetricsJson(ev, (run_ / "metrics.json").string());
  const YAML::Node j = YAML::LoadFile((run_ / "metrics.json").string());  // JSON is YAML
  EXPECT_NEAR(j["pose"]["orientation"]["anees"].as<double>(), m["pose"]["orientation"]["anees"].as<double>(), 1e-9);

  writeErrorsCsv(ev, (run_ / "errors.csv").string());
  std::ifstream f(run_ / "errors.csv");
  std::string header, first;
  std::getline(f, header);
  std::getline(f, first);
  EXPECT_EQ(header.rfind("t,ep_x_m,ep_y_m,ep_z_m,sigma3_p_x_m", 0), 0u);
  EXPECT_EQ(first.rfind("0.025000,0.19", 0), 0u) << first;  // x error 0.2 m (chord of the circle GT)
  EXPECT_NE(first.find(",0.60000,"), std::string::npos) << first;  // 3σ = 0.6 m
  int lines = 1;
  while (std::getline(f, first)) ++lines;
  EXPECT_EQ(lines, 200);
}

TEST_F(RunEvaluationTest, ASmoothedEstimateIsScoredBesideTheFilter) {
  writeAll();
  EvalOptions opt;
  EXPECT_FALSE(evaluateRun(ds_.string(), run_.string(), opt).smoothed);  // none without the file
  {
    // The smoother's poses at the filter's times: 0.05 m off in y, σ 0.05 m (NEES 1 per sample).
    EstimateCsvWriter w((run_ / "estimate_smoothed.csv").string());
    for (int k = 0; k < 200; ++k) {
      const double t = 0.025 + k * 0.05;
      PoseEstimate e;
      e.t = Timestamp::fromSec(t);
      e.p_IinG = Eigen::Vector3d(std::cos(t), std::sin(t) + 0.05, 2.0);
      e.q_ItoG = Eigen::Quaterniond(Eigen::AngleAxisd(t, Eigen::Vector3d::UnitZ()));
      e.cov_p_m2 = Eigen::Matrix3d::Identity() * 0.0025;
      e.cov_theta_rad2 = Eigen::Matrix3d::Identity() * 1e-4;
      w.write(e);
    }
    w.flush();
  }
  const RunEvaluation ev = evaluateRun(ds_.string(), run_.string(), opt);
  ASSERT_TRUE(ev.smoothed);
  EXPECT_NEAR(ev.trajectory.position.rmse, 0.2, 1e-4);  // the filter's figures unchanged
  EXPECT_EQ(ev.smoothed->trajectory.n_selected, 200);
  EXPECT_NEAR(ev.smoothed->trajectory.position.rmse, 0.05, 1e-4);
  EXPECT_NEAR(ev.smoothed->trajectory.position.anees, 1.0, 5e-3);
  EXPECT_NE(formatRunReport(ev).find("position [m], smoothed"), std::string::npos);
  writeMetricsYaml(ev, (run_ / "metrics.yaml").string());
  const YAML::Node m = YAML::LoadFile((run_ / "metrics.yaml").string());
  EXPECT_NEAR(m["pose_smoothed"]["position"]["rmse_m"].as<double>(), 0.05, 1e-4);
  EXPECT_NEAR(m["pose"]["position"]["rmse_m"].as<double>(), 0.2, 1e-4);
  writeSmoothedErrorsCsv(ev, (run_ / "errors_smoothed.csv").string());
  std::ifstream f(run_ / "errors_smoothed.csv");
  std::string header, first;
  std::getline(f, header);
  std::getline(f, first);
  EXPECT_EQ(first.rfind("0.025000,", 0), 0u) << first;
  EXPECT_NE(first.find(",-0.05"), std::string::npos) << first;  // truth − estimate in y
}

TEST_F(RunEvaluationTest, MetricsKeepUnixTimesToTheMicrosecond) {
  // Real recordings are stamped in Unix seconds: metrics.yaml once said t_first_s: 1.66496e+09.
  RunEvaluation ev;
  ev.trajectory.n_associated = ev.trajectory.n_selected = 2;
  ev.trajectory.t_first_s = 1664959690.648354;
  ev.trajectory.t_last_s = 1664959736.089986;
  writeMetricsYaml(ev, (run_ / "metrics.yaml").string());
  const YAML::Node m = YAML::LoadFile((run_ / "metrics.yaml").string());
  EXPECT_EQ(m["pose"]["t_first_s"].as<std::string>(), "1664959690.648354");
  EXPECT_EQ(m["pose"]["t_last_s"].as<std::string>(), "1664959736.089986");
}

TEST_F(RunEvaluationTest, AnchorGivenWithSigmaCountsAsEstimated) {
  writeAll(true, true);
  const RunEvaluation ev = evaluateRun(ds_.string(), run_.string(), {});
  ASSERT_TRUE(ev.anchors);
  EXPECT_EQ(ev.anchors->n_estimated, 2);  // 106 (setup with σ) and 107 (calibrated); 101 known
  for (const auto& a : ev.anchors->anchors) EXPECT_EQ(a.known, a.id == 101) << a.id;
  EXPECT_NEAR(ev.anchors->mean_final_error_m, 0.2, 1e-6);
  EXPECT_NE(formatRunReport(ev).find("estimated"), std::string::npos);
  std::vector<BatchEntry> entries;
  entries.push_back({"seed01", ev});
  const std::string table = makeBatchTable(entries).plain();
  EXPECT_NE(table.find("A106★ [m]"), std::string::npos) << table;
  // The anchor summary of the batch (issue 10): the two estimated anchors, their mean final error
  // and how many final beliefs pass the χ²(3) bound.
  const TextTable summary = makeBatchAnchorSummary(entries);
  ASSERT_FALSE(summary.empty());
  const std::string md = summary.markdown();
  EXPECT_NE(md.find("| 2 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| 0.200 |"), std::string::npos) << md;
  int fin_ok = 0, with_nees = 0;
  for (const auto& a : ev.anchors->anchors)
    if (!a.known && a.final_nees) ++with_nees, fin_ok += *a.final_nees <= 13.93;
  EXPECT_NE(md.find(std::to_string(fin_ok) + " / " + std::to_string(with_nees)), std::string::npos) << md;
  EXPECT_TRUE(makeBatchAnchorSummary({}).empty());
}

TEST_F(RunEvaluationTest, BatchTableHasMeanRow) {
  writeAll();
  std::vector<BatchEntry> entries;
  entries.push_back({"seed01", evaluateRun(ds_.string(), run_.string(), {})});
  entries.push_back({"seed02", evaluateRun(ds_.string(), run_.string(), {})});
  const auto t = makeBatchTable(entries);
  const std::string md = t.markdown();
  EXPECT_NE(md.find("| run | pos RMSE [m] |"), std::string::npos) << md;
  EXPECT_NE(md.find("A106★ [m]"), std::string::npos) << md;
  EXPECT_NE(md.find("| seed02 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| mean | 0.200 |"), std::string::npos) << md;
  EXPECT_EQ(md.find("A101"), std::string::npos) << "known anchors are not in the table";
  EXPECT_NE(t.plain().find("mean"), std::string::npos);
}

TEST_F(RunEvaluationTest, MissingTruthIsExplainedNotFatal) {
  writeAll(/*with_truth=*/false);
  fs::remove(ds_ / "groundtruth.csv");
  const RunEvaluation ev = evaluateRun(ds_.string(), run_.string(), {});
  EXPECT_FALSE(ev.has_ground_truth);
  EXPECT_EQ(ev.trajectory.n_selected, 0);
  EXPECT_FALSE(ev.anchors.has_value());
  ASSERT_GE(ev.notes.size(), 2u);
  EXPECT_NE(ev.notes[0].find("groundtruth.csv"), std::string::npos);
  EXPECT_NE(ev.notes[1].find("truth.yaml"), std::string::npos);
  const std::string report = formatRunReport(ev);
  EXPECT_NE(report.find("not available"), std::string::npos);
  EXPECT_NO_THROW(writeMetricsYaml(ev, (run_ / "metrics.yaml").string()));
  EXPECT_TRUE(YAML::LoadFile((run_ / "metrics.yaml").string())["pose"].IsNull());
}

TEST_F(RunEvaluationTest, BadRowsAreCountedAndSkipped) {
  writeAll();
  std::ofstream(run_ / "estimate.csv", std::ios::app) << "11.0,nan,0,0,0,0,0,1,1,0,0,1,0,1,1,0,0,1,0,1\n";
  const RunEvaluation ev = evaluateRun(ds_.string(), run_.string(), {});
  EXPECT_EQ(ev.trajectory.n_associated, 200);
  EXPECT_GE(ev.diagnostics.size(), 1u);
}

TEST_F(RunEvaluationTest, PlotScriptWritesPngs) {
  if (!findPythonWithMatplotlib()) GTEST_SKIP() << "no Python with matplotlib";
  writeAll();
  const RunEvaluation ev = evaluateRun(ds_.string(), run_.string(), {});
  writeErrorsCsv(ev, (run_ / "errors.csv").string());
  writeAnchorsEvalCsv(ev, (run_ / "anchors_eval.csv").string());
  const fs::path out = root_ / "plots";
  ASSERT_TRUE(runPlotScript("plot_run.py", {"--out", out.string(), "--errors", (run_ / "errors.csv").string(),
                                            "--anchors", (run_ / "anchors_eval.csv").string(), "--groundtruth",
                                            (ds_ / "groundtruth.csv").string(), "--estimate",
                                            (run_ / "estimate.csv").string()}));
  for (const char* png : {"trajectory_xy.png", "trajectory_3d.png", "position_error.png", "orientation_error.png",
                          "nees.png"}) {
    EXPECT_TRUE(fs::exists(out / png)) << png;
    EXPECT_GT(fs::file_size(out / png), 1000u) << png;
  }
  EXPECT_FALSE(runPlotScript("no_such_script.py", {}));
}
