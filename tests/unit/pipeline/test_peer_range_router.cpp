#include <gtest/gtest.h>

#include <stdexcept>

#include "pipeline/peer_range_router.h"

using meshnav::Timestamp;
using meshnav::pipeline::PeerRangeRouter;
using meshnav::pipeline::PeerRangeRoutingOptions;
using meshnav::pipeline::PeerSide;

namespace {

Timestamp at(double s) { return Timestamp::fromSec(s); }

PeerSide side(double trace) {
  PeerSide p;
  p.has_estimate = true;
  p.cov_p_trace_m2 = trace;
  return p;
}

/// Vehicle v ranges anchors 1..n at t.
void seeAnchors(PeerRangeRouter& r, size_t v, int n, double t) {
  for (int k = 1; k <= n; ++k) r.noteAnchorRange(v, static_cast<meshnav::SensorId>(k), at(t));
}

}  // namespace

TEST(PeerRangeRouter, AnchorsAreCountedWithinTheWindowOnly) {
  PeerRangeRouter r(PeerRangeRoutingOptions{}, 2);
  seeAnchors(r, 0, 2, 10.5);
  r.noteAnchorRange(0, 7, Timestamp::fromSec(11.0));
  r.noteAnchorRange(0, 7, Timestamp::fromSec(10.2));  // older: the last stays 11 s
  EXPECT_EQ(r.anchorsSeen(0, at(11.0)), 3);
  EXPECT_FALSE(r.shortOfAnchors(0, at(11.0)));
  EXPECT_EQ(r.anchorsSeen(0, at(11.6)), 1);  // 10.5 s is 1.1 s back, beyond the 1 s window
  EXPECT_TRUE(r.shortOfAnchors(0, at(11.6)));
  EXPECT_EQ(r.anchorsSeen(1, at(11.0)), 0);
}

TEST(PeerRangeRouter, InformationFlowsFromAVehicleWithAnchorsToOneWithoutAndNeverBack) {
  PeerRangeRouter r(PeerRangeRoutingOptions{}, 3);
  // v0 sees 4 anchors, v1 none: v1 receives whatever the covariances say.
  seeAnchors(r, 0, 4, 20.0);
  auto d = r.decide(0, side(5.0), 1, side(0.1), at(20.5));
  ASSERT_TRUE(d.receiver);
  EXPECT_EQ(*d.receiver, 1u);
  EXPECT_EQ(*r.decide(1, side(0.1), 0, side(5.0), at(20.5)).receiver, 1u);  // the order of the ends does not matter
  r.noteReceived(1, at(20.5));
  // v1 is not clean for 10 s: v2, also without anchors, cannot receive from it (a cycle if v2
  // ever sends to v1), but v1 may still receive from v2 (clean).
  d = r.decide(1, side(1.0), 2, side(2.0), at(25.0));
  ASSERT_TRUE(d.receiver);
  EXPECT_EQ(*d.receiver, 1u);
  r.noteReceived(1, at(25.0));
  r.noteReceived(2, at(25.0));
  d = r.decide(1, side(1.0), 2, side(2.0), at(26.0));
  EXPECT_FALSE(d.receiver);
  EXPECT_EQ(d.why, "cycle");
  // Both with anchors: not needed.
  seeAnchors(r, 1, 3, 30.0);
  seeAnchors(r, 0, 3, 30.0);
  d = r.decide(0, side(1.0), 1, side(2.0), at(30.5));
  EXPECT_FALSE(d.receiver);
  EXPECT_EQ(d.why, "not_needed");
  // No estimate at one end.
  d = r.decide(0, side(1.0), 2, PeerSide{}, at(30.5));
  EXPECT_FALSE(d.receiver);
  EXPECT_EQ(d.why, "no_estimate");
  // 10 s after its last peer range v1 is clean again (35.0 + ... > 25.0 + 10).
  EXPECT_FALSE(r.clean(1, at(35.0)));
  EXPECT_TRUE(r.clean(1, at(35.1)));
}

TEST(PeerRangeRouter, BothShortAndCleanTheLargerCovarianceReceives) {
  PeerRangeRouter r(PeerRangeRoutingOptions{}, 2);
  EXPECT_EQ(*r.decide(0, side(1.0), 1, side(2.0), at(1.0)).receiver, 1u);
  EXPECT_EQ(*r.decide(0, side(3.0), 1, side(2.0), at(1.0)).receiver, 0u);
}

TEST(PeerRangeRouter, BadOptionsAreRefused) {
  PeerRangeRoutingOptions o;
  o.min_anchors = -1;
  EXPECT_THROW(PeerRangeRouter(o, 2), std::invalid_argument);
  o = {};
  o.anchor_window_s = 0.0;
  EXPECT_THROW(PeerRangeRouter(o, 2), std::invalid_argument);
  o = {};
  o.memory_s = -1.0;
  EXPECT_THROW(PeerRangeRouter(o, 2), std::invalid_argument);
  EXPECT_THROW(PeerRangeRouter(PeerRangeRoutingOptions{}, 0), std::invalid_argument);
  EXPECT_NE(PeerRangeRoutingOptions{}.toString().find("3 anchors"), std::string::npos);
}
