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
  r.noteReceived(1, 0, at(20.5));
  EXPECT_TRUE(r.holds(1, 0, at(20.5)));
  EXPECT_FALSE(r.holds(0, 1, at(20.5)));
  // v1 holds v0's information, nothing of v2's: v2 (also without anchors) may receive from v1, and
  // v1 from v2; the larger covariance receives.
  d = r.decide(1, side(1.0), 2, side(2.0), at(25.0));
  ASSERT_TRUE(d.receiver);
  EXPECT_EQ(*d.receiver, 2u);
  r.noteReceived(2, 1, at(25.0));
  // v2 now holds v1's and, through v1, v0's: it may not send to either, v1 not to v2.
  EXPECT_TRUE(r.holds(2, 1, at(25.0)));
  EXPECT_TRUE(r.holds(2, 0, at(25.0)));
  d = r.decide(1, side(3.0), 2, side(2.0), at(26.0));
  ASSERT_TRUE(d.receiver) << "v1 holds nothing of v2's: v2 may receive from it again";
  EXPECT_EQ(*d.receiver, 2u);
  // v0, short of anchors now too, may not receive from v2 (v2 holds v0's information through v1);
  // v2 may receive from v0 (v0 holds nothing of v2's).
  d = r.decide(0, side(9.0), 2, side(1.0), at(26.0));
  ASSERT_TRUE(d.receiver);
  EXPECT_EQ(*d.receiver, 2u);
  // Both holding each other's: a cycle either way.
  r.noteReceived(1, 2, at(26.0));
  d = r.decide(1, side(1.0), 2, side(2.0), at(27.0));
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
  // What a vehicle absorbed counts for memory_s (10 s): v2 received from v1 at 25 s and holds v1's
  // until 35 s; v1 received from v2 at 26 s and holds v2's until 36 s.
  EXPECT_TRUE(r.holds(2, 1, at(35.0)));
  EXPECT_FALSE(r.holds(2, 1, at(35.1)));
  EXPECT_TRUE(r.holds(1, 2, at(36.0)));
  EXPECT_FALSE(r.holds(1, 2, at(36.1)));
}

TEST(PeerRangeRouter, AVehicleThatReceivedStillSendsToOneWhoseInformationItDoesNotHold) {
  // Seed 9's outage (docs/fleet.md): v3, short of anchors now and then, received from v0; v4 lost
  // its anchors. v3 holds nothing of v4's, so v4 receives v3's ranges (the rule before refused them
  // for 10 s after v3's last peer range, and v4 drifted 1.16 m).
  PeerRangeRouter r(PeerRangeRoutingOptions{}, 5);
  seeAnchors(r, 0, 5, 60.0);
  r.noteReceived(3, 0, at(60.2));
  seeAnchors(r, 3, 5, 60.5);
  const auto d = r.decide(3, side(0.02), 4, side(0.3), at(61.0));
  ASSERT_TRUE(d.receiver);
  EXPECT_EQ(*d.receiver, 4u);
}

TEST(PeerRangeRouter, BothShortAndHoldingNothingOfEachOtherTheLargerCovarianceReceives) {
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

TEST(PeerRangeRouter, ARestoredProvenanceKeepsTheFlowAcyclicAndDropsWhatNoLongerCounts) {
  PeerRangeRouter before(PeerRangeRoutingOptions{}, 3);
  seeAnchors(before, 0, 4, 20.0);
  before.noteReceived(1, 0, at(20.0));  // v1 took v0's information at 20 s
  const PeerRangeRouter::Provenance journal = before.provenance();
  ASSERT_EQ(journal.size(), 3u);
  EXPECT_EQ(journal[1].count(0), 1u);
  // A respawned router at 22 s: v0 lost its anchors, v1 sees four. Started empty it would let v0
  // receive from v1, whose estimate still holds v0's own information.
  auto roles = [](PeerRangeRouter& r) {
    seeAnchors(r, 1, 4, 22.0);
    return r.decide(0, side(1.0), 1, side(0.1), at(22.0));
  };
  PeerRangeRouter fresh(PeerRangeRoutingOptions{}, 3);
  ASSERT_TRUE(roles(fresh).receiver);
  PeerRangeRouter restored(PeerRangeRoutingOptions{}, 3);
  EXPECT_EQ(restored.restoreProvenance(journal, at(22.0)), 1u);
  const auto d = roles(restored);
  EXPECT_FALSE(d.receiver);
  EXPECT_EQ(d.why, "cycle");
  // What no longer counts is not taken: an entry from after `now` (another run's file), one older
  // than memory_s, a vehicle about itself.
  PeerRangeRouter::Provenance odd(3);
  odd[0][1] = at(30.0);
  odd[1][2] = at(5.0);
  odd[2][2] = at(21.0);
  odd[2][0] = at(21.0);
  PeerRangeRouter r(PeerRangeRoutingOptions{}, 3);
  EXPECT_EQ(r.restoreProvenance(odd, at(22.0)), 1u);
  EXPECT_TRUE(r.holds(2, 0, at(22.0)));
  EXPECT_FALSE(r.holds(0, 1, at(22.0)));
  EXPECT_FALSE(r.holds(1, 2, at(22.0)));
  EXPECT_EQ(r.provenance()[2].count(2), 0u);
  // Another fleet's provenance is refused.
  EXPECT_THROW(r.restoreProvenance(PeerRangeRouter::Provenance(2), at(22.0)), std::invalid_argument);
  PeerRangeRouter::Provenance out_of_fleet(3);
  out_of_fleet[0][7] = at(21.0);
  EXPECT_THROW(r.restoreProvenance(out_of_fleet, at(22.0)), std::invalid_argument);
}
