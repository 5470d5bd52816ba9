/// FlightVolumeGuard (estimator/health/flight_volume_guard.h): four known anchors on the wall x = 0
/// of a hall 0 ≤ x ≤ 6 m. The mirror image across that plane (position and velocity reflected,
/// P ← J P Jᵀ), and the side constraint (H = nᵀ on δp) at its rate and only near the plane.
#include <gtest/gtest.h>

#include "estimator/health/flight_volume_guard.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

Timestamp at(double s) { return Timestamp::fromSec(s); }

/// The hall [0, 6] × [−3, 3] × [0, 6] m with four anchors on its wall x = 0: the plane's normal is
/// e_x, pointing into the hall, and its mirror image of (x, y, z) is (−x, y, z).
SystemSetup wallSetup() {
  SystemSetup s;
  s.flight_volume = FlightVolume{Eigen::Vector3d(0.0, -3.0, 0.0), Eigen::Vector3d(6.0, 3.0, 6.0)};
  s.abs_anchor_positions = {{101, {0.0, -2.0, 1.0}}, {102, {0.0, -1.0, 5.0}}, {103, {0.0, 1.0, 2.0}},
                            {104, {0.0, 2.0, 4.0}}};
  return s;
}

ImuState state(const Eigen::Vector3d& p, const Eigen::Vector3d& v) {
  ImuState x;
  x.p_IinG = p;
  x.v_IinG = v;
  x.q_ItoG = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, 0.1, 1.0).normalized()));
  x.bias_gyro_rad_s = {0.001, 0.002, 0.003};
  x.bias_acc_m_s2 = {0.01, -0.02, 0.03};
  return x;
}

/// A symmetric matrix with distinct entries (every sign change shows).
ImuMatrix distinctCovariance() {
  ImuMatrix P;
  for (int i = 0; i < ImuErr::kDim; ++i)
    for (int j = 0; j < ImuErr::kDim; ++j) P(i, j) = 0.001 * (1 + std::min(i, j) * ImuErr::kDim + std::max(i, j));
  return P;
}

}  // namespace

TEST(FlightVolumeGuard, InactiveWithoutAVolumeWhenDisabledOrWhenTheAnchorsDoNotBoundIt) {
  Diagnostics diag;
  const ImuState behind = state({-1.0, 0.5, 2.0}, Eigen::Vector3d::Zero());
  SystemSetup no_volume = wallSetup();
  no_volume.flight_volume.reset();
  FlightVolumeOptions disabled;
  disabled.enabled = false;
  SystemSetup crossing = wallSetup();  // the hall reaches 2 m beyond the anchors' plane
  crossing.flight_volume->min_m.x() = -2.0;
  const std::vector<std::pair<FlightVolumeOptions, SystemSetup>> cases = {
      {FlightVolumeOptions{}, no_volume}, {disabled, wallSetup()}, {FlightVolumeOptions{}, crossing}};
  for (const auto& [options, setup] : cases) {
    FlightVolumeGuard g(options, setup, diag);
    EXPECT_FALSE(g.active());
    EXPECT_FALSE(g.plane());
    EXPECT_FALSE(g.isMirrorImage(behind.p_IinG));
    EXPECT_FALSE(g.mirrorImage(at(1.0), behind, ImuMatrix::Identity()));
    EXPECT_FALSE(g.sideConstraintDue(at(1.0)));
    EXPECT_FALSE(g.sideConstraint(at(1.0), 1, Eigen::Vector3d(0.05, 0, 2), Eigen::Matrix3d::Identity() * 0.04));
  }
  EXPECT_EQ(diag.total(), 0);
  // The same setup enabled is active.
  EXPECT_TRUE(FlightVolumeGuard(FlightVolumeOptions{}, wallSetup(), diag).active());
}

TEST(FlightVolumeGuard, TheMirrorImageIsReflectedWithItsCovariance) {
  Diagnostics diag;
  FlightVolumeGuard g(FlightVolumeOptions{}, wallSetup(), diag);
  ASSERT_TRUE(g.active());
  const ImuState x = state({-1.0, 0.5, 2.0}, {0.3, -0.2, 0.1});  // 1 m behind the wall
  const ImuMatrix P = distinctCovariance();
  const auto m = g.mirrorImage(at(4.0), x, P);
  ASSERT_TRUE(m);
  EXPECT_TRUE(m->x.p_IinG.isApprox(Eigen::Vector3d(1.0, 0.5, 2.0), 1e-12));
  EXPECT_TRUE(m->x.v_IinG.isApprox(Eigen::Vector3d(-0.3, -0.2, 0.1), 1e-12));
  // Attitude and biases are the same for both images.
  EXPECT_TRUE(m->x.q_ItoG.isApprox(x.q_ItoG, 1e-15));
  EXPECT_EQ(m->x.bias_gyro_rad_s, x.bias_gyro_rad_s);
  EXPECT_EQ(m->x.bias_acc_m_s2, x.bias_acc_m_s2);
  // J = diag(I, M, M, I, I) with M = diag(−1, 1, 1): rows/columns δp_x (0) and δv_x (3) change sign.
  ImuVector s = ImuVector::Ones();
  s(ImuErr::kP) = s(ImuErr::kV) = -1.0;
  for (int i = 0; i < ImuErr::kDim; ++i)
    for (int j = 0; j < ImuErr::kDim; ++j) EXPECT_NEAR(m->P(i, j), s(i) * s(j) * P(i, j), 1e-15) << i << "," << j;
  EXPECT_NEAR(m->P(0, 1), -0.002, 1e-15);  // p_x, p_y
  EXPECT_NEAR(m->P(0, 3), 0.004, 1e-15);   // p_x, v_x: both flipped
  EXPECT_NEAR(m->P(3, 6), -0.052, 1e-15);  // v_x, θ_x
  EXPECT_NEAR(m->P(1, 2), 0.018, 1e-15);   // p_y, p_z untouched
  EXPECT_EQ(diag.get("mirrored_into_flight_volume"), 1);
}

TEST(FlightVolumeGuard, NoMirrorImageInsideWithinTheMarginOrBehindAnotherWall) {
  Diagnostics diag;
  FlightVolumeGuard g(FlightVolumeOptions{}, wallSetup(), diag);  // mirror_margin_m 0.1
  const ImuMatrix P = ImuMatrix::Identity();
  EXPECT_FALSE(g.mirrorImage(at(1.0), state({1.0, 0.5, 2.0}, {1, 0, 0}), P));    // inside
  EXPECT_FALSE(g.mirrorImage(at(1.0), state({-0.09, 0.5, 2.0}, {1, 0, 0}), P));  // 0.09 m out
  EXPECT_TRUE(g.mirrorImage(at(1.0), state({-0.11, 0.5, 2.0}, {1, 0, 0}), P));   // 0.11 m out
  EXPECT_FALSE(g.mirrorImage(at(1.0), state({-1.0, 3.5, 2.0}, {1, 0, 0}), P));   // image outside too
  EXPECT_FALSE(g.mirrorImage(at(1.0), state({7.0, 0.5, 2.0}, {1, 0, 0}), P));    // out at the far wall
  EXPECT_EQ(diag.get("mirrored_into_flight_volume"), 1);
}

TEST(FlightVolumeGuard, TheSideConstraintIsNormalOnPositionAtItsRate) {
  Diagnostics diag;
  FlightVolumeOptions options;
  options.side_constraint_rate_hz = 10.0;
  FlightVolumeGuard g(options, wallSetup(), diag);
  const Eigen::Matrix3d P_pp = Eigen::Vector3d(0.04, 0.5, 0.7).asDiagonal();  // σ 0.2 m along n
  const Eigen::Vector3d p(0.1, 0.5, 2.0);                                     // μ = 0.1 m: a = 0.5
  EXPECT_TRUE(g.sideConstraintDue(at(1.0)));
  const auto lin = g.sideConstraint(at(1.0), 7, p, P_pp);
  ASSERT_TRUE(lin);
  const auto c = AnchorPlaneMirror::sideConstraint(0.1, 0.04);
  ASSERT_TRUE(c);
  ASSERT_EQ(lin->dim(), 1);
  EXPECT_NEAR(lin->residual(0), c->z - 0.1, 1e-12);
  EXPECT_NEAR(lin->R(0, 0), c->R, 1e-12);
  ASSERT_EQ(lin->blocks.size(), 1u);
  EXPECT_EQ(lin->blocks[0].id, 7);
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(1, ImuErr::kDim);
  H(0, ImuErr::kP) = 1.0;  // nᵀ = e_xᵀ on δp, nothing elsewhere
  EXPECT_TRUE(lin->blocks[0].H.isApprox(H, 1e-12)) << lin->blocks[0].H;
  EXPECT_EQ(diag.get("flight_volume_side_constraint"), 1);

  // The rate: not before 0.1 s after the last one.
  EXPECT_FALSE(g.sideConstraintDue(at(1.05)));
  EXPECT_FALSE(g.sideConstraint(at(1.05), 7, p, P_pp));
  EXPECT_FALSE(g.sideConstraint(at(1.0999), 7, p, P_pp));
  EXPECT_TRUE(g.sideConstraintDue(at(1.1)));
  EXPECT_TRUE(g.sideConstraint(at(1.1), 7, p, P_pp));
  EXPECT_EQ(diag.get("flight_volume_side_constraint"), 2);
  // reset() forgets the last time.
  g.reset();
  EXPECT_TRUE(g.sideConstraint(at(1.11), 7, p, P_pp));
}

TEST(FlightVolumeGuard, NoSideConstraintFarInsideOrWithoutARate) {
  Diagnostics diag;
  FlightVolumeGuard g(FlightVolumeOptions{}, wallSetup(), diag);
  const Eigen::Matrix3d P_pp = Eigen::Matrix3d::Identity() * 0.04;  // σ 0.2 m
  ASSERT_DOUBLE_EQ(AnchorPlaneMirror::kInactiveSigmas, 3.0);
  // 0.62 m inside: a = 3.1 > kInactiveSigmas, nothing to truncate.
  EXPECT_FALSE(g.sideConstraint(at(2.0), 1, Eigen::Vector3d(0.62, 0.0, 2.0), P_pp));
  // 0.58 m: a = 2.9, still within reach of the plane.
  EXPECT_TRUE(g.sideConstraint(at(3.0), 1, Eigen::Vector3d(0.58, 0.0, 2.0), P_pp));
  // The same point with a wider σ (0.3 m, a = 2.07) is constrained, a narrower (0.1 m) is not.
  EXPECT_FALSE(g.sideConstraint(at(4.0), 1, Eigen::Vector3d(0.58, 0.0, 2.0), P_pp * 0.25));
  EXPECT_TRUE(g.sideConstraint(at(5.0), 1, Eigen::Vector3d(0.62, 0.0, 2.0), P_pp * 2.25));
  EXPECT_EQ(diag.get("flight_volume_side_constraint"), 2);

  FlightVolumeOptions no_rate;
  no_rate.side_constraint_rate_hz = 0.0;
  FlightVolumeGuard g0(no_rate, wallSetup(), diag);
  EXPECT_TRUE(g0.active());
  EXPECT_FALSE(g0.sideConstraintDue(at(1.0)));
  EXPECT_FALSE(g0.sideConstraint(at(1.0), 1, Eigen::Vector3d(0.1, 0.0, 2.0), P_pp));
}
