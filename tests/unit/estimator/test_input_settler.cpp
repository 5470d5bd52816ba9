/// InputSettler (estimator/node/input_settler.h): inputs released in the canonical order once every
/// stream has passed them, or once they are init.settle_max_s behind the newest input; late ones refused.
#include <gtest/gtest.h>

#include <vector>

#include "estimator/node/input_settler.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

Timestamp at(double s) { return Timestamp::fromSec(s); }
ImuSample imu(double t) { return {at(t), Eigen::Vector3d(0, 0, 9.81), Eigen::Vector3d::Zero()}; }
RangeSample range(double t, SensorId tag = 100, SensorId anchor = 101) {
  RangeSample r;
  r.t = at(t);
  r.id_initiator = tag;
  r.id_responder = anchor;
  r.range_m = r.range_corr_m = 3.0;
  return r;
}
std::vector<double> times(const std::vector<EstimatorInput>& v) {
  std::vector<double> t;
  for (const auto& in : v) t.push_back(static_cast<double>(inputTime(in).us) / 1e6);  // exact for whole µs
  return t;
}

}  // namespace

TEST(InputSettler, ReleasesAnInputOnlyOnceEveryStreamHasPassedIt) {
  InputSettler s(2.0);
  EXPECT_FALSE(s.watermark());
  ASSERT_TRUE(s.add(imu(0.00)));
  ASSERT_TRUE(s.add(imu(0.01)));
  ASSERT_TRUE(s.add(imu(0.02)));
  // No range yet: the ranges' stream, which every UWB-aided INS has, holds W until it comes.
  EXPECT_FALSE(s.watermark());
  EXPECT_TRUE(s.takeSettled().empty());
  // A range stamped 0.015 s arrives after the 0.02 s sample; W = 0.015.
  ASSERT_TRUE(s.add(range(0.015)));
  ASSERT_TRUE(s.add(imu(0.03)));
  EXPECT_EQ(s.watermark()->us, 15000);
  EXPECT_EQ(times(s.takeSettled()), (std::vector<double>{0.00, 0.01}));  // 0.02 waits: a range before it may come
  ASSERT_TRUE(s.add(range(0.025)));
  EXPECT_EQ(times(s.takeSettled()), (std::vector<double>{0.015, 0.02}));
  EXPECT_EQ(s.size(), 2u);  // 0.025 and 0.03
}

TEST(InputSettler, WithoutTagsTheImuStreamAloneSetsTheWatermark) {
  InputSettler s(2.0, /*expect_ranges=*/false);
  ASSERT_TRUE(s.add(imu(0.00)));
  ASSERT_TRUE(s.add(imu(0.01)));
  EXPECT_EQ(times(s.takeSettled()), (std::vector<double>{0.00}));
}

TEST(InputSettler, ReleasesInTheCanonicalOrderWhateverTheArrivalOrder) {
  InputSettler s(2.0);
  // Two ranges of one instant arrive in the other order than the canonical one (ids), the IMU sample
  // of that instant after them.
  ASSERT_TRUE(s.add(range(1.0, 100, 103)));
  ASSERT_TRUE(s.add(range(1.0, 100, 101)));
  ASSERT_TRUE(s.add(imu(1.0)));
  ASSERT_TRUE(s.add(imu(1.1)));
  ASSERT_TRUE(s.add(range(1.2)));
  const auto out = s.takeSettled();
  ASSERT_EQ(out.size(), 3u);  // those of 1.0 s; 1.1 waits for the ranges' stream to pass it
  for (size_t i = 1; i < out.size(); ++i) EXPECT_LT(inputOrder(out[i - 1]), inputOrder(out[i]));
  EXPECT_TRUE(std::holds_alternative<ImuSample>(out[0]));  // the IMU's rank comes first at equal time
}

TEST(InputSettler, AStoppedStreamHoldsTheOthersAtMostTheSettleTime) {
  InputSettler s(0.5);
  ASSERT_TRUE(s.add(range(0.0)));
  for (int i = 0; i <= 100; ++i) ASSERT_TRUE(s.add(imu(0.01 * i)));  // the ranges stopped at 0
  const auto out = s.takeSettled();
  // Released: the range at 0 and the IMU samples at least 0.5 s older than the newest (1.0 s).
  ASSERT_FALSE(out.empty());
  EXPECT_NEAR(inputTime(out.back()).sec(), 0.5, 1e-9);
  // With 0 nothing waits: every input goes at once, as without a settler.
  InputSettler none(0.0);
  ASSERT_TRUE(none.add(imu(0.0)));
  EXPECT_EQ(none.takeSettled().size(), 1u);
}

TEST(InputSettler, RefusesAnInputOlderThanOneReleasedAndTakeAllEmptiesIt) {
  InputSettler s(2.0);
  ASSERT_TRUE(s.add(imu(0.0)));
  ASSERT_TRUE(s.add(range(0.1)));
  ASSERT_TRUE(s.add(imu(0.2)));
  ASSERT_EQ(times(s.takeSettled()), (std::vector<double>{0.0}));
  ASSERT_TRUE(s.add(range(0.3)));
  ASSERT_EQ(times(s.takeSettled()), (std::vector<double>{0.1}));  // 0.2 waits for the IMU to pass it
  EXPECT_FALSE(s.add(range(0.05)));  // out of its stream's order, after 0.1 was released
  EXPECT_TRUE(s.add(range(0.25)));
  EXPECT_EQ(times(s.takeAll()), (std::vector<double>{0.2, 0.25, 0.3}));
  EXPECT_EQ(s.size(), 0u);
  s.clear();
  EXPECT_TRUE(s.add(imu(0.0)));  // a reset forgets what was released
}
