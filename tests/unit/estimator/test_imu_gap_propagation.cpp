/// ImuPropagation (estimator/imu/imu_propagation.h) on a real filter: across an IMU gap the
/// readings of `imu.gap_readings` ("held", "still", "mean") with the gap's white noise; the noise
/// scale λ's extra noise between samples; the low-passed reading and its restart after a gap.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "estimator/core/so3.h"
#include "estimator/filter/strategy_factory.h"
#include "estimator/imu/imu_propagation.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

Timestamp at(double s) { return Timestamp::fromSec(s); }
constexpr double kG = 9.81;
const Eigen::Vector3d kGravityG(0.0, 0.0, -kG);

/// A filter at rest at the origin, level, with a small covariance, at t = 0.
std::unique_ptr<FusionStrategy> levelFilter() {
  auto f = makeStrategy(EstimatorOptions{});
  f->reset(1, ImuState{}, ImuMatrix::Identity() * 1e-4, at(0.0));
  return f;
}

/// A reading of a level body accelerating by `a_G` and turning at `w` [rad/s] about each axis.
ImuSample sample(double t, const Eigen::Vector3d& a_G, const Eigen::Vector3d& w) {
  ImuSample s;
  s.t = at(t);
  s.acc_m_s2 = a_G - kGravityG;  // specific force of a level body
  s.gyro_rad_s = w;
  return s;
}

struct Gap {
  ImuNoiseOptions imu;
  std::unique_ptr<FusionStrategy> f = levelFilter();
  std::optional<ImuSample> last, prev;
  std::optional<ImuReading> mean;

  /// The filter's last IMU sample at t = 0 is `s0`; the next comes at `t1` (a gap when > max_dt_s).
  void run(const std::string& mode, const ImuSample& s0, double t1, double lambda = 1.0) {
    imu.gap_readings = mode;
    last = s0;
    ImuPropagation p(imu);
    p.toSample(*f, sample(t1, s0.acc_m_s2 + kGravityG, s0.gyro_rad_s), {last, prev, mean, kGravityG, lambda});
  }
};

}  // namespace

TEST(ImuGapPropagation, HeldRepeatsTheLastReadingForTheWholeGap) {
  Gap g;
  g.run("held", sample(0.0, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.5}), 2.0);
  // 2 s of a held 0.5 rad/s: 1 rad of yaw.
  EXPECT_NEAR(so3::yawOf(g.f->state().imu.q_ItoG), 1.0, 1e-6);
}

TEST(ImuGapPropagation, StillKeepsVelocityAndAttitude) {
  Gap g;
  g.f->reset(1, [] { ImuState x; x.v_IinG = {1.0, 0.0, 0.0}; return x; }(), ImuMatrix::Identity() * 1e-4, at(0.0));
  g.run("still", sample(0.0, {2.0, 0.0, 0.0}, {0.0, 0.0, 0.5}), 2.0);
  const ImuState& x = g.f->state().imu;
  // The first max_dt_s on the reading (a = 2 m/s² along x, turning), then a = 0 in G, ω = 0.
  const double dt0 = g.imu.max_dt_s;
  EXPECT_NEAR(x.v_IinG.x(), 1.0 + 2.0 * dt0, 1e-3);
  EXPECT_NEAR(x.v_IinG.z(), 0.0, 1e-6);
  EXPECT_NEAR(so3::yawOf(x.q_ItoG), 0.5 * dt0, 1e-3);
}

TEST(ImuGapPropagation, MeanContinuesTheLowPassedAccelerationWithoutTilting) {
  Gap g;
  g.mean = ImuReading{Eigen::Vector3d(0.5, 0.0, 0.0), Eigen::Vector3d(0.4, 0.0, 0.0)};  // in G
  g.run("mean", sample(0.0, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}), 3.0);
  const ImuState& x = g.f->state().imu;
  const double gap_s = 3.0 - g.imu.max_dt_s;
  EXPECT_NEAR(x.v_IinG.x(), 0.5 * gap_s, 1e-6);
  EXPECT_NEAR(x.v_IinG.z(), 0.0, 1e-6);
  // The low-passed roll rate (0.4 rad/s) is not integrated: the body stays level.
  const Eigen::Vector3d z_body = x.q_ItoG * Eigen::Vector3d::UnitZ();
  EXPECT_NEAR(z_body.z(), 1.0, 1e-9);
}

TEST(ImuGapPropagation, MeanContinuesTheTurnRateAboutTheVertical) {
  Gap g;
  g.mean = ImuReading{Eigen::Vector3d::Zero(), Eigen::Vector3d(0.0, 0.0, 0.2)};
  g.run("mean", sample(0.0, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}), 3.0);
  EXPECT_NEAR(so3::yawOf(g.f->state().imu.q_ItoG), 0.2 * (3.0 - g.imu.max_dt_s), 1e-6);
}

TEST(ImuGapPropagation, TheGapAddsItsWhiteNoiseToTheVelocity) {
  Gap shortStep, gap;
  shortStep.run("mean", sample(0.0, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}), 0.05);
  gap.run("mean", sample(0.0, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}), 2.0);
  const double var_v_short = shortStep.f->covariance(1, 1)(ImuErr::kV, ImuErr::kV);
  const double var_v_gap = gap.f->covariance(1, 1)(ImuErr::kV, ImuErr::kV);
  // At least σ_gap² × (gap beyond max_dt) more than a regular step.
  const double expected = std::pow(gap.imu.gap_sigma_acc_m_s2, 2) * (2.0 - gap.imu.max_dt_s);
  EXPECT_GT(var_v_gap - var_v_short, expected);
  EXPECT_LT(var_v_gap - var_v_short, expected * 1.2);
}

TEST(ImuGapPropagation, TheNoiseScaleAddsLambdaMinusOneOfTheDensities) {
  Gap one, two;
  one.run("mean", sample(0.0, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}), 0.05, 1.0);
  two.run("mean", sample(0.0, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}), 0.05, 2.0);
  const double dv = two.f->covariance(1, 1)(ImuErr::kV, ImuErr::kV) - one.f->covariance(1, 1)(ImuErr::kV, ImuErr::kV);
  EXPECT_NEAR(dv, std::pow(one.imu.acc_noise_density, 2) * 0.05, 1e-12);
}

TEST(ImuGapPropagation, TheMeanReadingIsLowPassedAndRestartsAfterAGap) {
  ImuNoiseOptions o;
  ImuPropagation p(o);
  std::optional<ImuReading> mean;
  const ImuState level;
  const ImuSample s0 = sample(0.0, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0});
  p.updateMean(mean, level, s0, std::nullopt, kGravityG);
  ASSERT_TRUE(mean);
  EXPECT_NEAR(mean->acc_m_s2.norm(), 0.0, 1e-9);
  // A step of 1 m/s² along x for dt = 0.01 s moves the mean by 1 − exp(−dt/τ) of it.
  const ImuSample s1 = sample(0.01, {1.0, 0.0, 0.0}, {0.0, 0.0, 0.0});
  p.updateMean(mean, level, s1, s0, kGravityG);
  EXPECT_NEAR(mean->acc_m_s2.x(), 1.0 - std::exp(-0.01 / o.gap_mean_time_constant_s), 1e-9);
  // After a gap longer than max_dt_s the mean restarts at the new reading.
  const ImuSample s2 = sample(1.0, {3.0, 0.0, 0.0}, {0.0, 0.0, 0.0});
  p.updateMean(mean, level, s2, s1, kGravityG);
  EXPECT_NEAR(mean->acc_m_s2.x(), 3.0, 1e-9);
}
