/// CentralizedEkf: update algebra, gating, Joseph vs standard form, instance add/remove.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>

#include "estimator/filter/centralized_ekf.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

CentralizedEkf makeFilter(bool joseph) {
  CentralizedEkf ekf(ImuPropagator(9.81, ImuNoiseOptions{}), KindRandomWalks{}.set<BaroBiasKind>(0.02), joseph);
  ImuState x;
  x.p_IinG = {1, 2, 3};
  ImuVector sig;
  sig << 0.3, 0.3, 0.3, 0.1, 0.1, 0.1, 0.05, 0.05, 0.2, 0.01, 0.01, 0.01, 0.1, 0.1, 0.1;
  ekf.reset(1, x, sig.array().square().matrix().asDiagonal(), Timestamp{});
  ekf.addInstance<BaroBiasKind>(2, 0.5, Eigen::MatrixXd::Constant(1, 1, 0.25));
  ekf.addInstance<AnchorKind>(106, AnchorState{Eigen::Vector3d(0, 0, 2)}, Eigen::Matrix3d::Identity() * 0.09);
  return ekf;
}

Linearization rangeLike(double r) {
  Linearization lin;
  lin.residual = Eigen::VectorXd::Constant(1, r);
  lin.R = Eigen::MatrixXd::Constant(1, 1, 0.01);
  Eigen::MatrixXd Hi = Eigen::MatrixXd::Zero(1, 15);
  Hi.block<1, 3>(0, 0) = Eigen::RowVector3d(-0.6, -0.8, 0.0);
  Hi(0, 8) = 0.1;
  lin.blocks = {{1, Hi}, {106, Eigen::MatrixXd(Eigen::RowVector3d(0.6, 0.8, 0.0))}};
  return lin;
}

}  // namespace

TEST(CentralizedEkf, UpdateEqualsTextbookEkf) {
  CentralizedEkf ekf = makeFilter(true);
  const Eigen::MatrixXd P = ekf.fullCovariance();
  const Linearization lin = rangeLike(0.2);
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(1, 19);
  H.block(0, 0, 1, 15) = lin.blocks[0].H;
  H.block(0, 16, 1, 3) = lin.blocks[1].H;  // layout: IMU 0..14, baro 15, anchor 16..18
  const Eigen::MatrixXd S = H * P * H.transpose() + lin.R;
  const Eigen::MatrixXd K = P * H.transpose() * S.inverse();
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(19, 19);
  const Eigen::MatrixXd P_expected = (I - K * H) * P * (I - K * H).transpose() + K * lin.R * K.transpose();
  const Eigen::VectorXd dx = K * lin.residual;

  const UpdateResult r = ekf.update(lin, 0.0);
  ASSERT_TRUE(r.accepted);
  EXPECT_NEAR(r.nis, 0.04 / S(0, 0), 1e-12);
  EXPECT_TRUE(ekf.fullCovariance().isApprox(P_expected, 1e-12));
  EXPECT_TRUE((ekf.state().imu.p_IinG - Eigen::Vector3d(1, 2, 3)).isApprox(dx.head<3>(), 1e-12));
  EXPECT_TRUE((ekf.state().values<AnchorKind>().at(106).p_AinG - Eigen::Vector3d(0, 0, 2)).isApprox(dx.tail<3>(), 1e-12));
  EXPECT_DOUBLE_EQ(ekf.state().values<BaroBiasKind>().at(2), 0.5);  // uncorrelated and unobserved: unchanged
}

TEST(CentralizedEkf, JosephAndStandardFormAgree) {
  CentralizedEkf a = makeFilter(true), b = makeFilter(false);
  for (double r : {0.2, -0.1, 0.05}) {
    a.update(rangeLike(r), 0.0);
    b.update(rangeLike(r), 0.0);
  }
  EXPECT_TRUE(a.fullCovariance().isApprox(b.fullCovariance(), 1e-10));
}

TEST(CentralizedEkf, GatedUpdateChangesNothing) {
  CentralizedEkf ekf = makeFilter(true);
  const Eigen::MatrixXd P = ekf.fullCovariance();
  const UpdateResult r = ekf.update(rangeLike(5.0), 9.0);
  EXPECT_FALSE(r.accepted);
  EXPECT_GT(r.nis, 9.0);
  EXPECT_EQ(ekf.fullCovariance(), P);
  EXPECT_EQ(ekf.state().imu.p_IinG, Eigen::Vector3d(1, 2, 3));
}

TEST(CentralizedEkf, RemoveInstanceKeepsTheRestOfTheCovariance) {
  CentralizedEkf ekf = makeFilter(true);
  ekf.update(rangeLike(0.2), 0.0);
  ekf.addInstance<AnchorKind>(107, AnchorState{Eigen::Vector3d(1, 1, 1)}, Eigen::Matrix3d::Identity() * 0.04);
  const Eigen::MatrixXd P = ekf.fullCovariance();
  ASSERT_TRUE(ekf.removeInstance(106));
  EXPECT_FALSE(ekf.removeInstance(106));
  EXPECT_FALSE(ekf.removeInstance(1));  // never the IMU
  ASSERT_EQ(ekf.layout().dim(), 19);
  EXPECT_EQ(ekf.layout().at(107).offset, 16);
  EXPECT_EQ(ekf.covariance(1, 1), P.topLeftCorner(15, 15));
  EXPECT_EQ(ekf.covariance(107, 107), P.bottomRightCorner(3, 3));
  EXPECT_EQ(ekf.covariance(1, 107), P.topRightCorner(15, 3));
  EXPECT_EQ(ekf.state().values<AnchorKind>().count(106), 0u);
}

TEST(CentralizedEkf, CloneIsIndependent) {
  CentralizedEkf ekf = makeFilter(true);
  auto copy = ekf.clone();
  ekf.update(rangeLike(0.2), 0.0);
  EXPECT_NE(copy->fullCovariance(), ekf.fullCovariance());
  EXPECT_EQ(copy->state().imu.p_IinG, Eigen::Vector3d(1, 2, 3));
}

TEST(CentralizedEkf, PropagationEqualsTheDenseTransition) {
  // P ← Φ_full P Φ_fullᵀ + diag(Q, σ_k² Δt) with Φ_full = diag(Φ, I), on a fully correlated P: the
  // block-sparse product of the filter against the dense one.
  CentralizedEkf ekf = makeFilter(true);
  ekf.update(rangeLike(0.2), 0.0);
  const Eigen::MatrixXd P = ekf.fullCovariance();
  const int n = static_cast<int>(P.rows());
  ImuState x = ekf.state().imu;
  x.q_ItoG = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()));
  x.bias_gyro_rad_s = {0.01, -0.02, 0.005};
  x.bias_acc_m_s2 = {0.05, 0.02, -0.03};
  ekf.reset(1, x, P.topLeftCorner<15, 15>(), Timestamp{});  // the rotated attitude, then the blocks back
  ekf.addInstance<BaroBiasKind>(2, 0.5, P.block(15, 15, 1, 1));
  ekf.addInstance<AnchorKind>(106, AnchorState{Eigen::Vector3d(0, 0, 2)}, P.block(16, 16, 3, 3));
  // Cross-covariances back through an update that correlates every block.
  Linearization lin = rangeLike(0.1);
  lin.blocks[0].H = Eigen::MatrixXd(Eigen::RowVectorXd::LinSpaced(15, -0.7, 0.8));  // every error state
  lin.blocks[1].H = Eigen::MatrixXd(Eigen::RowVector3d(0.6, 0.7, 0.4));
  lin.blocks.push_back({2, Eigen::MatrixXd::Constant(1, 1, 1.0)});
  ASSERT_TRUE(ekf.update(lin, 0.0).accepted);
  const Eigen::MatrixXd P0 = ekf.fullCovariance();
  ASSERT_GT(P0.block(0, 15, 15, n - 15).cwiseAbs().minCoeff(), 0.0);

  const Eigen::Vector3d acc(0.3, -0.2, 9.7), gyro(0.2, -0.1, 0.4);
  const ImuPropagator prop(9.81, ImuNoiseOptions{});
  ImuState xp = ekf.state().imu;
  ImuMatrix Phi, Q;
  prop.propagate(xp, acc, gyro, 0.005, &Phi, &Q);
  Eigen::MatrixXd F = Eigen::MatrixXd::Identity(n, n);
  F.topLeftCorner<15, 15>() = Phi;
  Eigen::MatrixXd expected = F * P0 * F.transpose();
  expected.topLeftCorner<15, 15>() += Q;
  expected(15, 15) += 0.02 * 0.02 * 0.005;  // the baro bias's random walk

  ekf.propagate(acc, gyro, Timestamp::fromSec(0.005));
  const Eigen::MatrixXd& P1 = ekf.fullCovariance();
  EXPECT_LT((P1 - expected).cwiseAbs().maxCoeff(), 1e-15 * expected.cwiseAbs().maxCoeff() * n);
  EXPECT_EQ(P1, P1.transpose());
  EXPECT_TRUE(ekf.state().imu.p_IinG.isApprox(xp.p_IinG, 1e-15));
}
