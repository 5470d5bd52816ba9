#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "eval/anchor_metrics.h"
#include "tests/support/test_util.h"

using namespace meshnav;
using namespace meshnav::eval;

namespace {

AnchorEstimate row(double t, SensorId id, Eigen::Vector3d p, double var) {
  AnchorEstimate a;
  a.t = Timestamp::fromSec(t);
  a.id = id;
  a.p_AinG = p;
  a.cov_p_m2 = Eigen::Matrix3d::Identity() * var;
  return a;
}

}  // namespace

TEST(AnchorMetrics, InitialAndFinalErrorsAndInitialNees) {
  const std::map<SensorId, Eigen::Vector3d> truth = {{101, {0, 0, 0}}, {106, {1, 2, 3}}, {107, {-1, 0, 2}}};
  const std::map<SensorId, Eigen::Vector3d> known = {{101, {0, 0, 0}}};
  std::vector<AnchorEstimate> rows = {
      // Out of time order on purpose: the first in time is the initial belief.
      row(90.0, 106, {1.0, 2.0, 3.1}, 0.01),   // final: error 0.1
      row(80.0, 106, {1.3, 2.4, 3.0}, 0.04),   // initial: error 0.5, NEES 0.25 / 0.04 = 6.25
      row(85.0, 106, {1.1, 2.0, 3.0}, 0.02),
      row(100.0, 107, {-1.0, 0.0, 1.0}, 0.25), // initial = final: error 1, NEES 4
      row(0.0, 101, {0, 0, 0}, 0.0),           // known, zero covariance: no NEES
  };
  Diagnostics diag;
  const auto m = computeAnchorMetrics(rows, truth, known, {}, diag);
  ASSERT_EQ(m.anchors.size(), 3u);
  const auto& a101 = m.anchors[0];
  const auto& a106 = m.anchors[1];
  const auto& a107 = m.anchors[2];
  EXPECT_EQ(a101.id, 101);
  EXPECT_TRUE(a101.known);
  EXPECT_FALSE(a101.initial_nees.has_value());
  EXPECT_EQ(a106.n_estimates, 3);
  EXPECT_NEAR(a106.initial_error_m, 0.5, 1e-12);
  EXPECT_NEAR(a106.final_error_m, 0.1, 1e-12);
  ASSERT_TRUE(a106.initial_nees);
  EXPECT_NEAR(*a106.initial_nees, 6.25, 1e-9);
  EXPECT_NEAR(*a106.final_nees, 1.0, 1e-9);
  EXPECT_EQ(a106.initial.t, Timestamp::fromSec(80.0));
  EXPECT_NEAR(a107.initial_error_m, 1.0, 1e-12);
  EXPECT_NEAR(*a107.initial_nees, 4.0, 1e-9);
  // Means over calibrated anchors only (101 is known).
  EXPECT_EQ(m.n_estimated, 2);
  EXPECT_NEAR(m.mean_initial_error_m, 0.75, 1e-12);
  EXPECT_NEAR(m.mean_final_error_m, 0.55, 1e-12);
}

TEST(AnchorMetrics, CalibrationOverrideAndMissingTruth) {
  const std::map<SensorId, Eigen::Vector3d> truth = {{106, {1, 2, 3}}};
  std::vector<AnchorEstimate> rows = {row(80.0, 106, {1, 2, 3.2}, 0.01), row(81.0, 199, {0, 0, 0}, 0.01)};
  std::map<SensorId, AnchorEstimate> init = {{106, row(79.5, 106, {1, 2, 2.0}, 1.0)}};
  Diagnostics diag;
  const auto m = computeAnchorMetrics(rows, truth, {}, init, diag);
  ASSERT_EQ(m.anchors.size(), 2u);
  EXPECT_NEAR(m.anchors[0].initial_error_m, 1.0, 1e-12);  // from the override
  EXPECT_NEAR(m.anchors[0].final_error_m, 0.2, 1e-12);
  EXPECT_FALSE(m.anchors[1].has_truth);
  EXPECT_EQ(diag.get("eval:anchor_without_truth"), 1);
  EXPECT_EQ(m.n_estimated, 1);
}

TEST(AnchorMetrics, NoAnchorsGivesNaNMeans) {
  Diagnostics diag;
  const auto m = computeAnchorMetrics({}, {}, {}, {}, diag);
  EXPECT_TRUE(m.anchors.empty());
  EXPECT_TRUE(std::isnan(m.mean_initial_error_m));
}

TEST(CalibrationYaml, ReadsEntriesAndNamesMissingKeys) {
  const meshnav::test::TempDir dir("eval_calib_test");
  const auto good = (dir / "good.yaml").string();
  std::ofstream(good) << "- id: 106\n  p_AinG: [1, 2, 3]\n  p_AinG_cov: [0.04, 0, 0, 0, 0.04, 0, 0, 0, 0.09]\n"
                         "- id: 107\n  p_AinG: [4, 5, 6]\n";
  const auto m = readCalibrationYaml(good);
  ASSERT_EQ(m.size(), 2u);
  EXPECT_TRUE(m.at(106).p_AinG.isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_DOUBLE_EQ(m.at(106).cov_p_m2(2, 2), 0.09);
  const auto bad = (dir / "bad.yaml").string();
  std::ofstream(bad) << "anchors:\n  - id: 106\n    p_AinG: [1, 2]\n";
  try {
    readCalibrationYaml(bad);
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& ex) {
    EXPECT_NE(std::string(ex.what()).find("p_AinG"), std::string::npos) << ex.what();
    EXPECT_NE(std::string(ex.what()).find("bad.yaml"), std::string::npos) << ex.what();
  }
}

TEST(CalibrationYaml, NonFiniteNumbersAreRefusedAndARecalibrationWins) {
  // Found by an audit: '.nan' and '.inf' loaded, and the report then showed NaN anchor errors
  // with exit 0. A repeated id is a re-calibration (the logger appends every ANCHOR_INIT).
  const meshnav::test::TempDir dir("eval_calib_nan");
  const auto twice = (dir / "twice.yaml").string();
  std::ofstream(twice) << "- id: 106\n  p_AinG: [1, 2, 3]\n- id: 106\n  p_AinG: [4, 5, 6]\n";
  EXPECT_TRUE(readCalibrationYaml(twice).at(106).p_AinG.isApprox(Eigen::Vector3d(4, 5, 6)));
  const std::pair<const char*, const char*> cases[] = {
      {"- id: 106\n  p_AinG: [1, .nan, 3]\n", "'.nan' is not a finite number"},
      {"- id: 106\n  p_AinG: [1, 2, 3]\n  p_AinG_cov: [.inf, 0, 0, 0, 1, 0, 0, 0, 1]\n", "p_AinG_cov"},
  };
  int i = 0;
  for (const auto& [text, needle] : cases) {
    const auto path = (dir / ("c" + std::to_string(i++) + ".yaml")).string();
    std::ofstream(path) << text;
    try {
      readCalibrationYaml(path);
      ADD_FAILURE() << "accepted:\n" << text;
    } catch (const std::runtime_error& ex) {
      EXPECT_NE(std::string(ex.what()).find(needle), std::string::npos) << ex.what();
      EXPECT_NE(std::string(ex.what()).find(path), std::string::npos) << ex.what();
    }
  }
}
