/// restMeasurement / restGate (estimator/zupt/rest_measurement.h): the σ's of a rest update from a
/// flight state and from IMU stillness, the ω row on the mean reading with its noise, the gate.
#include <gtest/gtest.h>

#include <cmath>

#include "common/chi_square.h"
#include "estimator/zupt/rest_measurement.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

ImuSample reading() {
  ImuSample s;
  s.t = Timestamp::fromSec(3.0);
  s.acc_m_s2 = {0.1, 0.0, 9.8};
  s.gyro_rad_s = {0.03, 0.0, 0.0};
  return s;
}

}  // namespace

TEST(RestMeasurement, AFlightStateIsTighterThanStillness) {
  const ZuptOptions o;
  const RestRateMean none;
  const ZuptMeasurement landed = restMeasurement(reading(), none, o, 0.002, 1.0, true);
  const ZuptMeasurement still = restMeasurement(reading(), none, o, 0.002, 1.0, false);
  EXPECT_DOUBLE_EQ(landed.sigma_vel_m_s, o.sigma_vel_m_s);
  EXPECT_DOUBLE_EQ(still.sigma_vel_m_s, o.stillness_sigma_vel_m_s);
  EXPECT_DOUBLE_EQ(landed.sigma_acc_m_s2, o.sigma_acc_m_s2);
  EXPECT_TRUE(landed.acc_m_s2.isApprox(reading().acc_m_s2));
  // Before any interval: the latest reading with the loosest σ.
  EXPECT_TRUE(landed.gyro_rad_s.isApprox(reading().gyro_rad_s));
  EXPECT_DOUBLE_EQ(landed.sigma_gyro_rad_s, std::max(o.sigma_gyro_rad_s, o.stillness_sigma_gyro_rad_s));
  EXPECT_DOUBLE_EQ(restGate(7, o, true), 0.0);
  EXPECT_DOUBLE_EQ(restGate(7, o, false), chi2Quantile(7, o.stillness_gate_probability));
}

TEST(RestMeasurement, TheRateRowUsesTheMeanReadingAndItsNoise) {
  const ZuptOptions o;
  RestRateMean rest;
  for (int k = 0; k < 100; ++k) rest.add(Eigen::Vector3d(0.001, -0.002, 0.0), 0.01, 0.1);  // 1 s
  const double lambda = 4.0, density = 0.002;
  const ZuptMeasurement z = restMeasurement(reading(), rest, o, density, lambda, true);
  EXPECT_TRUE(z.gyro_rad_s.isApprox(Eigen::Vector3d(0.001, -0.002, 0.0)));
  EXPECT_NEAR(z.sigma_gyro_rad_s, std::hypot(o.sigma_gyro_rad_s, rest.sigma(density * std::sqrt(lambda))), 1e-15);
  EXPECT_NEAR(rest.sigma(density * 2.0), density * 2.0 / std::sqrt(1.0), 1e-12) << "σ_g √λ / √T over T = 1 s";
  const ZuptMeasurement still = restMeasurement(reading(), rest, o, density, lambda, false);
  EXPECT_GT(still.sigma_gyro_rad_s, z.sigma_gyro_rad_s);
}
