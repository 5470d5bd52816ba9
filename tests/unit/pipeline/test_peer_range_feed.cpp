// A fleet's ranges between two vehicles' tags (pipeline/peer_range_feed.h): which ranges, each
// exchange once, one receiver, and the sender's tag from its pose; the same object runs in
// meshnav_run --fleet and (through PeerRangeRelay) in `peer_router` over LCM.
#include <gtest/gtest.h>

#include "common/skew.h"
#include "fleet_test_data.h"
#include "pipeline/fleet.h"
#include "pipeline/peer_range_feed.h"

using namespace meshnav;
using namespace meshnav::pipeline;
using meshnav::pipeline::test::range;
using meshnav::pipeline::test::vehicleSetup;

namespace {

PoseEstimate pose(double t, Eigen::Vector3d p, Eigen::Vector3d v, double yaw_rad, double var_p) {
  PoseEstimate e;
  e.t = Timestamp::fromSec(t);
  e.p_IinG = p;
  e.v_IinG = v;
  e.q_ItoG = Eigen::Quaterniond(Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()));
  e.cov_p_m2 = var_p * Eigen::Matrix3d::Identity();
  e.cov_v = 0.04 * Eigen::Matrix3d::Identity();
  e.cov_theta_rad2 = 1e-4 * Eigen::Matrix3d::Identity();
  return e;
}

/// Two vehicles: a with tags 10, 11 (11 0.5 m ahead of its IMU); b with tag 20 (0.3 m to the left).
struct TwoVehicles {
  std::vector<Vehicle> vehicles{{"a", vehicleSetup({{10, {0, 0, 0}}, {11, {0.5, 0, 0}}})},
                                {"b", vehicleSetup({{20, {0, 0.3, 0}}})}};
  SystemSetup fleet = mergeFleetSetups(vehicles, "test");
  Diagnostics diag;
  PeerRangeFeed feed{vehicles, fleet, PeerRangeRoutingOptions{}, diag};
  /// Vehicle v ranges the three known anchors at t: not short of anchors.
  void anchorsAround(size_t v, SensorId tag, double t) {
    for (SensorId a : {101, 102, 103}) EXPECT_FALSE(feed.interVehicle(v, range(t, tag, a)));
  }
};

}  // namespace

TEST(PeerRangeFeed, ARangeToAnotherVehiclesTagIsInterVehicleAndCounted) {
  TwoVehicles f;
  EXPECT_TRUE(f.feed.interVehicle(0, range(1.0, 11, 20)));
  EXPECT_TRUE(f.feed.interVehicle(1, range(1.0, 20, 10)));
  EXPECT_FALSE(f.feed.interVehicle(0, range(1.0, 10, 101)));  // an anchor
  EXPECT_FALSE(f.feed.interVehicle(0, range(1.0, 10, 11)));   // its own tags
  EXPECT_EQ(f.diag.get("inter_vehicle_range:a"), 1);
  EXPECT_EQ(f.diag.get("inter_vehicle_range:b"), 1);
}

TEST(PeerRangeFeed, EachExchangeIsAdmittedOnceWithItsTwoVehicles) {
  TwoVehicles f;
  const auto ends = f.feed.admit(range(1.0, 11, 20));
  ASSERT_TRUE(ends);
  EXPECT_EQ(ends->a, 0u);
  EXPECT_EQ(ends->b, 1u);
  EXPECT_FALSE(f.feed.admit(range(1.0, 20, 11)));  // the same exchange from the other vehicle's data
  EXPECT_EQ(f.diag.get("inter_vehicle_range_duplicate"), 1);
  EXPECT_TRUE(f.feed.admit(range(1.1, 11, 20)));   // the next one
  EXPECT_FALSE(f.feed.admit(range(1.2, 10, 11)));  // one vehicle's two tags
  EXPECT_EQ(f.diag.get("inter_vehicle_range_not_between_two_vehicles"), 1);
}

// The vehicle with anchors sends, the one without receives; the sender's tag is its pose moved to
// the range's instant: p_S = p + v dt + R l, Σ_S = Σ_p + dt² Σ_v + J Σ_θ Jᵀ with J = −R [l]×.
TEST(PeerRangeFeed, TheReceiverGetsTheSendersTagMovedToTheRangesInstant) {
  TwoVehicles f;
  f.anchorsAround(0, 10, 4.95);  // a ranges three anchors; b none: b receives
  const RangeSample r = range(5.0, 11, 20);
  const auto ends = f.feed.admit(r);
  ASSERT_TRUE(ends);
  const PoseEstimate pa = pose(4.99, {1, 2, 1}, {1.0, -0.5, 0}, 0.5 * M_PI, 0.01);
  const PoseEstimate pb = pose(5.0, {5, 2, 1}, {0, 0, 0}, 0.0, 0.25);
  const auto routed = f.feed.route(r, *ends, pa, pb);
  ASSERT_TRUE(routed);
  EXPECT_EQ(routed->receiver, 1u);
  EXPECT_EQ(routed->sender, 0u);
  EXPECT_EQ(routed->range.peer_tag, 11);
  EXPECT_EQ(routed->range.t, r.t);
  // Yaw 90°: tag 11's lever arm (0.5, 0, 0) points along +y in G; dt = 0.01 s.
  EXPECT_NEAR((routed->range.p_peer_tag_in_G - Eigen::Vector3d(1.01, 2.495, 1.0)).norm(), 0.0, 1e-12);
  const Eigen::Matrix3d R = pa.q_ItoG.toRotationMatrix();
  const Eigen::Matrix3d J = -R * skew(Eigen::Vector3d(0.5, 0, 0));
  const Eigen::Matrix3d expected = pa.cov_p_m2 + 1e-4 * pa.cov_v + J * pa.cov_theta_rad2 * J.transpose();
  EXPECT_NEAR((routed->range.cov_peer_tag_m2 - expected).norm(), 0.0, 1e-15);
  EXPECT_EQ(f.diag.get("inter_vehicle_range_to:b"), 1);
}

TEST(PeerRangeFeed, NoRangeWithoutTheSendersEstimateOrWhenNeitherNeedsIt) {
  TwoVehicles f;
  f.anchorsAround(0, 10, 0.95);
  f.anchorsAround(1, 20, 0.95);
  // Both have anchors: neither needs the range.
  RangeSample r = range(1.0, 11, 20);
  auto ends = f.feed.admit(r);
  ASSERT_TRUE(ends);
  EXPECT_FALSE(f.feed.route(r, *ends, pose(1.0, {0, 0, 1}, {0, 0, 0}, 0, 0.01), pose(1.0, {3, 0, 1}, {0, 0, 0}, 0, 0.01)));
  EXPECT_EQ(f.diag.get("inter_vehicle_range_not_needed"), 1);
  // b short of anchors (its ranges are 2 s old), a's estimate unknown: no range.
  r = range(3.0, 11, 20);
  ends = f.feed.admit(r);
  ASSERT_TRUE(ends);
  f.anchorsAround(0, 10, 2.95);
  EXPECT_FALSE(f.feed.route(r, *ends, std::nullopt, pose(3.0, {3, 0, 1}, {0, 0, 0}, 0, 0.01)));
  EXPECT_EQ(f.diag.get("inter_vehicle_range_no_estimate"), 1);
}

// A calibrated anchor counts towards a vehicle's anchors once its ANCHOR_INIT was seen.
TEST(PeerRangeFeed, CalibratedAnchorsCountOnceInitialized) {
  TwoVehicles f;
  f.feed.interVehicle(1, range(0.9, 20, 101));
  f.feed.interVehicle(1, range(0.9, 20, 102));
  f.feed.interVehicle(1, range(0.9, 20, 106));  // not yet calibrated: not counted
  f.anchorsAround(0, 10, 0.95);
  RangeSample r = range(1.0, 11, 20);
  auto ends = f.feed.admit(r);
  auto routed = f.feed.route(r, *ends, pose(1.0, {0, 0, 1}, {0, 0, 0}, 0, 0.01), pose(1.0, {3, 0, 1}, {0, 0, 0}, 0, 0.01));
  ASSERT_TRUE(routed);
  EXPECT_EQ(routed->receiver, 1u);  // b: two anchors only
  f.feed.onAnchorInit(106);
  f.feed.interVehicle(1, range(1.9, 20, 101));
  f.feed.interVehicle(1, range(1.9, 20, 102));
  f.feed.interVehicle(1, range(1.9, 20, 106));
  f.anchorsAround(0, 10, 1.95);
  r = range(2.0, 11, 20);
  ends = f.feed.admit(r);
  EXPECT_FALSE(f.feed.route(r, *ends, pose(2.0, {0, 0, 1}, {0, 0, 0}, 0, 0.01), pose(2.0, {3, 0, 1}, {0, 0, 0}, 0, 0.01)));
  EXPECT_EQ(f.diag.get("inter_vehicle_range_not_needed"), 1);
}
