/// @file test_imu_preintegration.cpp
/// @brief Preintegrated increments against a direct strapdown integration, their bias sensitivities
/// against re-integration, and their covariance against Monte Carlo.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "estimator/core/so3.h"
#include "smoother/imu_preintegration.h"

using namespace meshnav;
using namespace meshnav::smoother;
using estimator::so3::expMap;
using estimator::so3::logMap;

namespace {

/// 200 Hz readings of a body turning and accelerating (smooth, every axis excited).
std::vector<ImuSample> wobblyImu(double duration_s, double rate_hz = 200.0) {
  std::vector<ImuSample> v;
  for (int k = 0; k * (1.0 / rate_hz) <= duration_s + 1e-9; ++k) {
    const double t = k / rate_hz;
    ImuSample s;
    s.t = Timestamp::fromSec(t);
    s.gyro_rad_s = Eigen::Vector3d(0.3 * std::sin(1.1 * t), -0.2 * std::cos(0.7 * t), 0.5 + 0.4 * std::sin(0.3 * t));
    s.acc_m_s2 = Eigen::Vector3d(0.8 * std::cos(0.9 * t), 0.5 * std::sin(1.3 * t), 9.81 + 0.3 * std::sin(2.0 * t));
    v.push_back(s);
  }
  return v;
}

}  // namespace

TEST(ImuPreintegration, EqualsTheStrapdownIntegrationOfTheSameReadings) {
  const auto imu = wobblyImu(1.0);
  const Eigen::Vector3d bg(0.01, -0.02, 0.005), ba(0.1, -0.05, 0.2);
  const Timestamp t0 = Timestamp::fromSec(0.1234), t1 = Timestamp::fromSec(0.8766);
  const ImuIncrement inc = preintegrate(imu, t0, t1, bg, ba, ImuNoiseDensities{});
  // Direct integration in a frame where the body starts at identity, gravity zero, 1 ms steps on
  // the interpolated readings, rotated by each step's mid attitude.
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d v = Eigen::Vector3d::Zero(), p = Eigen::Vector3d::Zero();
  const int n = 7532;
  const double d = (t1 - t0).sec() / n;
  for (int k = 0; k < n; ++k) {
    const Timestamp a = Timestamp::fromSec(t0.sec() + k * d), b = Timestamp::fromSec(t0.sec() + (k + 1) * d);
    const ImuSample sa = interpolateImu(imu, a), sb = interpolateImu(imu, b);
    const Eigen::Vector3d w = 0.5 * (sa.gyro_rad_s + sb.gyro_rad_s) - bg;
    const Eigen::Vector3d f = 0.5 * (sa.acc_m_s2 + sb.acc_m_s2) - ba;
    const Eigen::Vector3d f_mid = R * expMap(0.5 * w * d) * f;
    p += v * d + 0.5 * f_mid * d * d;
    v += f_mid * d;
    R = R * expMap(w * d);
  }
  EXPECT_NEAR(inc.dt_s, (t1 - t0).sec(), 1e-12);
  EXPECT_LT(logMap(Eigen::Matrix3d(inc.dR.transpose() * R)).norm(), 2e-6);
  EXPECT_LT((inc.dv - v).norm(), 2e-5);
  EXPECT_LT((inc.dp - p).norm(), 2e-5);
}

TEST(ImuPreintegration, BiasSensitivitiesPredictAReintegrationToFirstOrder) {
  const auto imu = wobblyImu(2.0);
  const Eigen::Vector3d bg(0.01, -0.02, 0.005), ba(0.1, -0.05, 0.2);
  const Timestamp t0 = Timestamp::fromSec(0.2), t1 = Timestamp::fromSec(1.7);
  const ImuIncrement inc = preintegrate(imu, t0, t1, bg, ba, ImuNoiseDensities{});
  const Eigen::Vector3d dbg(0.002, -0.001, 0.003), dba(0.02, 0.03, -0.01);
  const ImuIncrement g = preintegrate(imu, t0, t1, bg + dbg, ba, ImuNoiseDensities{});
  const ImuIncrement a = preintegrate(imu, t0, t1, bg, ba + dba, ImuNoiseDensities{});
  // Each prediction is right to second order in the perturbation: its error well below the change.
  const Eigen::Vector3d dphi_true = logMap(Eigen::Matrix3d(inc.dR.transpose() * g.dR));
  EXPECT_GT(dphi_true.norm(), 1e-3);
  EXPECT_LT((inc.dR_dbg * dbg - dphi_true).norm(), 0.01 * dphi_true.norm());
  EXPECT_LT((inc.dv + inc.dv_dbg * dbg - g.dv).norm(), 0.01 * (g.dv - inc.dv).norm());
  EXPECT_LT((inc.dp + inc.dp_dbg * dbg - g.dp).norm(), 0.01 * (g.dp - inc.dp).norm());
  EXPECT_LT((inc.dv + inc.dv_dba * dba - a.dv).norm(), 1e-9 + 1e-6 * (a.dv - inc.dv).norm());
  EXPECT_LT((inc.dp + inc.dp_dba * dba - a.dp).norm(), 1e-9 + 1e-6 * (a.dp - inc.dp).norm());
}

TEST(ImuPreintegration, CovarianceMatchesMonteCarloOfWhiteReadingNoise) {
  const auto clean = wobblyImu(1.0, 100.0);
  const ImuNoiseDensities noise{0.05, 0.005};
  const Timestamp t0 = Timestamp::fromSec(0.0), t1 = Timestamp::fromSec(1.0);
  const ImuIncrement ref = preintegrate(clean, t0, t1, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), noise);
  // The model treats each sub-step's mean reading as carrying white noise of variance σ²/δ; draw
  // exactly that: per-step noise added to a piecewise-constant version of the readings.
  std::mt19937 rng(7);
  std::normal_distribution<double> n01;
  const int trials = 4000;
  Eigen::Matrix<double, 9, 9> S = Eigen::Matrix<double, 9, 9>::Zero();
  for (int k = 0; k < trials; ++k) {
    std::vector<ImuSample> noisy;  // two samples per step at its ends with the same reading
    const double d = 0.01;
    for (size_t i = 0; i + 1 < clean.size(); ++i) {
      const double sa = noise.acc / std::sqrt(d), sg = noise.gyro / std::sqrt(d);
      const Eigen::Vector3d ea(sa * n01(rng), sa * n01(rng), sa * n01(rng));
      const Eigen::Vector3d eg(sg * n01(rng), sg * n01(rng), sg * n01(rng));
      ImuSample a = clean[i], b = clean[i + 1];
      const Eigen::Vector3d ma = 0.5 * (a.acc_m_s2 + b.acc_m_s2) + ea, mg = 0.5 * (a.gyro_rad_s + b.gyro_rad_s) + eg;
      a.acc_m_s2 = b.acc_m_s2 = ma;
      a.gyro_rad_s = b.gyro_rad_s = mg;
      b.t = Timestamp::fromUtime(b.t.us - 1);
      noisy.push_back(a);
      noisy.push_back(b);
    }
    noisy.back().t = t1;
    const ImuIncrement x = preintegrate(noisy, t0, t1, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), noise);
    Eigen::Matrix<double, 9, 1> e;
    e << logMap(Eigen::Matrix3d(ref.dR.transpose() * x.dR)), x.dv - ref.dv, x.dp - ref.dp;
    S += e * e.transpose();
  }
  S /= trials;
  for (int i = 0; i < 9; ++i)
    EXPECT_NEAR(S(i, i) / ref.cov(i, i), 1.0, 0.1) << "component " << i;
}

TEST(ImuPreintegration, RefusesASpanTheSamplesDoNotCover) {
  const auto imu = wobblyImu(1.0);
  EXPECT_THROW(preintegrate(imu, Timestamp::fromSec(0.5), Timestamp::fromSec(1.5), Eigen::Vector3d::Zero(),
                            Eigen::Vector3d::Zero(), ImuNoiseDensities{}),
               std::invalid_argument);
  EXPECT_THROW(preintegrate(imu, Timestamp::fromSec(0.5), Timestamp::fromSec(0.4), Eigen::Vector3d::Zero(),
                            Eigen::Vector3d::Zero(), ImuNoiseDensities{}),
               std::invalid_argument);
}
