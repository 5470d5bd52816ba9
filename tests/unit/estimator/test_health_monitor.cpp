/// HealthMonitor: states from windowed gating, NIS and aiding gaps; hysteresis.
#include <gtest/gtest.h>

#include "estimator/health/health_monitor.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {
Timestamp at(double s) { return Timestamp::fromSec(s); }

/// Ranges every 0.1 s over [t0, t1) cycling over `anchors`; `gated(k)` decides per range.
template <typename F>
void ranges(HealthMonitor& m, double t0, double t1, int anchors, F gated, double nis = 1.0) {
  int k = 0;
  for (double t = t0; t < t1; t += 0.1, ++k) {
    m.onUpdate(at(t), "range", 101 + k % anchors, !gated(k), gated(k) ? 50.0 : nis);
    m.evaluate(at(t), 0.1);
  }
}
}  // namespace

TEST(HealthMonitor, ConsistentRangesStayOk) {
  HealthMonitor m;
  m.reset(at(0));
  ranges(m, 0.0, 20.0, 4, [](int) { return false; });
  EXPECT_EQ(m.health(), Health::Ok);
  EXPECT_EQ(m.stats().at("range").n_gated, 0);
  EXPECT_NEAR(m.stats().at("range").meanNis(), 1.0, 1e-12);
}

TEST(HealthMonitor, SustainedGatingOnSeveralAnchorsIsLost) {
  HealthMonitor m;
  m.reset(at(0));
  ranges(m, 0.0, 5.0, 4, [](int) { return false; });
  ranges(m, 5.0, 6.5, 4, [](int) { return true; });  // 15 of 40 in the window gated: degraded
  EXPECT_EQ(m.health(), Health::Degraded);
  ranges(m, 6.5, 12.0, 4, [](int) { return true; });
  EXPECT_EQ(m.health(), Health::Lost);
  EXPECT_NE(m.reason().find("gated"), std::string::npos) << m.reason();
  EXPECT_DOUBLE_EQ(m.stats().at("anchor 101").gatedFraction(), 1.0);
}

TEST(HealthMonitor, OneBadAnchorIsDegradedNotLost) {
  HealthMonitor m;
  m.reset(at(0));
  ranges(m, 0.0, 20.0, 2, [](int k) { return k % 2 == 0; });  // anchor 101 always gated, 102 never
  EXPECT_EQ(m.health(), Health::Degraded);
}

TEST(HealthMonitor, HighNisIsDegradedAndRecoveryNeedsHold) {
  HealthOptions o;
  o.hold_s = 2.0;
  HealthMonitor m(o);
  m.reset(at(0));
  ranges(m, 0.0, 6.0, 4, [](int) { return false; }, 6.0);
  EXPECT_EQ(m.health(), Health::Degraded);
  // The window's mean NIS falls below 4 at ~7.6 s; ok must then hold 2 s.
  ranges(m, 6.0, 9.0, 4, [](int) { return false; }, 1.0);
  EXPECT_EQ(m.health(), Health::Degraded);
  ranges(m, 9.0, 13.0, 4, [](int) { return false; }, 1.0);
  EXPECT_EQ(m.health(), Health::Ok);
}

TEST(HealthMonitor, NoAidingIsDegradedThenLostAndLargeSigmaIsLost) {
  HealthMonitor m;
  m.reset(at(0));
  m.evaluate(at(3.0), 0.1);
  EXPECT_EQ(m.health(), Health::Degraded);
  m.evaluate(at(10.5), 0.1);
  EXPECT_EQ(m.health(), Health::Lost);
  EXPECT_NE(m.reason().find("no usable position aiding"), std::string::npos) << m.reason();
  HealthMonitor n;
  n.reset(at(0));
  ranges(n, 0.0, 2.0, 4, [](int) { return false; });
  n.evaluate(at(2.0), 5.0);
  EXPECT_EQ(n.health(), Health::Lost);
}

TEST(HealthMonitor, GatingAloneWithFittingAcceptedRangesIsTellable) {
  // A third of the ranges gated (NLOS outliers, or a filter drifting away): degraded either way.
  // Whether the accepted ones fit tells the two apart for the recovery (EstimatorNode).
  HealthMonitor nlos;
  nlos.reset(at(0));
  ranges(nlos, 0.0, 8.0, 4, [](int k) { return k % 3 == 0; }, 1.1);
  EXPECT_EQ(nlos.health(), Health::Degraded);
  EXPECT_TRUE(nlos.acceptedRangesFit(at(8.0)));
  HealthMonitor drift;
  drift.reset(at(0));
  ranges(drift, 0.0, 8.0, 4, [](int k) { return k % 3 == 0; }, 6.0);
  EXPECT_EQ(drift.health(), Health::Degraded);
  EXPECT_FALSE(drift.acceptedRangesFit(at(8.0)));
  // No range accepted for longer than degraded_no_aiding_s: not fitting either.
  EXPECT_FALSE(nlos.acceptedRangesFit(at(8.0 + HealthOptions{}.degraded_no_aiding_s + 0.5)));
}
