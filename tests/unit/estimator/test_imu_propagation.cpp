/// IMU propagation: Φ against numerically propagated errors, and noise-free propagation against truth.
#include <gtest/gtest.h>

#include "estimator/filter/centralized_ekf.h"
#include "estimator/imu/imu_propagator.h"
#include "estimator/testing/synthetic_scenario.h"
#include "test_helpers.h"

using namespace meshnav;
using namespace meshnav::estimator;

TEST(ImuPropagation, TransitionMatrixMatchesNumericallyPropagatedError) {
  const ImuPropagator prop(9.81, ImuNoiseOptions{});
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const NominalState x0 = test::randomState(seed);
    const Eigen::Vector3d acc(0.5, -1.2, 9.3), gyro(0.4, -0.7, 1.1);
    for (double dt : {0.005, 0.05}) {
      ImuMatrix Phi, Q;
      ImuState xp = x0.imu;
      prop.propagate(xp, acc, gyro, dt, &Phi, &Q);
      ImuMatrix Phi_num;
      const double eps = 1e-6;
      for (int i = 0; i < ImuErr::kDim; ++i) {
        ImuVector d = ImuVector::Zero();
        d(i) = eps;
        ImuState a = x0.imu, b = x0.imu;
        a.boxplus(d);
        b.boxplus(-d);
        prop.propagate(a, acc, gyro, dt, nullptr, nullptr);
        prop.propagate(b, acc, gyro, dt, nullptr, nullptr);
        Phi_num.col(i) = (a.boxminus(xp) - b.boxminus(xp)) / (2.0 * eps);
      }
      EXPECT_TRUE(Phi.isApprox(Phi_num, 1e-6)) << "dt " << dt << "\n" << Phi - Phi_num;
      EXPECT_TRUE(Q.isApprox(Q.transpose()));
      EXPECT_GT(Q.diagonal().minCoeff(), 0.0);
    }
  }
}

TEST(ImuPropagation, NoiseFreePropagationMatchesTruth) {
  synthetic::SyntheticOptions o;
  o.landed_s = 1.0;
  o.duration_s = 11.0;
  const synthetic::SyntheticTrajectory traj(o.landed_s, 0.5);
  const ImuPropagator prop(9.81, ImuNoiseOptions{});
  ImuState x;
  x.p_IinG = traj.position(0.0);
  x.v_IinG = traj.velocity(0.0);
  x.q_ItoG = Eigen::Quaterniond(traj.rotation(0.0));
  // Same input scheme as the node: readings interpolated to the middle of each step.
  const double dt = 1.0 / 200.0;
  ImuSample prev = traj.imu(0.0);
  for (int k = 1; k <= 2000; ++k) {
    const ImuSample cur = traj.imu(k * dt);
    prop.propagate(x, 0.5 * (prev.acc_m_s2 + cur.acc_m_s2), 0.5 * (prev.gyro_rad_s + cur.gyro_rad_s), dt, nullptr,
                   nullptr);
    prev = cur;
  }
  const double t = 2000 * dt;
  EXPECT_LT((x.p_IinG - traj.position(t)).norm(), 0.01);
  EXPECT_LT((x.v_IinG - traj.velocity(t)).norm(), 0.005);
  EXPECT_LT(so3::logMap(Eigen::Matrix3d(traj.rotation(t).transpose() * x.q_ItoG.toRotationMatrix())).norm(),
            0.05 * M_PI / 180.0);
  // The motion was substantial (not a trivially static test).
  EXPECT_GT((traj.position(t) - traj.position(0.0)).norm(), 1.0);
}

TEST(ImuPropagation, CentralizedCovarianceMovesCrossTermsWithPhi) {
  const ImuPropagator prop(9.81, ImuNoiseOptions{});
  CentralizedEkf ekf(prop, KindRandomWalks{}.set<BaroBiasKind>(0.02), true);
  ImuState x;
  x.q_ItoG = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));
  ekf.reset(1, x, ImuMatrix::Identity() * 0.01, Timestamp{});
  ekf.addInstance<BaroBiasKind>(2, 0.0, Eigen::MatrixXd::Constant(1, 1, 0.25));
  ekf.addInstance<AnchorKind>(106, AnchorState{Eigen::Vector3d(1, 2, 3)}, Eigen::Matrix3d::Identity() * 0.04);
  // Correlate the anchor with the IMU by one update, then propagate and check Σ against Φ Σ Φᵀ + Q.
  Linearization lin;
  lin.residual = Eigen::VectorXd::Constant(1, 0.1);
  lin.R = Eigen::MatrixXd::Constant(1, 1, 0.01);
  Eigen::MatrixXd Hi = Eigen::MatrixXd::Zero(1, 15);
  Hi(0, 0) = 1.0;
  lin.blocks = {{1, Hi}, {106, Eigen::MatrixXd::Ones(1, 3)}};
  ASSERT_TRUE(ekf.update(lin, 0.0).accepted);
  const Eigen::MatrixXd P0 = ekf.fullCovariance();
  ImuMatrix Phi, Q;
  ImuState xi = ekf.state().imu;
  const Eigen::Vector3d acc(0.1, 0.2, 9.9), gyro(0.1, 0.0, 0.2);
  prop.propagate(xi, acc, gyro, 0.01, &Phi, &Q);
  ekf.propagate(acc, gyro, Timestamp::fromSec(0.01));
  Eigen::MatrixXd F = Eigen::MatrixXd::Identity(19, 19);
  F.topLeftCorner<15, 15>() = Phi;
  Eigen::MatrixXd expected = F * P0 * F.transpose();
  expected.topLeftCorner<15, 15>() += Q;
  expected(15, 15) += 0.02 * 0.02 * 0.01;
  EXPECT_TRUE(ekf.fullCovariance().isApprox(expected, 1e-12));
}
