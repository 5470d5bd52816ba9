// The recorder behind the logging process: estimate.csv / anchors.csv readable by the project's
// readers with the same values, visible after flush(), plus anchor_init.yaml and summary.yaml.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>

#include "common/dataset.h"
#include "common/anchor_init_io.h"
#include "common/estimate_io.h"
#include "logging/run_recorder.h"
#include "tests/support/test_util.h"

using namespace meshnav;
using namespace meshnav::logging;
namespace fs = std::filesystem;

namespace {

fs::path freshDir(const std::string& name) {
  static const test::TempDir root("log");  // removed at exit
  const fs::path d = root / name;
  fs::remove_all(d);
  return d;
}

PoseEstimate pose(double t) {
  PoseEstimate e;
  e.t = Timestamp::fromSec(t);
  e.p_IinG = {t, 2.0 * t, 3.0};
  e.q_ItoG = Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * t, Eigen::Vector3d::UnitZ()));
  e.cov_p_m2 = Eigen::Matrix3d::Identity() * 0.01;
  e.cov_p_m2(0, 1) = e.cov_p_m2(1, 0) = 0.002;
  e.cov_theta_rad2 = Eigen::Matrix3d::Identity() * 1e-4;
  return e;
}

}  // namespace

TEST(RunRecorder, EstimateAndAnchorsFilesVisibleAfterFlush) {
  const auto d = freshDir("flush");
  RunRecorder rec(d.string());
  EXPECT_TRUE(fs::exists(d / "estimate.csv"));
  EXPECT_TRUE(fs::exists(d / "anchors.csv"));
  for (int i = 0; i < 5; ++i) rec.onPose(pose(0.5 * i));
  AnchorEstimate a;
  a.t = Timestamp::fromSec(2.0);
  a.id = 106;
  a.p_AinG = {-1.772, 0.943, 3.256};
  a.cov_p_m2 = Eigen::Matrix3d::Identity() * 0.04;
  AnchorEstimate b = a;
  b.id = 101;
  rec.onAnchors({a, b});
  rec.flush();

  Diagnostics diag;
  const auto est = readEstimateCsv((d / "estimate.csv").string(), diag);
  ASSERT_EQ(est.size(), 5u);
  EXPECT_NEAR(est[4].p_IinG.x(), 2.0, 1e-9);
  EXPECT_NEAR(est[4].p_IinG.y(), 4.0, 1e-9);
  EXPECT_NEAR(est[4].cov_p_m2(1, 0), 0.002, 1e-9);
  EXPECT_NEAR(est[4].q_ItoG.angularDistance(pose(2.0).q_ItoG), 0.0, 1e-6);
  const auto anchors = readAnchorsCsv((d / "anchors.csv").string(), diag);
  ASSERT_EQ(anchors.size(), 2u);
  EXPECT_EQ(anchors[0].id, 106);
  EXPECT_NEAR(anchors[0].p_AinG.z(), 3.256, 1e-9);
  EXPECT_EQ(diag.total(), 0);
  EXPECT_EQ(rec.posesWritten(), 5);
  EXPECT_EQ(rec.anchorRowsWritten(), 2);
  fs::remove_all(d);
}

TEST(RunRecorder, FinishWritesSummaryAnchorInitsAndGroundTruth) {
  const auto d = freshDir("finish");
  {
    RunRecorder rec(d.string());
    for (int i = 0; i < 10; ++i) rec.countMessage("IMU", 60, 1'000'000 + i * 5'000);
    rec.countMessage("POSE", 300, 2'000'000);
    rec.onPose(pose(1.0));
    EstimatorStatus st;
    st.t = Timestamp::fromSec(140.0);
    st.initialized = true;
    st.strategy = "dah";
    st.counters = {{"out_of_sequence", 17}, {"gated_range", 3}};
    st.mean_step_us = {{"propagate", 11.5}};
    st.instances = {{1, "imu", 28000, 0}, {106, "anchor", 40, 1}};
    st.uwb_clock_offset_s = -0.031;
    st.uwb_clock_offset_sigma_s = 0.004;
    rec.onEstimatorStatus(st);
    CalibStatus cs;
    cs.anchors = {{107, "refused", 12, 2, "too few measurements: 12 < 50"}};
    rec.onCalibStatus(cs);
    rec.onMissionStatus(MissionStatus{Timestamp::fromSec(100.0), 0, 1, 2, "calibrating"});
    AnchorInit ai;
    ai.t = Timestamp::fromSec(80.0);
    ai.id = 106;
    ai.p_AinG = {-1.7, 0.9, 3.2};
    ai.cov_p_m2 = Eigen::Matrix3d::Identity() * 0.05;
    ai.biases = {PairBias{100, 106, 0.2, 1.0, 0.1, 0.03, 0.0}, PairBias{101, 106, -0.1, 1.0, 0.1, 0.05, 0.0}};
    ai.n_inliers = 300;
    ai.n_outliers = 9;
    rec.onAnchorInit(ai);
    rec.onGroundTruth(PoseSample{Timestamp::fromSec(1.0), {1, 2, 3}, Eigen::Quaterniond::Identity()});
    Diagnostics process_diag;
    process_diag.count("RANGE:decode_error", 2);
    rec.finish(process_diag);
    rec.finish(process_diag);  // idempotent
    EXPECT_NE(rec.summaryText().find("out_of_sequence=17"), std::string::npos) << rec.summaryText();
  }
  const YAML::Node s = YAML::LoadFile((d / "summary.yaml").string());
  EXPECT_EQ(s["channels"]["IMU"]["messages"].as<int>(), 10);
  EXPECT_EQ(s["channels"]["IMU"]["bytes"].as<int>(), 600);
  EXPECT_NEAR(s["channels"]["IMU"]["rate_hz"].as<double>(), 200.0, 1e-6);
  EXPECT_EQ(s["files"]["estimate_rows"].as<int>(), 1);
  EXPECT_EQ(s["estimator_status"]["counters"]["out_of_sequence"].as<int>(), 17);
  EXPECT_EQ(s["estimator_status"]["strategy"].as<std::string>(), "dah");
  EXPECT_EQ(s["estimator_status"]["instances"][1]["id"].as<int>(), 106);
  EXPECT_DOUBLE_EQ(s["estimator_status"]["uwb_clock_offset_s"].as<double>(), -0.031);
  EXPECT_DOUBLE_EQ(s["estimator_status"]["uwb_clock_offset_sigma_s"].as<double>(), 0.004);
  EXPECT_EQ(s["calib_status"]["anchors"][0]["reason"].as<std::string>(), "too few measurements: 12 < 50");
  EXPECT_EQ(s["mission_status"]["text"].as<std::string>(), "calibrating");
  EXPECT_EQ(s["logger_counters"]["RANGE:decode_error"].as<int>(), 2);

  const YAML::Node ai = YAML::LoadFile((d / "anchor_init.yaml").string());
  ASSERT_EQ(ai["anchors"].size(), 1u);
  EXPECT_EQ(ai["anchors"][0]["id"].as<int>(), 106);
  EXPECT_EQ(ai["anchors"][0]["ref_ids"][1].as<int>(), 101);
  EXPECT_DOUBLE_EQ(ai["anchors"][0]["const_biases"][0].as<double>(), 0.2);
  EXPECT_EQ(ai["anchors"][0]["p_AinG_cov"].size(), 9u);
  EXPECT_EQ(ai["anchors"][0]["n_outliers"].as<int>(), 9);

  Diagnostics diag;
  const auto gt = readTumCsv((d / "groundtruth.csv").string(), diag);
  ASSERT_EQ(gt.size(), 1u);
  EXPECT_DOUBLE_EQ(gt[0].p_IinG.z(), 3.0);
  fs::remove_all(d);
}

TEST(RunRecorder, ARestartedLoggerContinuesItsFiles) {
  // Issue 12: a logger killed (-9) and respawned within the same run keeps what it had written:
  // the CSVs are continued (one header), the ANCHOR_INITs come back from anchor_init.yaml, which
  // is rewritten at every ANCHOR_INIT.
  const auto d = freshDir("restart");
  AnchorInit ai;
  ai.t = Timestamp::fromSec(80.0);
  ai.id = 106;
  ai.p_AinG = {-1.7, 0.9, 3.2};
  ai.cov_p_m2 = Eigen::Matrix3d::Identity() * 0.05;
  ai.biases = {PairBias{100, 106, 0.2, 1.0, 0.1, 0.03, 0.0}};
  {
    RunRecorder first(d.string());
    first.onPose(pose(1.0));
    first.onPose(pose(1.5));
    first.onAnchorInit(ai);
    first.flush();
  }  // killed: no finish()
  ASSERT_TRUE(fs::exists(d / "anchor_init.yaml"));
  {
    RunRecorder second(d.string(), true);
    second.onPose(pose(2.0));
    AnchorInit b = ai;
    b.id = 107;
    second.onAnchorInit(b);
    second.finish(Diagnostics{});
  }
  Diagnostics diag;
  const auto est = readEstimateCsv((d / "estimate.csv").string(), diag);
  ASSERT_EQ(est.size(), 3u);
  EXPECT_NEAR(est[2].t.sec(), 2.0, 1e-9);
  EXPECT_EQ(diag.total(), 0);  // one header: no bad row
  const auto inits = readAnchorInitsYaml((d / "anchor_init.yaml").string());
  ASSERT_EQ(inits.size(), 2u);
  EXPECT_EQ(inits[0].id, 106);
  EXPECT_EQ(inits[1].id, 107);
  // Without append (a new run into the same folder) the files start anew.
  {
    RunRecorder fresh(d.string());
    fresh.onPose(pose(5.0));
    fresh.flush();
  }
  EXPECT_EQ(readEstimateCsv((d / "estimate.csv").string(), diag).size(), 1u);
  fs::remove_all(d);
}

TEST(RunRecorder, ARestartedLoggerCutsTheRowItsPredecessorLeftHalfWritten) {
  // A kill -9 while a row was being written leaves half of it at the end of estimate.csv; the
  // respawned logger cuts it (counted) instead of gluing its first row onto it.
  const auto d = freshDir("torn");
  {
    RunRecorder first(d.string());
    first.onPose(pose(1.0));
    first.onPose(pose(1.5));
    first.flush();
  }
  std::ofstream(d / "estimate.csv", std::ios::app) << "2.000000,0.12";  // the torn row
  {
    RunRecorder second(d.string(), true);
    EXPECT_EQ(second.diagnostics().get("estimate.csv:torn_row_cut"), 1);
    EXPECT_EQ(second.diagnostics().get("anchors.csv:torn_row_cut"), 0);
    second.onPose(pose(2.5));
    second.finish(Diagnostics{});
  }
  Diagnostics diag;
  const auto est = readEstimateCsv((d / "estimate.csv").string(), diag);
  EXPECT_EQ(diag.total(), 0);  // no bad row
  ASSERT_EQ(est.size(), 3u);
  EXPECT_NEAR(est[2].t.sec(), 2.5, 1e-9);
  EXPECT_NEAR(est[2].p_IinG.y(), 5.0, 1e-9);
  const YAML::Node s = YAML::LoadFile((d / "summary.yaml").string());
  EXPECT_EQ(s["logger_counters"]["estimate.csv:torn_row_cut"].as<int>(), 1);
  EXPECT_FALSE(fs::exists(d / "anchor_init.yaml.tmp"));
  fs::remove_all(d);
}

TEST(RunRecorder, UnwritableFolderThrows) {
  EXPECT_THROW(RunRecorder("/proc/meshnav_cannot_write_here"), std::exception);
}

TEST(RunRecorder, SmoothedPosesGoToTheirOwnFileFromTheFirstOne) {
  const auto d = freshDir("smoothed");
  {
    RunRecorder rec(d.string());
    rec.onPose(pose(1.0));
    rec.flush();
    EXPECT_FALSE(fs::exists(d / "estimate_smoothed.csv"));  // no POSE_SMOOTHED yet: no file
    rec.onPoseSmoothed(pose(1.0));
    rec.onPoseSmoothed(pose(2.0));
    rec.finish(Diagnostics{});
    EXPECT_EQ(rec.smoothedPosesWritten(), 2);
  }
  {
    RunRecorder again(d.string(), true);  // a restart within the run continues the file
    again.onPoseSmoothed(pose(3.0));
    again.finish(Diagnostics{});
  }
  Diagnostics diag;
  const auto smoothed = readEstimateCsv((d / "estimate_smoothed.csv").string(), diag);
  ASSERT_EQ(smoothed.size(), 3u);
  EXPECT_NEAR(smoothed[2].t.sec(), 3.0, 1e-9);
  EXPECT_EQ(YAML::LoadFile((d / "summary.yaml").string())["files"]["estimate_smoothed_rows"].as<int>(), 1);
  fs::remove_all(d);
}
