#include "view/view_state.h"

#include <gtest/gtest.h>

using namespace meshnav;
using meshnav::view::ViewCursor;
using meshnav::view::ViewState;

namespace {

PoseEstimate pose(double t_s, double x, double y) {
  PoseEstimate e;
  e.t = Timestamp::fromSec(t_s);
  e.p_IinG = Eigen::Vector3d(x, y, 1.0);
  e.cov_p_m2 = Eigen::Vector3d(0.04, 0.01, 0.09).asDiagonal();
  return e;
}

RangeSample range(double t_s, SensorId tag, SensorId anchor, double z) {
  RangeSample r;
  r.t = Timestamp::fromSec(t_s);
  r.id_initiator = tag;
  r.id_responder = anchor;
  r.range_m = z;
  return r;
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

}  // namespace

TEST(ViewState, PathIsDecimatedAndSentIncrementally) {
  ViewState v;
  v.onPose(pose(100.0, 0.0, 0.0));
  v.onPose(pose(100.01, 0.001, 0.0));  // 1 mm, 10 ms later: not on the path
  v.onPose(pose(100.02, 0.5, 0.0));
  v.onPose(pose(100.7, 0.5, 0.0));     // no motion, but 0.68 s after the last point
  ASSERT_EQ(v.path().size(), 3u);
  EXPECT_DOUBLE_EQ(v.path().at(0, 0), 0.0);  // seconds since the first message
  EXPECT_NEAR(v.path().at(2, 0), 0.7, 1e-9);
  EXPECT_NEAR(v.path().at(0, 4), 0.2 * meshnav::view::kChi2Scale95, 1e-12);  // the 95 % ellipse's axes
  EXPECT_NEAR(v.path().at(0, 5), 0.1 * meshnav::view::kChi2Scale95, 1e-12);
  EXPECT_NEAR(v.path().at(0, 7), 0.3, 1e-12);  // σz
  ViewCursor c;
  c.path_epoch = 0;
  c.path_rows = 2;
  const std::string json = v.json(c);
  EXPECT_TRUE(contains(json, R"("path":{"epoch":0,"start":2,"rows":[[0.7,0.5,0,1,0.489549,0.244775,0,0.3]]})")) << json;
  EXPECT_TRUE(contains(json, R"("t0_utime":100000000)")) << json;
  // The current pose is the newest, with its 95 % ellipse (0.2 · 2.44775 = 0.489549…).
  EXPECT_TRUE(contains(json, R"("ell":[0.4895,0.2448,0])")) << json;
}

TEST(ViewState, OlderPoseIsCountedAndKeptOffThePath) {
  ViewState v;
  v.onPose(pose(2.0, 0.0, 0.0));
  v.onPose(pose(1.0, 5.0, 0.0));
  EXPECT_EQ(v.path().size(), 1u);
  EXPECT_EQ(v.counters().at("view:pose_out_of_order"), 1);
}

TEST(ViewState, AnchorsMergeEstimatorCalibratorAndSetup) {
  ViewState v;
  SystemSetup setup;
  setup.abs_anchor_positions[101] = Eigen::Vector3d(1, 2, 3);
  setup.rel_tag_positions[1] = Eigen::Vector3d(0, 0, 0.1);
  v.setSetup(setup);
  ASSERT_EQ(v.anchors().at(101).state(), "known");

  // 106 heard in RANGE only: listed, no position.
  v.onRange(range(1.0, 1, 106, 4.0));
  EXPECT_EQ(v.anchors().at(106).state(), "unknown");
  EXPECT_EQ(v.anchors().at(106).n_ranges, 1);

  CalibStatus cs;
  cs.t = Timestamp::fromSec(1.0);
  cs.anchors.push_back({106, "collecting", 10, 2, "waiting for 3 references"});
  v.onCalibStatus(cs);
  EXPECT_EQ(v.anchors().at(106).state(), "collecting");

  cs.anchors[0].state = "calibrated";
  cs.anchors[0].reason = "";
  v.onCalibStatus(cs);
  AnchorEstimate known{Timestamp::fromSec(2.0), 101, Eigen::Vector3d(1, 2, 3), Eigen::Matrix3d::Zero()};
  AnchorEstimate calibrated{Timestamp::fromSec(2.0), 106, Eigen::Vector3d(4, 0, 2), Eigen::Matrix3d::Identity() * 0.01};
  v.onAnchors({known, calibrated});
  EXPECT_EQ(v.anchors().at(106).state(), "calibrated");
  EXPECT_TRUE(v.anchors().at(106).in_estimator);
  const std::string json = v.json({});
  EXPECT_TRUE(contains(json, R"("id":106,"state":"calibrated","p":[4,0,2],"ell":[0.2448,0.2448,0])")) << json;
  EXPECT_TRUE(contains(json, R"("lever_arms":"setup")")) << json;
  EXPECT_TRUE(contains(json, R"("channel":"CALIB_STATUS")")) << json;
}

TEST(ViewState, ResidualsPerAnchorFromTheEstimatedTagPosition) {
  ViewState v;
  AnchorEstimate a{Timestamp::fromSec(0.0), 101, Eigen::Vector3d(3, 4, 1), Eigen::Matrix3d::Zero()};
  v.onAnchors({a});
  v.onPose(pose(0.0, 0.0, 0.0));  // z = 1 like the anchor: distance 5
  v.onRange(range(0.0, 1, 101, 5.3));
  ASSERT_EQ(v.residuals().size(), 1u);
  EXPECT_NEAR(v.residuals().at(0, 2), 0.3, 1e-12);
  EXPECT_EQ(v.anchors().at(101).n_residuals, 1);
  const std::string json = v.json({});
  EXPECT_TRUE(contains(json, R"("last_residual_m":0.3,"mean_residual_m":0.3,"rms_residual_m":0.3)")) << json;
  EXPECT_TRUE(contains(json, R"("lever_arms":"zero")")) << json;
}

TEST(ViewState, HealthAndStatusChannelsAsTables) {
  ViewState v;
  EstimatorStatus s;
  s.t = Timestamp::fromSec(3.0);
  s.health = "degraded";
  s.health_reason = "range innovations large";
  s.counters["gated_range"] = 4;
  s.counters["bad_input"] = 0;
  v.onEstimatorStatus(s);
  v.onStatusFields("CONTROL_STATUS", Timestamp::fromSec(3.0), {{"mode", "hover"}});
  const std::string json = v.json({});
  EXPECT_TRUE(contains(json, R"("health":{"t":0,"state":"degraded","reason":"range innovations large")")) << json;
  EXPECT_TRUE(contains(json, R"(["counters","gated_range=4"])")) << json;
  EXPECT_TRUE(contains(json, R"({"channel":"CONTROL_STATUS","t":0,"fields":[["mode","hover"]]})")) << json;
}

TEST(ViewState, TruthHasItsOwnTrack) {
  ViewState v;
  EXPECT_TRUE(contains(v.json({}), R"("truth_pose":null)"));
  PoseSample g;
  g.t = Timestamp::fromSec(1.0);
  g.p_IinG = Eigen::Vector3d(1, 1, 1);
  v.onGroundTruth(g);
  EXPECT_EQ(v.truth().size(), 1u);
  EXPECT_FALSE(v.hasPose());
  EXPECT_TRUE(contains(v.json({}), R"("truth_pose":{"t":0,"n":1,"p":[1,1,1],"yaw_deg":0})")) << v.json({});
}
