/// RestRateMean (the ZUPT's ω row) and what it buys the node: the gyro bias of a landed phase
/// known to its noise bound σ_ω/√T instead of the fixed σ of single readings.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "estimator/zupt/rest_rate_mean.h"
#include "node_test_helpers.h"

using namespace meshnav;
using namespace meshnav::estimator;

TEST(RestRateMean, WeightsReadingsByTheirIntervalsAndClampsGaps) {
  RestRateMean m;
  EXPECT_EQ(m.span(), 0.0);
  EXPECT_TRUE(std::isinf(m.sigma(2e-4)));
  m.add(Eigen::Vector3d(1.0, 0.0, 0.0), 0.005, 0.1);
  m.add(Eigen::Vector3d(4.0, 0.0, -2.0), 0.015, 0.1);
  EXPECT_DOUBLE_EQ(m.span(), 0.02);
  EXPECT_TRUE(m.mean().isApprox(Eigen::Vector3d(3.25, 0.0, -1.5)));
  // An IMU gap counts as max_dt_s only; a reading from the past adds nothing.
  m.add(Eigen::Vector3d(0.0, 0.0, 0.0), 5.0, 0.1);
  m.add(Eigen::Vector3d(9.0, 9.0, 9.0), -0.01, 0.1);
  EXPECT_DOUBLE_EQ(m.span(), 0.12);
  EXPECT_DOUBLE_EQ(m.sigma(2e-4), 2e-4 / std::sqrt(0.12));
  m.reset();
  EXPECT_EQ(m.span(), 0.0);
  EXPECT_EQ(m.mean(), Eigen::Vector3d::Zero());
}

TEST(RestRateMean, SigmaIsTheSpreadOfTheMeanOfWhiteNoise) {
  // 0.1 s of 200 Hz readings with density σ_ω: the mean's spread over many intervals is σ_ω/√0.1.
  constexpr double kNd = 2e-4, kRate = 200.0;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0.0, kNd * std::sqrt(kRate));
  double sq = 0.0;
  const int trials = 4000;
  RestRateMean m;
  for (int k = 0; k < trials; ++k) {
    m.reset();
    for (int i = 0; i < 20; ++i) m.add(Eigen::Vector3d(n(rng), 0.0, 0.0), 1.0 / kRate, 0.1);
    sq += m.mean().x() * m.mean().x();
  }
  EXPECT_NEAR(std::sqrt(sq / trials) / m.sigma(kNd), 1.0, 0.05);
}

TEST(RestRateMean, LandedPhaseFixesTheGyroBiasToItsNoiseBound) {
  // 5 s landed (initialized after init.duration_s = 1 s), flight-controller gyro: the z gyro bias,
  // which the flight can hardly correct (yaw is weakly observable), leaves the pad known to
  // ≈ σ_ω/√4 s = 1e-4 rad/s plus the rest allowance (zupt.sigma_gyro_rad_s 1e-3 per 0.1 s,
  // /√40). Single readings with σ 0.01 left it at ≈ 0.0016 rad/s (the paper table's seed 8 then
  // drifted 7° in yaw).
  synthetic::SyntheticOptions o;
  o.duration_s = 5.5;
  o.landed_s = 5.0;
  o.noise = true;
  o.seed = 7;
  o.gyro_noise_density = 2e-4;
  o.bias_gyro_rad_s = Eigen::Vector3d(0.002, -0.003, 0.0025);
  const Dataset ds = synthetic::makeSyntheticDataset(o);
  EstimatorOptions opts = test::testOptions();
  opts.imu.gyro_bias_rw = 2e-5;  // the flight-controller grade (the synthetic setup states none)
  EstimatorNode node(opts, ds.setup);
  for (const auto& in : mergeInTimeOrder(ds)) {
    if (inputTime(in).sec() > o.landed_s) break;
    node.onInput(in);
  }
  ASSERT_TRUE(node.initialized());
  const Eigen::Matrix3d P_bg =
      node.filter()->covariance(ds.setup.imu_id, ds.setup.imu_id).block<3, 3>(ImuErr::kBg, ImuErr::kBg);
  const double sigma_z = std::sqrt(P_bg(2, 2));
  const double bound = std::hypot(2e-4 / std::sqrt(4.0), 1e-3 / std::sqrt(40.0));
  EXPECT_LT(sigma_z, 1.3 * bound);
  EXPECT_GT(sigma_z, 0.8 * bound);
  const double err_z = node.filter()->state().imu.bias_gyro_rad_s.z() - o.bias_gyro_rad_s.z();
  EXPECT_LT(std::abs(err_z), 3.0 * sigma_z);
  EXPECT_LT((node.filter()->state().imu.bias_gyro_rad_s - o.bias_gyro_rad_s).norm(), 5e-4);
}
