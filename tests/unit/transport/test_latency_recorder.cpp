/// @file test_latency_recorder.cpp
/// @brief LatencyRecorder (transport/latency_recorder.h): IMU → POSE and RANGE → POSE from receive
/// times, on hand-made streams with known answers.
#include <gtest/gtest.h>

#include "transport/latency_recorder.h"

using meshnav::transport::LatencyRecorder;
using meshnav::transport::LatencyStats;

TEST(LatencyStats, MedianP99AndMaxOfASample) {
  std::vector<double> s;
  for (int i = 1; i <= 100; ++i) s.push_back(i);
  const LatencyStats st = LatencyStats::of(s);
  EXPECT_EQ(st.n, 100u);
  EXPECT_DOUBLE_EQ(st.median_us, 51.0);  // the rounded middle of 1..100
  EXPECT_DOUBLE_EQ(st.p99_us, 99.0);
  EXPECT_DOUBLE_EQ(st.max_us, 100.0);
  EXPECT_EQ(LatencyStats::of({}).n, 0u);
}

// IMU every 5 ms (received at its data time + 100 µs), POSE 30 µs after each IMU; a RANGE at
// 2 ms after each IMU (received 100 µs after its time): its POSE is the next IMU's, which is made
// once that IMU is in, so RANGE → POSE is the 30 µs of processing, not the 3 ms wait.
TEST(LatencyRecorder, ImuAndRangeToPoseWithoutTheWaitForTheNextImuSample) {
  LatencyRecorder r;
  for (int k = 0; k < 100; ++k) {
    const int64_t t = 1'000'000 + k * 5'000;
    r.onImu(t, t + 100);
    r.onPose(t, t + 130);
    r.onRange(t + 2'000, t + 2'100);
  }
  const LatencyStats imu = r.imuToPose();
  EXPECT_EQ(imu.n, 100u);
  EXPECT_DOUBLE_EQ(imu.median_us, 30.0);
  EXPECT_DOUBLE_EQ(imu.max_us, 30.0);
  const LatencyStats range = r.rangeToPose();
  EXPECT_EQ(range.n, 99u);  // the last RANGE has no later POSE: it came after the last one
  EXPECT_EQ(r.rangesUnanswered(), 0u);
  EXPECT_EQ(r.rangesAfterLastPose(), 1u);
  EXPECT_DOUBLE_EQ(range.median_us, 30.0);
  EXPECT_EQ(r.counts().at("IMU"), 100);
  EXPECT_NEAR(r.ratesHz().at("IMU"), 100.0 / 0.497, 0.5);  // over 100 µs … 497 ms + 130 µs of receive times
}

// A RANGE that arrives after the POSE of its time went out (late: the estimator re-runs it) is
// answered by the first POSE that leaves after it, never by one that left before it came.
TEST(LatencyRecorder, ALateRangeIsAnsweredByTheFirstPoseAfterItCame) {
  LatencyRecorder r;
  r.onImu(5'000, 5'000);  // initialized before the range's instant
  r.onPose(5'000, 5'050);
  r.onImu(10'000, 10'000);
  r.onPose(10'000, 10'050);
  r.onRange(9'000, 11'000);  // stamped before IMU 10 ms, received after its POSE
  r.onImu(15'000, 15'000);
  r.onPose(15'000, 15'040);
  const LatencyStats range = r.rangeToPose();
  ASSERT_EQ(range.n, 1u);
  EXPECT_DOUBLE_EQ(range.median_us, 40.0);  // POSE 15 ms at 15 040 − max(11 000, 15 000)
}

// Lost messages: IMU samples before the first POSE (the estimator initializing) are not lost; one
// between the first and the last POSE without its POSE is; a POSE whose IMU sample the probe
// never got counts that IMU as lost on the way to the probe.
TEST(LatencyRecorder, CountsImuSamplesWithoutPoseAndPosesWithoutImu) {
  LatencyRecorder r;
  for (int k = 0; k < 10; ++k) {
    const int64_t t = k * 5'000;
    if (k != 7) r.onImu(t, t + 100);  // IMU 7 lost on the way to the probe
    if (k >= 3 && k != 5) r.onPose(t, t + 130);  // none before 3 (initializing), POSE 5 lost
  }
  EXPECT_EQ(r.imusUnanswered(), 1u);   // IMU 5
  EXPECT_EQ(r.posesWithoutImu(), 1u);  // POSE 7
  EXPECT_EQ(r.imuToPose().n, 5u);      // POSE 3, 4, 6, 8, 9
}

// Ranges the estimator does not fuse (anchor mesh, another vehicle's tag) are kept apart: RANGE →
// POSE is over the fused ones only, and every range counts when it is unanswered.
TEST(LatencyRecorder, RangesNotFusedAreMeasuredApart) {
  LatencyRecorder r;
  r.onImu(8'000, 8'000);
  r.onPose(8'000, 8'100);
  r.onImu(10'000, 10'000);
  r.onRange(9'000, 9'500, true);
  r.onRange(9'100, 9'600, false);
  r.onPose(10'000, 10'300);
  r.onRange(11'000, 11'000, false);  // after the last POSE
  EXPECT_EQ(r.fusedRanges(), 1u);
  EXPECT_EQ(r.rangeToPose().n, 1u);
  EXPECT_DOUBLE_EQ(r.rangeToPose().median_us, 300.0);
  EXPECT_EQ(r.otherRangeToPose().n, 1u);
  EXPECT_EQ(r.rangesUnanswered(), 0u);
  EXPECT_EQ(r.rangesAfterLastPose(), 1u);
  EXPECT_EQ(r.counts().at("RANGE"), 3);
}

// Ranges stamped before the first POSE (the estimator initializing) are answered by the
// initialization, not by a range update: counted apart, in neither RANGE → POSE nor unanswered.
TEST(LatencyRecorder, RangesBeforeTheFirstPoseAreTheInitializations) {
  LatencyRecorder r;
  r.onRange(1'000, 1'100);            // before the estimator initialized at 5 ms
  r.onRange(2'000, 2'100, false);
  r.onImu(5'000, 5'000);
  r.onPose(5'000, 35'000);            // the initialization took 30 ms
  r.onRange(6'000, 36'000);
  r.onImu(10'000, 40'000);
  r.onPose(10'000, 40'200);
  EXPECT_EQ(r.rangesBeforeFirstPose(), 2u);
  EXPECT_EQ(r.rangeToPose().n, 1u);
  EXPECT_DOUBLE_EQ(r.rangeToPose().max_us, 200.0);
  EXPECT_EQ(r.rangesUnanswered(), 0u);
  EXPECT_TRUE(r.rangeToPoseOverByWindow(2'000.0, 10.0).empty());
}

// A RANGE whose POSE was lost (received before the last POSE, none after it at or past its time)
// is unanswered; one received after the last POSE is not (nothing could answer it).
TEST(LatencyRecorder, ARangeBeforeTheLastPoseWithoutAnswerIsUnanswered) {
  LatencyRecorder r;
  r.onImu(10'000, 10'000);
  r.onPose(10'000, 10'100);
  r.onRange(12'000, 12'050);  // its POSE (of a later IMU sample) never came
  r.onPose(5'000, 13'000);    // a late re-published older POSE: the last one received
  r.onRange(13'000, 13'500);  // after the last POSE
  EXPECT_EQ(r.rangesUnanswered(), 1u);
  EXPECT_EQ(r.rangesAfterLastPose(), 1u);
}

// Where the tail is: the ranges answered later than a bound, per window of data time.
TEST(LatencyRecorder, TheTailIsCountedPerWindowOfDataTime) {
  LatencyRecorder r;
  for (int k = 0; k < 400; ++k) {  // 20 s at 20 Hz; from 12 s on every POSE leaves 5 ms after its IMU
    const int64_t t = 1'000'000 + k * 50'000;
    const int64_t delay = k >= 240 ? 5'000 : 30;
    r.onImu(t, t + 100);
    r.onPose(t, t + 100 + delay);
    r.onRange(t, t + 50);
  }
  const auto over = r.rangeToPoseOverByWindow(2'000.0, 10.0);
  ASSERT_EQ(over.size(), 1u);
  EXPECT_EQ(over.begin()->first, 10);  // 12-20 s of data time
  EXPECT_EQ(over.begin()->second, 160u);
  EXPECT_TRUE(r.rangeToPoseOverByWindow(10'000.0, 10.0).empty());
  EXPECT_EQ(r.rangeToPoseOverByWindow(10.0, 5.0).size(), 4u);  // every answer > 10 µs: 0, 5, 10, 15 s
  // Each answered range with its latency (the probe's --samples): POSE − max(RANGE, IMU) = 30 µs, then 5 ms.
  const auto samples = r.rangeToPoseSamples();
  ASSERT_EQ(samples.size(), 400u);
  EXPECT_EQ(samples.front().utime, 1'000'000);
  EXPECT_EQ(samples.front().pose_utime, 1'000'000);
  EXPECT_FALSE(samples.front().range_last);  // the RANGE (at +50 µs) came before its IMU sample (+100)
  EXPECT_DOUBLE_EQ(samples.front().latency_us, 30.0);
  EXPECT_DOUBLE_EQ(samples.back().latency_us, 5'000.0);
}
