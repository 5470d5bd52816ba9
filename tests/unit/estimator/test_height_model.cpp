/// HeightModel (estimator/height/): prediction of a downward rangefinder over the floor z = 0 of G,
/// Jacobian blocks against numerical differentiation (with and without tilt correction), the tilt
/// limit, and the height bias instance in the filters (added, propagated as a random walk).
#include <gtest/gtest.h>

#include <cmath>

#include "estimator/filter/centralized_ekf.h"
#include "estimator/filter/modular_filter.h"
#include "estimator/height/height_model.h"
#include "test_helpers.h"

using namespace meshnav;
using namespace meshnav::estimator;
using namespace meshnav::estimator::test;

namespace {

constexpr SensorId kHeightId = 3;

/// A state tilted by up to ~20° (the beam still points down), random yaw, with a height bias.
NominalState tiltedState(unsigned seed) {
  NominalState x = randomState(seed);
  const Eigen::Vector3d rpy = Eigen::Vector3d::Random() * 0.35;
  x.imu.q_ItoG = Eigen::AngleAxisd(rpy.z() * 9.0, Eigen::Vector3d::UnitZ()) *
                 Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX());
  x.values<HeightBiasKind>()[kHeightId] = -0.12;
  return x;
}

StateLayout layoutWithHeight(const NominalState& x) {
  StateLayout l = layoutOf(x);
  l.add(kHeightId, kindOf<HeightBiasKind>);
  return l;
}

void expectJacobian(bool tilt_correction) {
  const HeightModel model(Eigen::Vector3d(0.04, -0.03, -0.08), tilt_correction, 30.0 * M_PI / 180.0);
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const NominalState x = tiltedState(seed);
    const StateLayout layout = layoutWithHeight(x);
    const HeightMeasurement z{Timestamp{}, kHeightId, 1.3, 0.05};
    const Linearization lin = model.linearize(z, x);
    ASSERT_EQ(lin.blocks.size(), 2u);
    const auto h = [&](const NominalState& s) { return Eigen::VectorXd::Constant(1, model.predict(z, s)); };
    const Eigen::MatrixXd Hn = numericalJacobian(x, layout, h);
    EXPECT_TRUE(stack(lin, layout).isApprox(Hn, 1e-6)) << "analytic\n" << stack(lin, layout) << "\nnumeric\n" << Hn;
    EXPECT_NEAR(lin.residual(0), 1.3 - model.predict(z, x), 1e-12);
    EXPECT_NEAR(lin.R(0, 0), 0.05 * 0.05, 1e-15);
  }
}

}  // namespace

TEST(HeightModel, JacobianWithTiltCorrection) { expectJacobian(true); }
TEST(HeightModel, JacobianWithoutTiltCorrection) { expectJacobian(false); }

TEST(HeightModel, PredictsTheBeamLengthToTheFloor) {
  NominalState x;
  x.imu.p_IinG = Eigen::Vector3d(2.0, -1.0, 1.5);
  x.values<HeightBiasKind>()[kHeightId] = 0.1;
  const HeightMeasurement z{Timestamp{}, kHeightId, 0.0, 0.05};
  const Eigen::Vector3d p_IH(0.0, 0.0, -0.2);  // 0.2 m below the IMU
  const HeightModel tilted(p_IH, true, 30.0 * M_PI / 180.0), level(p_IH, false, 30.0 * M_PI / 180.0);
  EXPECT_NEAR(tilted.predict(z, x), 1.3 + 0.1, 1e-12);  // level body: s_z + b
  // Rolled by 20°: the beam runs slanted, s_z / cos(20°); without correction only s_z.
  const double roll = 20.0 * M_PI / 180.0;
  x.imu.q_ItoG = Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
  const double s_z = 1.5 - 0.2 * std::cos(roll);
  EXPECT_NEAR(tilted.predict(z, x), s_z / std::cos(roll) + 0.1, 1e-12);
  EXPECT_NEAR(level.predict(z, x), s_z + 0.1, 1e-12);
  EXPECT_TRUE(tilted.valid(x));
  x.imu.q_ItoG = Eigen::AngleAxisd(35.0 * M_PI / 180.0, Eigen::Vector3d::UnitY());
  EXPECT_FALSE(tilted.valid(x));  // beyond max_tilt: the beam may not hit the floor below
}

TEST(HeightModel, BiasInstanceIsARandomWalkInEveryStrategy) {
  const double rw = 0.01, dt = 4.0;
  CentralizedEkf ekf(ImuPropagator(9.81, ImuNoiseOptions{}),
                     KindRandomWalks{}.set<BaroBiasKind>(0.02).set<HeightBiasKind>(rw), true);
  ModularFilter dah(ModularFilter::Mode::DAH, ImuPropagator(9.81, ImuNoiseOptions{}),
                     KindRandomWalks{}.set<BaroBiasKind>(0.02).set<HeightBiasKind>(rw), true);
  for (FusionStrategy* f : std::initializer_list<FusionStrategy*>{&ekf, &dah}) {
    f->reset(1, ImuState{}, ImuMatrix::Identity() * 0.01, Timestamp{});
    f->addInstance<HeightBiasKind>(kHeightId, 0.05, Eigen::MatrixXd::Constant(1, 1, 0.09));
    ASSERT_NE(f->layout().find(kHeightId), nullptr);
    EXPECT_EQ(f->layout().at(kHeightId).kind, kindOf<HeightBiasKind>);
    EXPECT_EQ(kindName(kindOf<HeightBiasKind>), "height");
    f->propagate(Eigen::Vector3d(0, 0, 9.81), Eigen::Vector3d::Zero(), Timestamp::fromSec(dt));
    EXPECT_NEAR(f->covariance(kHeightId, kHeightId)(0, 0), 0.09 + rw * rw * dt, 1e-12) << f->name();
    EXPECT_DOUBLE_EQ(f->state().values<HeightBiasKind>().at(kHeightId), 0.05);
    // A level body at z = 0 reading 1.05 m: the update moves both z and the bias, by their variances.
    const HeightModel model(Eigen::Vector3d::Zero(), true, 0.5);
    const HeightMeasurement z{f->state().t, kHeightId, 1.05, 0.05};
    ASSERT_TRUE(f->update(model.linearize(z, f->state()), 0.0).accepted);
    EXPECT_GT(f->state().imu.p_IinG.z(), 0.0);
    EXPECT_GT(f->state().values<HeightBiasKind>().at(kHeightId), 0.05);
    EXPECT_TRUE(f->removeInstance(kHeightId));
    EXPECT_EQ(f->state().values<HeightBiasKind>().count(kHeightId), 0u);
  }
}
