/// StillnessDetector: rest from IMU noise statistics; motion and shaking are not rest.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "estimator/zupt/stillness_detector.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {
constexpr double kAccNd = 0.002, kGyroNd = 0.0002, kRate = 200.0;

/// 1 s of samples at 200 Hz with white noise of the densities plus `extra(t)` on x.
template <typename F>
bool run(F extra_acc, double gyro_bias = 0.0) {
  StillnessDetector d({}, kAccNd, kGyroNd, 9.81);
  std::mt19937_64 rng(1);
  std::normal_distribution<double> n(0.0, 1.0);
  const double sa = kAccNd * std::sqrt(kRate), sg = kGyroNd * std::sqrt(kRate);
  bool still = false;
  for (int k = 0; k < 200; ++k) {
    ImuSample s;
    s.t = Timestamp::fromSec(k / kRate);
    s.acc_m_s2 = Eigen::Vector3d(sa * n(rng) + extra_acc(k / kRate), sa * n(rng), 9.81 + sa * n(rng));
    s.gyro_rad_s = Eigen::Vector3d(sg * n(rng) + gyro_bias, sg * n(rng), sg * n(rng));
    still = d.add(s);
  }
  return still;
}
}  // namespace

TEST(StillnessDetector, NoiseOnlyIsStill) { EXPECT_TRUE(run([](double) { return 0.0; }, 0.003)); }

TEST(StillnessDetector, GaitLikeAccelerationIsNotStill) {
  EXPECT_FALSE(run([](double t) { return 1.0 * std::sin(2 * M_PI * 1.8 * t); }));
}

TEST(StillnessDetector, VibrationIsNotStill) {
  EXPECT_FALSE(run([](double t) { return 0.5 * std::sin(2 * M_PI * 40.0 * t); }));
}

TEST(StillnessDetector, NeedsAFullWindow) {
  StillnessDetector d({}, kAccNd, kGyroNd, 9.81);
  ImuSample s;
  s.acc_m_s2 = Eigen::Vector3d(0, 0, 9.81);
  for (int k = 0; k < 20; ++k) {
    s.t = Timestamp::fromSec(k / kRate);
    EXPECT_FALSE(d.add(s));
  }
}

TEST(StillnessDetector, ASmoothTurnIsNotStill) {
  // Constant yaw rate of 0.07 rad/s: no spread at all, but the body turns.
  EXPECT_FALSE(run([](double) { return 0.0; }, 0.07));
}
