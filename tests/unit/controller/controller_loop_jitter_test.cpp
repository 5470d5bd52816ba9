// LoopJitter (controller/loop_jitter.h): |wall interval − data interval| between consecutive updates.
#include <gtest/gtest.h>

#include "controller/loop_jitter.h"

using meshnav::controller::LoopJitter;

TEST(LoopJitter, ZeroForALoopOnTheDataClock) {
  LoopJitter j;
  for (int k = 0; k < 100; ++k) j.add(5000 * k, 1'000'000 + 5000 * k);
  EXPECT_EQ(j.count(), 99u);
  EXPECT_DOUBLE_EQ(j.quantileMs(0.99), 0.0);
  EXPECT_DOUBLE_EQ(j.maxMs(), 0.0);
}

TEST(LoopJitter, LateUpdatesShowInTheUpperQuantiles) {
  LoopJitter j;
  int64_t wall = 0;
  for (int k = 0; k < 200; ++k) {
    // Every 50th update 3 ms late (and the next one on time again: two intervals off by 3 ms).
    const int64_t late = (k % 50 == 49) ? 3000 : 0;
    j.add(5000 * k, wall + 5000 * k + late);
  }
  EXPECT_EQ(j.count(), 199u);
  EXPECT_DOUBLE_EQ(j.quantileMs(0.5), 0.0);
  EXPECT_DOUBLE_EQ(j.maxMs(), 3.0);
  EXPECT_DOUBLE_EQ(j.quantileMs(0.99), 3.0);  // 7 of 199 intervals are 3 ms off: above the 1 %
}

TEST(LoopJitter, IgnoresDataTimesThatDoNotAdvanceAndReportsNothingWithoutIntervals) {
  LoopJitter j;
  EXPECT_EQ(j.quantileMs(0.99), -1.0);
  j.add(1000, 0);
  j.add(1000, 50'000);  // the same data time again
  EXPECT_EQ(j.count(), 0u);
  EXPECT_EQ(j.maxMs(), -1.0);
  j.add(6000, 55'000);  // 5 ms of data after the counted update at wall 0: 55 ms of wall
  EXPECT_EQ(j.count(), 1u);
  EXPECT_DOUBLE_EQ(j.maxMs(), 50.0);
}
