// Inter-vehicle ranges where the vehicles' POSEs are messages (pipeline/peer_range_relay.h, the
// core of `peer_router`): a range waits for both vehicles' POSE of its instant, uses the pose
// nearest it, goes out at the end of the wait without a POSE that does not come, and never twice.
#include <gtest/gtest.h>

#include "fleet_test_data.h"
#include "pipeline/fleet.h"
#include "pipeline/peer_range_relay.h"

using namespace meshnav;
using namespace meshnav::pipeline;
using meshnav::pipeline::test::range;
using meshnav::pipeline::test::vehicleSetup;

namespace {

PoseEstimate pose(double t, double x, double vx = 0.0) {
  PoseEstimate e;
  e.t = Timestamp::fromSec(t);
  e.p_IinG = {x, 0, 1};
  e.v_IinG = {vx, 0, 0};
  e.cov_p_m2 = 0.01 * Eigen::Matrix3d::Identity();
  e.cov_v = 0.04 * Eigen::Matrix3d::Identity();
  e.cov_theta_rad2 = 1e-4 * Eigen::Matrix3d::Identity();
  return e;
}

/// a (tag 10) ranges the three known anchors, b (tag 20) none: b receives a's tag.
struct Relay {
  explicit Relay(PeerRangeRelayOptions o = {}) : relay(vehicles, fleet, PeerRangeRoutingOptions{}, o, diag) {}
  std::vector<Vehicle> vehicles{{"a", vehicleSetup({{10, {0, 0, 0}}})}, {"b", vehicleSetup({{20, {0, 0, 0}}})}};
  SystemSetup fleet = mergeFleetSetups(vehicles, "test");
  Diagnostics diag;
  PeerRangeRelay relay;
  void anchorsOfA(double t) {
    for (SensorId an : {101, 102, 103}) EXPECT_TRUE(relay.onRange(0, range(t, 10, an)).empty());
  }
};

}  // namespace

TEST(PeerRangeRelay, ARangeWaitsForBothVehiclesPoseOfItsInstant) {
  Relay f;
  f.anchorsOfA(0.99);
  EXPECT_TRUE(f.relay.onPose(0, pose(0.995, 1.0, 2.0)).empty());
  EXPECT_TRUE(f.relay.onPose(1, pose(0.995, 4.0)).empty());
  EXPECT_TRUE(f.relay.onRange(0, range(1.0, 10, 20)).empty());  // no POSE at 1.0 yet
  EXPECT_EQ(f.relay.held(), 1u);
  EXPECT_TRUE(f.relay.onPose(0, pose(1.0, 1.01, 2.0)).empty());  // a's is there, b's not
  const auto out = f.relay.onPose(1, pose(1.001, 4.0));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(f.relay.held(), 0u);
  EXPECT_EQ(out[0].receiver, 1u);
  EXPECT_EQ(out[0].range.peer_tag, 10);
  // a's POSE of the range's own instant, not the older one moved forward.
  EXPECT_NEAR((out[0].range.p_peer_tag_in_G - Eigen::Vector3d(1.01, 0, 1)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(out[0].range.cov_peer_tag_m2(0, 0), 0.01, 1e-12);  // dt 0, lever arm 0
  EXPECT_EQ(f.diag.get("inter_vehicle_range_pose_late"), 0);
}

TEST(PeerRangeRelay, APoseAfterTheRangeIsUsedWhenNearer) {
  Relay f;
  f.anchorsOfA(0.99);
  f.relay.onPose(0, pose(0.96, 0.9, 2.0));
  f.relay.onPose(1, pose(0.999, 4.0));
  EXPECT_TRUE(f.relay.onRange(0, range(1.0, 10, 20)).empty());
  f.relay.onPose(1, pose(1.0, 4.0));
  const auto out = f.relay.onPose(0, pose(1.01, 1.02, 2.0));  // 10 ms after the range: nearer than 40 ms before
  ASSERT_EQ(out.size(), 1u);
  // Moved back by 10 ms: x = 1.02 − 2.0 · 0.01; Σ_x = 0.01 + 0.01² · 0.04.
  EXPECT_NEAR(out[0].range.p_peer_tag_in_G.x(), 1.0, 1e-12);
  EXPECT_NEAR(out[0].range.cov_peer_tag_m2(0, 0), 0.01 + 1e-4 * 0.04, 1e-12);
}

// A POSE that does not come: at the end of the wait (data time max_wait_s past the range) the
// range goes with the poses there are; one farther than max_pose_age_s counts as no estimate.
TEST(PeerRangeRelay, AtTheEndOfTheWaitTheRangeGoesWithThePosesThereAre) {
  PeerRangeRelayOptions o;
  o.max_wait_s = 0.2;
  o.max_pose_age_s = 0.05;
  Relay f(o);
  f.relay.onPose(0, pose(0.98, 1.0));
  f.relay.onPose(1, pose(0.99, 4.0));
  f.anchorsOfA(0.99);
  EXPECT_TRUE(f.relay.onRange(0, range(1.0, 10, 20)).empty());
  EXPECT_TRUE(f.relay.onPose(1, pose(1.1, 4.0)).empty());  // b goes on; a's estimator is silent
  f.anchorsOfA(1.15);
  const auto out = f.relay.onRange(1, range(1.2, 20, 101));  // data time 1.2: the wait is over
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].receiver, 1u);
  EXPECT_EQ(f.diag.get("inter_vehicle_range_pose_late"), 1);
  EXPECT_NEAR(out[0].range.p_peer_tag_in_G.x(), 1.0, 1e-12);  // a's POSE 20 ms before: within 50 ms
  // Next: a's newest POSE is 0.3 s old when the wait ends: no estimate of a, no range.
  EXPECT_TRUE(f.relay.onRange(0, range(1.25, 10, 20)).empty());
  f.relay.onPose(1, pose(1.3, 4.0));
  EXPECT_TRUE(f.relay.onRange(1, range(1.5, 20, 101)).empty());
  EXPECT_EQ(f.relay.held(), 0u);
  EXPECT_EQ(f.diag.get("inter_vehicle_range_pose_late"), 2);
  EXPECT_EQ(f.diag.get("inter_vehicle_range_no_estimate"), 1);
}

TEST(PeerRangeRelay, TheSameExchangeFromBothBusesGoesOutOnce) {
  Relay f;
  f.anchorsOfA(0.99);
  f.relay.onPose(0, pose(1.0, 1.0));
  f.relay.onPose(1, pose(1.0, 4.0));
  EXPECT_EQ(f.relay.onRange(0, range(1.0, 10, 20)).size(), 1u);
  EXPECT_TRUE(f.relay.onRange(1, range(1.0, 20, 10)).empty());
  EXPECT_EQ(f.diag.get("inter_vehicle_range_duplicate"), 1);
}

TEST(PeerRangeRelay, WaitingRangesAreBoundedAndOptionsChecked) {
  PeerRangeRelayOptions o;
  o.max_held = 2;
  Relay f(o);
  for (int k = 0; k < 3; ++k) EXPECT_TRUE(f.relay.onRange(0, range(1.0 + 0.001 * k, 10, 20)).empty());
  EXPECT_EQ(f.relay.held(), 2u);
  EXPECT_EQ(f.diag.get("inter_vehicle_range_hold_full"), 1);
  for (auto bad : {PeerRangeRelayOptions{0.0, 0.5, 10}, PeerRangeRelayOptions{0.05, -1.0, 10},
                   PeerRangeRelayOptions{0.05, 0.5, 0}}) {
    Relay g;
    EXPECT_THROW(PeerRangeRelay(g.vehicles, g.fleet, PeerRangeRoutingOptions{}, bad, g.diag), std::invalid_argument);
  }
  EXPECT_THROW(f.relay.onRange(2, range(1.0, 10, 20)), std::out_of_range);
}

TEST(PeerRangeRelay, RangesGoOutOldestFirstWhateverTheirArrivalOrder) {
  Relay f;
  f.anchorsOfA(0.99);
  // Two exchanges of the same pair, the later one heard first (another bus's latency).
  EXPECT_TRUE(f.relay.onRange(0, range(1.002, 10, 20)).empty());
  EXPECT_TRUE(f.relay.onRange(1, range(1.001, 20, 10)).empty());
  EXPECT_TRUE(f.relay.onPose(0, pose(1.003, 1.0)).empty());
  const auto out = f.relay.onPose(1, pose(1.003, 4.0));
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].range.range.t, Timestamp::fromSec(1.001));
  EXPECT_EQ(out[1].range.range.t, Timestamp::fromSec(1.002));
}

TEST(PeerRangeRelay, ARestartsJournalIsTakenAtTheFirstInputOfItsRunOnly) {
  PeerRangeRouter::Provenance journal(2);
  journal[0][1] = Timestamp::fromSec(0.5);  // a took b's information at 0.5 s
  {
    Relay f;
    f.relay.restoreAtFirstData(journal, Timestamp::fromSec(0.9));
    EXPECT_TRUE(f.relay.restorePending());
    EXPECT_FALSE(f.relay.feed().router().holds(0, 1, Timestamp::fromSec(0.99)));
    f.anchorsOfA(0.99);  // the first input takes it
    EXPECT_FALSE(f.relay.restorePending());
    EXPECT_EQ(f.diag.get("peer_router_state_restored"), 1);
    EXPECT_TRUE(f.relay.feed().router().holds(0, 1, Timestamp::fromSec(0.99)));
    // So a, which holds b's information, does not send to b (b ranges no anchors: short of them).
    EXPECT_TRUE(f.relay.onPose(0, pose(1.0, 1.0)).empty());
    EXPECT_TRUE(f.relay.onPose(1, pose(1.0, 4.0)).empty());
    EXPECT_TRUE(f.relay.onRange(0, range(1.0, 10, 20)).empty());
    EXPECT_TRUE(f.relay.onPose(0, pose(1.6, 1.0)).empty());  // the wait is over: not routed
    EXPECT_EQ(f.relay.held(), 0u);
    EXPECT_EQ(f.diag.get("inter_vehicle_range_cycle"), 1);
  }
  {  // the journal is of a later data time than this stream: another run's
    Relay f;
    f.relay.restoreAtFirstData(journal, Timestamp::fromSec(30.0));
    f.anchorsOfA(0.99);
    EXPECT_EQ(f.diag.get("peer_router_state_not_used"), 1);
    EXPECT_EQ(f.diag.get("peer_router_state_restored"), 0);
    EXPECT_FALSE(f.relay.feed().router().holds(0, 1, Timestamp::fromSec(0.99)));
  }
  {  // nothing in it counts any more (written more than memory_s, 10 s, before)
    Relay f;
    f.relay.restoreAtFirstData(journal, Timestamp::fromSec(0.9));
    f.anchorsOfA(11.0);
    EXPECT_EQ(f.diag.get("peer_router_state_not_used"), 1);
  }
  Relay f;
  EXPECT_THROW(f.relay.restoreAtFirstData(PeerRangeRouter::Provenance(3), Timestamp::fromSec(1.0)), std::invalid_argument);
}
