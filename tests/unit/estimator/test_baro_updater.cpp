/// BaroUpdater (estimator/baro/baro_updater.h): a pressure reading as the height H(p, p_ref) with
/// σ_h = |∂H/∂p| σ_p, fused through BaroModel into a small filter and χ² gated; no reference, no
/// height.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "common/atmosphere.h"
#include "estimator/baro/baro_updater.h"
#include "estimator/filter/strategy_factory.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

Timestamp at(double s) { return Timestamp::fromSec(s); }

constexpr double kRef = 97000.0;  // reference pressure [Pa]
constexpr SensorId kBaro = 2;

/// A level filter at z = 2 m (σ_z 1 m) with the baro's bias instance 0 (σ 0.1 m).
std::unique_ptr<FusionStrategy> smallFilter() {
  auto f = makeStrategy(EstimatorOptions{});
  ImuState x;
  x.p_IinG = {0.5, -0.5, 2.0};
  f->reset(1, x, ImuMatrix::Identity(), at(1.0));
  f->addInstance<BaroBiasKind>(kBaro, 0.0, Eigen::MatrixXd::Constant(1, 1, 0.01));
  return f;
}

/// The posterior z of the scalar update of a height `h` with H = [1 on z, 1 on the bias].
double expectedZ(double h, double sigma_h) {
  const double S = 1.0 + 0.01 + sigma_h * sigma_h;
  return 2.0 + 1.0 / S * (h - 2.0);
}

double sigmaH(double p_pa, const BaroOptions& o) {
  return std::abs(atmosphere::dHeightDPressure(p_pa, kRef)) * o.pressure_sigma_pa;
}

}  // namespace

TEST(BaroUpdater, NoReferenceUntilOneIsSet) {
  BaroUpdater b(BaroOptions{}, kBaro, Eigen::Vector3d::Zero());
  EXPECT_TRUE(b.enabled());
  EXPECT_FALSE(b.reference());
  b.setReference(kRef);
  ASSERT_TRUE(b.reference());
  EXPECT_DOUBLE_EQ(*b.reference(), kRef);
  b.setReference(std::nullopt);
  EXPECT_FALSE(b.reference());
  BaroOptions off;
  off.enabled = false;
  EXPECT_FALSE(BaroUpdater(off, kBaro, Eigen::Vector3d::Zero()).enabled());
}

TEST(BaroUpdater, TheReferencePressureMovesTheHeightTowardZero) {
  const BaroOptions o;
  BaroUpdater b(o, kBaro, Eigen::Vector3d::Zero());
  b.setReference(kRef);
  auto f = smallFilter();
  const double sigma_h = sigmaH(kRef, o);
  ASSERT_GT(sigma_h, 0.1);  // ~0.25 m for 3 Pa: the noise figure is used
  const UpdateResult r = b.update(*f, BaroSample{at(1.0), kRef});
  EXPECT_TRUE(r.accepted);
  EXPECT_NEAR(r.nis, 4.0 / (1.01 + sigma_h * sigma_h), 1e-9);
  const double z = f->state().imu.p_IinG.z();
  EXPECT_LT(z, 2.0);
  EXPECT_GT(z, 0.0);
  EXPECT_NEAR(z, expectedZ(0.0, sigma_h), 1e-9);
  EXPECT_NEAR(f->state().imu.p_IinG.x(), 0.5, 1e-12);  // nothing horizontal
}

TEST(BaroUpdater, ALowerPressureIsAHigherHeight) {
  const BaroOptions o;
  BaroUpdater b(o, kBaro, Eigen::Vector3d::Zero());
  b.setReference(kRef);
  auto f = smallFilter();
  const double p = atmosphere::pressureFromHeight(3.0, kRef);
  ASSERT_LT(p, kRef);
  EXPECT_TRUE(b.update(*f, BaroSample{at(1.0), p}).accepted);
  EXPECT_NEAR(f->state().imu.p_IinG.z(), expectedZ(3.0, sigmaH(p, o)), 1e-6);
  EXPECT_GT(f->state().imu.p_IinG.z(), 2.0);
}

TEST(BaroUpdater, AHeightFarOffIsGatedUnlessTheGateIsOff) {
  const double p = atmosphere::pressureFromHeight(30.0, kRef);  // 28 m from the estimate, σ_S ≈ 1 m
  BaroOptions o;
  BaroUpdater gated(o, kBaro, Eigen::Vector3d::Zero());
  gated.setReference(kRef);
  auto f = smallFilter();
  const UpdateResult r = gated.update(*f, BaroSample{at(1.0), p});
  EXPECT_FALSE(r.accepted);
  EXPECT_GT(r.nis, chi2Quantile(1, o.gate_probability));
  EXPECT_DOUBLE_EQ(f->state().imu.p_IinG.z(), 2.0);
  o.gate_probability = 0.0;
  BaroUpdater open(o, kBaro, Eigen::Vector3d::Zero());
  open.setReference(kRef);
  EXPECT_TRUE(open.update(*f, BaroSample{at(1.0), p}).accepted);
  EXPECT_GT(f->state().imu.p_IinG.z(), 20.0);
}
