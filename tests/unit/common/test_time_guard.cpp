/// TimeGuard: inputs far from the current time are refused and never move it; a jump of the whole
/// stream is followed after `rebase_after` agreeing inputs (issue 12, finding 1).
#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "common/time_guard.h"

using namespace meshnav;

namespace {
Timestamp sec(double s) { return Timestamp::fromSec(s); }
using V = TimeGuard::Verdict;
}  // namespace

TEST(TimeGuard, FarInputsAreRefusedAndDoNotMoveTheClock) {
  TimeGuard g({10.0, 5});
  EXPECT_EQ(g.check(sec(100.0)), V::Accept);
  EXPECT_EQ(g.check(sec(100.5)), V::Accept);
  EXPECT_EQ(g.check(sec(3700.5)), V::Ahead);   // +1 h
  EXPECT_EQ(g.check(sec(50.0)), V::Behind);
  EXPECT_EQ(*g.now(), sec(100.5));
  EXPECT_EQ(g.check(sec(101.0)), V::Accept);   // normal inputs go on
  EXPECT_EQ(g.check(sec(95.0)), V::Accept);    // late within the offset: the caller's window decides
  EXPECT_EQ(*g.now(), sec(101.0));
  EXPECT_EQ(g.check(sec(111.0)), V::Accept);   // exactly the offset
  EXPECT_EQ(g.check(sec(121.000001)), V::Ahead);
}

TEST(TimeGuard, TheLimitBehindMayBeLonger) {
  TimeGuard g({10.0, 5, 300.0});
  g.check(sec(1000.0));
  EXPECT_EQ(g.check(sec(750.0)), V::Accept);
  EXPECT_EQ(g.check(sec(699.0)), V::Behind);
  EXPECT_EQ(g.check(sec(1011.0)), V::Ahead);
  EXPECT_EQ(*g.now(), sec(1000.0));
}

TEST(TimeGuard, ExtremeStampsDoNotOverflow) {
  TimeGuard g({10.0, 5});
  g.check(Timestamp{std::numeric_limits<int64_t>::min() + 1});
  EXPECT_EQ(g.check(Timestamp{std::numeric_limits<int64_t>::max()}), V::Ahead);
  TimeGuard h({10.0, 5});
  h.check(sec(1.0));
  EXPECT_EQ(h.check(Timestamp{std::numeric_limits<int64_t>::min()}), V::Behind);
  EXPECT_EQ(h.check(Timestamp{std::numeric_limits<int64_t>::max()}), V::Ahead);
  EXPECT_EQ(*h.now(), sec(1.0));
}

TEST(TimeGuard, OneBadSourceAmongGoodOnesNeverRebases) {
  TimeGuard g({10.0, 5});
  int refused = 0;
  for (int i = 0; i < 1000; ++i) {
    EXPECT_EQ(g.check(sec(0.01 * i)), V::Accept);
    if (g.check(sec(3600.0 + 0.01 * i)) == V::Ahead) ++refused;  // a sensor whose clock is off
  }
  EXPECT_EQ(refused, 1000);
  EXPECT_EQ(*g.now(), sec(9.99));
}

TEST(TimeGuard, RandomStampsDoNotAgree) {
  TimeGuard g({10.0, 5});
  g.check(sec(0.0));
  std::mt19937_64 rng(1);
  for (int i = 0; i < 10000; ++i) {
    const V v = g.check(Timestamp{static_cast<int64_t>(rng())});
    EXPECT_TRUE(v == V::Ahead || v == V::Behind);
  }
  EXPECT_EQ(*g.now(), sec(0.0));
}

TEST(TimeGuard, AJumpOfTheWholeStreamIsFollowed) {
  TimeGuard g({10.0, 5});
  g.check(sec(10.0));
  for (int i = 1; i < 5; ++i) EXPECT_EQ(g.check(sec(70.0 + 0.1 * i)), V::Ahead) << i;
  EXPECT_EQ(g.check(sec(70.5)), V::Rebased);
  EXPECT_EQ(g.lastJump(), Duration::fromSec(60.5));
  EXPECT_EQ(*g.now(), sec(70.5));
  EXPECT_EQ(g.check(sec(70.6)), V::Accept);
}

TEST(TimeGuard, AWrongFirstInputIsLeftBehind) {
  TimeGuard g({10.0, 3});
  g.check(sec(3600.0));  // the first input sets the clock, wrongly
  EXPECT_EQ(g.check(sec(1.0)), V::Behind);
  EXPECT_EQ(g.check(sec(1.1)), V::Behind);
  EXPECT_EQ(g.check(sec(1.2)), V::Rebased);
  EXPECT_LT(g.lastJump().us, 0);
  EXPECT_EQ(*g.now(), sec(1.2));
}

TEST(TimeGuard, AnAcceptedInputRestartsTheCount) {
  TimeGuard g({10.0, 3});
  g.check(sec(0.0));
  EXPECT_EQ(g.check(sec(100.0)), V::Ahead);
  EXPECT_EQ(g.check(sec(100.1)), V::Ahead);
  EXPECT_EQ(g.check(sec(0.1)), V::Accept);
  EXPECT_EQ(g.check(sec(100.2)), V::Ahead);
  EXPECT_EQ(g.check(sec(100.3)), V::Ahead);
  EXPECT_EQ(g.check(sec(100.4)), V::Rebased);
}

TEST(TimeGuard, OnceTwoSourcesAreKnownOneAloneNeverMovesTheClock) {
  // Issue 36: a burst of one source that disagrees with the others is that source's fault.
  TimeGuard g({10.0, 5});
  Diagnostics d;
  EXPECT_EQ(g.admit("IMU", sec(1.0), d), V::Accept);
  EXPECT_EQ(g.admit("RANGE", sec(1.01), d), V::Accept);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(g.admit("IMU", sec(3601.0 + 0.005 * i), d), V::Ahead) << i;
  EXPECT_EQ(*g.now(), sec(1.01));
  EXPECT_EQ(d.get("IMU:time_ahead"), 100);
  EXPECT_EQ(d.get("IMU:time_jump_alone"), 1);  // once per burst
  EXPECT_EQ(d.get("time_rebased"), 0);
  EXPECT_EQ(g.admit("IMU", sec(1.02), d), V::Accept);  // the good stream goes on
  // The whole stream jumping: the clock follows when a second source agrees.
  for (int i = 0; i < 20; ++i) EXPECT_EQ(g.admit("IMU", sec(61.0 + 0.005 * i), d), V::Ahead);
  EXPECT_EQ(g.admit("RANGE", sec(61.1), d), V::Rebased);
  EXPECT_EQ(*g.now(), sec(61.1));
  EXPECT_EQ(d.get("time_rebased"), 1);
  // A single anonymous source (check() without one) keeps the old rule.
  TimeGuard h({10.0, 3});
  h.check(sec(0.0));
  h.check(sec(100.0));
  h.check(sec(100.1));
  EXPECT_EQ(h.check(sec(100.2)), V::Rebased);
}

TEST(TimeGuard, AdmitCountsPerKind) {
  TimeGuard g({10.0, 50});
  Diagnostics d;
  EXPECT_EQ(g.admit("IMU", sec(1.0), d), V::Accept);
  EXPECT_EQ(g.admit("RANGE", sec(3601.0), d), V::Ahead);
  EXPECT_EQ(g.admit("IMU", sec(-3600.0), d), V::Behind);
  EXPECT_EQ(d.get("RANGE:time_ahead"), 1);
  EXPECT_EQ(d.get("IMU:time_behind"), 1);
  EXPECT_EQ(d.total(), 2);
}

TEST(TimeGuard, OptionsAreValidated) {
  EXPECT_THROW(TimeGuard({0.0, 5}), std::invalid_argument);
  EXPECT_THROW(TimeGuard({10.0, 0}), std::invalid_argument);
  EXPECT_THROW(TimeGuard({std::numeric_limits<double>::infinity(), 5}), std::invalid_argument);
}
