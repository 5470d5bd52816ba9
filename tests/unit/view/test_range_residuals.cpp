#include "view/range_residuals.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

using namespace meshnav;
using meshnav::view::RangeResidual;
using meshnav::view::RangeResiduals;

namespace {

PoseEstimate pose(double t_s, Eigen::Vector3d p, double yaw = 0.0) {
  PoseEstimate e;
  e.t = Timestamp::fromSec(t_s);
  e.p_IinG = p;
  e.q_ItoG = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  return e;
}

RangeSample range(double t_s, SensorId tag, SensorId anchor, double z, bool anchor_first = false) {
  RangeSample r;
  r.t = Timestamp::fromSec(t_s);
  r.id_initiator = anchor_first ? anchor : tag;
  r.id_responder = anchor_first ? tag : anchor;
  r.type_initiator = anchor_first ? UwbType::Anchor : UwbType::Tag;
  r.type_responder = anchor_first ? UwbType::Tag : UwbType::Anchor;
  r.range_m = z;
  r.range_corr_m = z;
  return r;
}

struct Fixture {
  std::map<SensorId, Eigen::Vector3d> anchors{{101, Eigen::Vector3d(10, 0, 0)}};
  std::vector<RangeResidual> out;
  RangeResiduals residuals{[this](SensorId id) -> const Eigen::Vector3d* {
                             auto it = anchors.find(id);
                             return it == anchors.end() ? nullptr : &it->second;
                           },
                           [this](const RangeResidual& r) { out.push_back(r); }};
};

}  // namespace

TEST(RangeResiduals, WaitsForThePoseAfterTheRangeAndInterpolates) {
  Fixture f;
  f.residuals.onPose(pose(0.0, {0, 0, 0}));
  f.residuals.onRange(range(0.5, 1, 101, 9.0));  // no pose at or after 0.5 s yet
  EXPECT_TRUE(f.out.empty());
  EXPECT_EQ(f.residuals.pending(), 1u);
  f.residuals.onPose(pose(1.0, {2, 0, 0}));  // at 0.5 s the vehicle was at x = 1: distance 9
  ASSERT_EQ(f.out.size(), 1u);
  EXPECT_NEAR(f.out[0].residual_m, 0.0, 1e-12);
  EXPECT_EQ(f.out[0].tag, 1);
  EXPECT_EQ(f.out[0].anchor, 101);
  // A range already covered by the poses is evaluated at once, either way round.
  f.residuals.onRange(range(0.25, 1, 101, 9.7, true));  // x = 0.5: distance 9.5
  ASSERT_EQ(f.out.size(), 2u);
  EXPECT_NEAR(f.out[1].residual_m, 0.2, 1e-12);
}

TEST(RangeResiduals, UsesTheTagLeverArmRotatedIntoG) {
  Fixture f;
  f.residuals.setLeverArms({{1, Eigen::Vector3d(1, 0, 0)}});
  // Yaw 90°: the tag 1 m along I's x is 1 m along G's y; distance √(10² + 1²).
  f.residuals.onPose(pose(0.0, {0, 0, 0}, M_PI / 2));
  f.residuals.onRange(range(0.0, 1, 101, 10.0));
  ASSERT_EQ(f.out.size(), 1u);
  EXPECT_NEAR(f.out[0].residual_m, 10.0 - std::sqrt(101.0), 1e-9);
  // Another tag, not in the setup: no lever arm.
  f.residuals.onRange(range(0.0, 2, 101, 10.0));
  EXPECT_NEAR(f.out[1].residual_m, 0.0, 1e-9);
}

TEST(RangeResiduals, SkipsAnchorPairsAndCountsAnchorsWithoutPosition) {
  Fixture f;
  f.residuals.onPose(pose(0.0, {0, 0, 0}));
  RangeSample aa = range(0.0, 101, 102, 3.0);
  aa.type_initiator = UwbType::Anchor;
  f.residuals.onRange(aa);
  f.residuals.onRange(range(0.0, 1, 999, 3.0));
  EXPECT_TRUE(f.out.empty());
  EXPECT_EQ(f.residuals.diagnostics().get("residual:no_anchor_position"), 1);
}

TEST(RangeResiduals, BoundsTheRangesWaitingForAPose) {
  Fixture f;
  for (size_t i = 0; i < RangeResiduals::kMaxPending + 5; ++i) f.residuals.onRange(range(1.0 + i * 1e-3, 1, 101, 9.0));
  EXPECT_EQ(f.residuals.pending(), RangeResiduals::kMaxPending);
  EXPECT_EQ(f.residuals.diagnostics().get("residual:pending_dropped"), 5);
}
