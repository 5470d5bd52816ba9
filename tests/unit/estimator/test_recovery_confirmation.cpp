/// RecoveryConfirmation (estimator/health/recovery_confirmation.h): a re-initialization counts as
/// recovered once health has been ok for a statistics window with enough tag ranges fitting since.
#include <gtest/gtest.h>

#include "estimator/health/recovery_confirmation.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {
Timestamp at(double s) { return Timestamp::fromSec(s); }
HealthOptions health() {
  HealthOptions o;  // window 4 s, 12 ranges, mean NIS within 4
  return o;
}
/// `n` accepted ranges of NIS `nis`.
void ranges(RecoveryConfirmation& c, int n, double nis) {
  for (int i = 0; i < n; ++i) c.noteRange(true, nis);
}
}  // namespace

TEST(RecoveryConfirmation, NothingPendingWithoutARecovery) {
  RecoveryConfirmation c(health());
  ranges(c, 50, 1.0);
  EXPECT_FALSE(c.noteHealth(at(10.0), Health::Ok));
  EXPECT_FALSE(c.pending());
}

TEST(RecoveryConfirmation, ConfirmedAfterAWindowOfOkWithEnoughFittingRanges) {
  RecoveryConfirmation c(health());
  c.noteRecovery(at(10.0));
  ASSERT_TRUE(c.pending());
  ranges(c, 40, 1.0);
  EXPECT_FALSE(c.noteHealth(at(13.9), Health::Ok)) << "ok for less than the window";
  EXPECT_TRUE(c.noteHealth(at(14.0), Health::Ok));
  EXPECT_FALSE(c.pending());
  EXPECT_FALSE(c.noteHealth(at(15.0), Health::Ok)) << "confirmed once";
}

TEST(RecoveryConfirmation, SparseRangesConfirmLaterNotNever) {
  // One range per 1.2 s (MILUV): a 4 s window never holds 12; the count runs since health became ok.
  RecoveryConfirmation c(health());
  c.noteRecovery(at(0.0));
  double t = 0.0;
  int n = 0;
  while (!c.noteHealth(at(t), Health::Ok)) {
    t += 1.2;
    c.noteRange(true, 0.8);
    ASSERT_LT(++n, 20);
  }
  EXPECT_EQ(c.rangesFitted(), 12);
  EXPECT_NEAR(t, 14.4, 1e-9);
}

TEST(RecoveryConfirmation, RangesThatDoNotFitOrGatedOnesDoNotConfirm) {
  RecoveryConfirmation c(health());
  c.noteRecovery(at(0.0));
  ranges(c, 30, 6.0);  // mean NIS 6 > 4: the new pose does not fit
  for (int i = 0; i < 30; ++i) c.noteRange(false, 100.0);  // gated ones do not count
  EXPECT_FALSE(c.noteHealth(at(10.0), Health::Ok));
  EXPECT_EQ(c.rangesFitted(), 30);
  EXPECT_NEAR(c.meanNis(), 6.0, 1e-12);
  EXPECT_TRUE(c.pending());
}

TEST(RecoveryConfirmation, AnInterruptionRestartsTheCount) {
  RecoveryConfirmation c(health());
  c.noteRecovery(at(0.0));
  ranges(c, 20, 1.0);
  EXPECT_FALSE(c.noteHealth(at(3.0), Health::Degraded));
  ranges(c, 20, 1.0);  // while not ok: not counted
  EXPECT_EQ(c.rangesFitted(), 0);
  EXPECT_FALSE(c.noteHealth(at(5.0), Health::Ok));  // ok again from 5 s
  ranges(c, 12, 1.0);
  EXPECT_FALSE(c.noteHealth(at(8.9), Health::Ok));
  EXPECT_NEAR(c.okFor(at(8.9)), 3.9, 1e-9);
  EXPECT_TRUE(c.noteHealth(at(9.0), Health::Ok));
}

TEST(RecoveryConfirmation, ANewRecoveryReplacesThePendingOne) {
  RecoveryConfirmation c(health());
  c.noteRecovery(at(0.0));
  ranges(c, 30, 1.0);
  c.noteRecovery(at(3.0));
  EXPECT_EQ(c.rangesFitted(), 0);
  ranges(c, 30, 1.0);
  EXPECT_FALSE(c.noteHealth(at(6.0), Health::Ok));
  EXPECT_TRUE(c.noteHealth(at(7.0), Health::Ok));
  c.noteRecovery(at(20.0));
  c.reset();
  EXPECT_FALSE(c.pending());
}
