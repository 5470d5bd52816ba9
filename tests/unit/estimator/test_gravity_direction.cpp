/// GravityDirection (estimator/init/gravity_direction.h) against a scripted Context: when the
/// comparison of both signs runs (first_s after the initialization, again while undecided each time
/// the data has doubled, at most kMaxChecks times, once early on a large range NIS), what +z does (sign, the models turned,
/// a re-initialization retried every kFlipRetry_s) and what a vertical sensor prevents.
#include <gtest/gtest.h>

#include <deque>
#include <vector>

#include "estimator/init/gravity_direction.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

Timestamp at(double s) { return Timestamp::fromSec(s); }

constexpr double kFirst_s = 3.0;  // init.motion_min_span_s
constexpr double kWindow_s = 12.0;
constexpr double kEarlyRatio = 6.0;

using Check = std::optional<MotionAligner::GravityCheck>;
/// Costs that decide for +z (zDown), for −z (zUp) or neither (undecided), margin 10.
Check zDown() { return MotionAligner::GravityCheck{200.0, 50.0, 10.0, 80}; }
Check zUp() { return MotionAligner::GravityCheck{50.0, 200.0, 10.0, 80}; }
Check undecided() { return MotionAligner::GravityCheck{100.0, 95.0, 10.0, 80}; }

/// Records every call; answers the comparisons and re-initializations from scripts (then
/// undecided / accepted).
class FakeContext : public GravityDirection::Context {
 public:
  std::deque<Check> checks;
  std::deque<bool> reinit_answers;
  bool vertical = false;
  int compared = 0, turned = 0;
  std::vector<Timestamp> reinit_at;

  Check compareGravitySigns() override {
    ++compared;
    if (checks.empty()) return undecided();
    Check c = checks.front();
    checks.pop_front();
    return c;
  }
  std::string whyNot() const override { return "too few ranges"; }
  bool hasVerticalSensor() const override { return vertical; }
  void gravityTurned() override { ++turned; }
  bool reinitializeWithGravity(Timestamp t) override {
    reinit_at.push_back(t);
    if (reinit_answers.empty()) return true;
    const bool ok = reinit_answers.front();
    reinit_answers.pop_front();
    return ok;
  }
  double rangeNisRatio() const override { return 12.0; }
};

struct GravityTest : ::testing::Test {
  Diagnostics diag;
  GravityDirection g{kFirst_s, kWindow_s, kEarlyRatio, diag};
  FakeContext c;
};

}  // namespace

TEST_F(GravityTest, NothingRunsBeforeTheFirstInitialization) {
  g.noteRangeNisRatio(100.0);  // no early check either: nothing is scheduled yet
  for (double t = 0.0; t < 50.0; t += 0.5) g.onImu(at(t), c);
  EXPECT_EQ(c.compared, 0);
  EXPECT_EQ(g.zSign(), -1.0);
  EXPECT_EQ(diag.get("gravity_early_check"), 0);
}

TEST_F(GravityTest, TheFirstComparisonRunsTheShortestWindowAfterTheFirstInitialization) {
  c.checks = {zUp()};
  g.onInitialized(at(5.0));
  g.onInitialized(at(7.0));  // a later initialization does not move it
  g.onImu(at(7.99), c);
  EXPECT_EQ(c.compared, 0);
  g.onImu(at(8.0), c);
  EXPECT_EQ(c.compared, 1);
  // Decided for −z: never again, not even after another initialization.
  g.onInitialized(at(30.0));
  for (double t = 8.5; t < 80.0; t += 0.5) g.onImu(at(t), c);
  EXPECT_EQ(c.compared, 1);
  EXPECT_EQ(g.zSign(), -1.0);
  EXPECT_EQ(c.turned, 0);
  EXPECT_TRUE(c.reinit_at.empty());
}

TEST_F(GravityTest, UndecidedOrRefusedIsComparedAgainWhenTheDataHasDoubledAtMostMaxChecksTimes) {
  ASSERT_EQ(GravityDirection::kMaxChecks, 4);
  c.checks = {std::nullopt, undecided(), undecided(), undecided(), zDown()};  // the fifth is never asked
  g.onInitialized(at(0.0));
  g.onImu(at(3.0), c);
  EXPECT_EQ(c.compared, 1);
  g.onImu(at(8.9), c);
  EXPECT_EQ(c.compared, 1);  // rescheduled from the check's time by twice the first step: 9
  g.onImu(at(9.0), c);
  EXPECT_EQ(c.compared, 2);
  g.onImu(at(20.9), c);
  EXPECT_EQ(c.compared, 2);  // then 12 s (the window caps the doubling): 21, 33
  g.onImu(at(21.0), c);
  EXPECT_EQ(c.compared, 3);
  g.onImu(at(33.0), c);
  EXPECT_EQ(c.compared, 4);
  for (double t = 33.5; t < 100.0; t += 0.5) g.onImu(at(t), c);
  EXPECT_EQ(c.compared, 4);
  EXPECT_EQ(g.zSign(), -1.0);
}

TEST_F(GravityTest, PlusZWithoutAVerticalSensorTurnsGravityAndReinitializes) {
  c.checks = {zDown()};
  g.onInitialized(at(2.0));
  g.onImu(at(5.0), c);
  EXPECT_EQ(g.zSign(), 1.0);
  EXPECT_EQ(g.gravityG(9.81), Eigen::Vector3d(0.0, 0.0, 9.81));
  EXPECT_EQ(c.turned, 1);
  ASSERT_EQ(c.reinit_at.size(), 1u);
  EXPECT_EQ(c.reinit_at[0], at(5.0));
  EXPECT_EQ(diag.get("anchor_frame_z_down"), 1);
  EXPECT_EQ(diag.get("gravity_flip"), 1);
  for (double t = 5.5; t < 60.0; t += 0.5) g.onImu(at(t), c);
  EXPECT_EQ(c.compared, 1);
  EXPECT_EQ(c.turned, 1);
  EXPECT_EQ(c.reinit_at.size(), 1u);
}

TEST_F(GravityTest, ARefusedReinitializationIsRetriedAfterFlipRetry) {
  ASSERT_DOUBLE_EQ(GravityDirection::kFlipRetry_s, 0.5);
  c.checks = {zDown()};
  c.reinit_answers = {false, false, true};
  g.onInitialized(at(0.0));
  g.onImu(at(3.0), c);
  EXPECT_EQ(c.reinit_at.size(), 1u);
  g.onImu(at(3.3), c);
  g.onImu(at(3.499), c);
  EXPECT_EQ(c.reinit_at.size(), 1u);
  g.onImu(at(3.5), c);
  EXPECT_EQ(c.reinit_at.size(), 2u);
  g.onImu(at(3.9), c);
  EXPECT_EQ(c.reinit_at.size(), 2u);
  g.onImu(at(4.0), c);
  ASSERT_EQ(c.reinit_at.size(), 3u);
  EXPECT_EQ(c.reinit_at[2], at(4.0));
  g.onImu(at(4.5), c);
  g.onImu(at(20.0), c);
  EXPECT_EQ(c.reinit_at.size(), 3u);  // accepted: no more tries
  EXPECT_EQ(diag.get("gravity_flip_refused"), 2);
  EXPECT_EQ(diag.get("gravity_flip"), 1);
  EXPECT_EQ(c.turned, 1);  // the models turned once, not per try
}

TEST_F(GravityTest, PlusZWithAVerticalSensorKeepsTheConvention) {
  c.vertical = true;
  c.checks = {zDown()};
  g.onInitialized(at(0.0));
  g.onImu(at(12.0), c);
  EXPECT_EQ(c.compared, 1);
  EXPECT_EQ(diag.get("anchor_frame_z_down"), 1);
  EXPECT_EQ(g.zSign(), -1.0);
  EXPECT_EQ(g.gravityG(9.81), Eigen::Vector3d(0.0, 0.0, -9.81));
  EXPECT_EQ(c.turned, 0);
  EXPECT_TRUE(c.reinit_at.empty());
}

TEST_F(GravityTest, EarlyCheckAtTheRatioRunsOnceAtTheNextImuSample) {
  c.checks = {undecided(), zUp()};
  g.onInitialized(at(0.0));
  g.noteRangeNisRatio(5.99);
  g.onImu(at(1.0), c);
  EXPECT_EQ(c.compared, 0);
  g.noteRangeNisRatio(6.0);  // at the ratio
  EXPECT_EQ(c.compared, 0);  // not before the next IMU sample
  g.onImu(at(1.01), c);
  EXPECT_EQ(c.compared, 1);
  EXPECT_EQ(diag.get("gravity_early_check"), 1);
  g.noteRangeNisRatio(50.0);  // only once
  g.onImu(at(2.0), c);
  EXPECT_EQ(c.compared, 1);
  // Undecided early: the scheduled comparison still runs.
  g.onImu(at(12.0), c);
  EXPECT_EQ(c.compared, 2);
  EXPECT_EQ(diag.get("gravity_early_check"), 1);
}

TEST_F(GravityTest, ADecisiveEarlyCheckTakesPlusZAndCancelsTheScheduledOne) {
  c.checks = {zDown()};
  g.onInitialized(at(0.0));
  g.noteRangeNisRatio(12.0);
  g.onImu(at(1.5), c);
  EXPECT_EQ(g.zSign(), 1.0);
  EXPECT_EQ(c.turned, 1);
  ASSERT_EQ(c.reinit_at.size(), 1u);
  EXPECT_EQ(c.reinit_at[0], at(1.5));
  for (double t = 2.0; t < 40.0; t += 0.5) g.onImu(at(t), c);
  EXPECT_EQ(c.compared, 1);
}

TEST_F(GravityTest, NoEarlyCheckAfterTheFirstScheduledOneOrWhenOff) {
  g.onInitialized(at(0.0));
  g.onImu(at(12.0), c);  // the first comparison (due at 3), undecided: rescheduled to 18
  ASSERT_EQ(c.compared, 1);
  g.noteRangeNisRatio(50.0);
  g.onImu(at(13.0), c);
  EXPECT_EQ(c.compared, 1);
  EXPECT_EQ(diag.get("gravity_early_check"), 0);

  Diagnostics d2;
  GravityDirection off(kFirst_s, kWindow_s, 0.0, d2);  // ratio 0: off
  FakeContext c2;
  off.onInitialized(at(0.0));
  off.noteRangeNisRatio(1000.0);
  off.onImu(at(1.0), c2);
  EXPECT_EQ(c2.compared, 0);
}

TEST_F(GravityTest, ResetReturnsToTheConventionAndForgetsTheSchedule) {
  c.checks = {zDown()};
  c.reinit_answers = {false};
  g.onInitialized(at(0.0));
  g.onImu(at(12.0), c);
  ASSERT_EQ(g.zSign(), 1.0);
  g.reset();
  EXPECT_EQ(g.zSign(), -1.0);
  g.onImu(at(13.0), c);  // the pending re-initialization is forgotten, nothing is scheduled
  g.onImu(at(30.0), c);
  EXPECT_EQ(c.reinit_at.size(), 1u);
  EXPECT_EQ(c.compared, 1);
  // A new initialization schedules a new first comparison.
  g.onInitialized(at(40.0));
  g.onImu(at(42.9), c);
  EXPECT_EQ(c.compared, 1);
  g.onImu(at(43.0), c);
  EXPECT_EQ(c.compared, 2);
}

TEST(GravityDirection, AReplayTakesTheLiveSign) {
  Diagnostics diag;
  GravityDirection live(kFirst_s, kWindow_s, kEarlyRatio, diag), replay(kFirst_s, kWindow_s, kEarlyRatio, diag);
  FakeContext c;
  c.checks = {zDown()};
  live.onInitialized(at(0.0));
  live.onImu(at(12.0), c);
  ASSERT_EQ(live.zSign(), 1.0);
  EXPECT_EQ(replay.zSign(), -1.0);
  replay.takeSignOf(live);
  EXPECT_EQ(replay.zSign(), 1.0);
  EXPECT_EQ(replay.gravityG(9.7), Eigen::Vector3d(0.0, 0.0, 9.7));
  live.reset();
  replay.takeSignOf(live);
  EXPECT_EQ(replay.gravityG(9.81), Eigen::Vector3d(0.0, 0.0, -9.81));
}

TEST_F(GravityTest, ASignDecidedAtTheFirstAlignmentIsTakenAndNothingIsScheduled) {
  g.onInitialized(at(5.0), +1);  // the first alignment's window fitted +z decisively
  EXPECT_EQ(g.zSign(), 1.0);
  EXPECT_EQ(diag.get("anchor_frame_z_down"), 1);
  g.noteRangeNisRatio(100.0);  // no early check either
  for (double t = 5.0; t < 60.0; t += 0.5) g.onImu(at(t), c);
  EXPECT_EQ(c.compared, 0);
  EXPECT_TRUE(c.reinit_at.empty());  // the pose was fitted with +z already
  EXPECT_EQ(c.turned, 0);            // the node turned its models at the initialization

  GravityDirection minus{kFirst_s, kWindow_s, kEarlyRatio, diag};
  minus.onInitialized(at(5.0), -1);
  for (double t = 5.0; t < 60.0; t += 0.5) minus.onImu(at(t), c);
  EXPECT_EQ(minus.zSign(), -1.0);
  EXPECT_EQ(c.compared, 0);

  GravityDirection undecided_at_init{kFirst_s, kWindow_s, kEarlyRatio, diag};
  undecided_at_init.onInitialized(at(5.0), 0);  // undecided: the comparison first_s later, as always
  undecided_at_init.onImu(at(8.0), c);
  EXPECT_EQ(c.compared, 1);
}
