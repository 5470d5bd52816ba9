/// Alignment (Umeyama without scale, yaw-only) and the multilateration baseline on synthetic data
/// with an exact answer.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "eval/baseline_evaluation.h"
#include "eval/multilateration.h"
#include "eval/trajectory_alignment.h"

using namespace meshnav;
using namespace meshnav::eval;

namespace {

/// A non-planar 3-D curve (a helix with varying radius) [m].
std::vector<Eigen::Vector3d> curve(int n) {
  std::vector<Eigen::Vector3d> p;
  for (int k = 0; k < n; ++k) {
    const double s = 0.1 * k;
    p.emplace_back((2.0 + 0.3 * std::sin(0.7 * s)) * std::cos(s), (2.0 + 0.3 * std::sin(0.7 * s)) * std::sin(s),
                   0.5 + 0.2 * s);
  }
  return p;
}

std::vector<Eigen::Vector3d> transformed(const std::vector<Eigen::Vector3d>& p, const Eigen::Matrix3d& R,
                                         const Eigen::Vector3d& t) {
  std::vector<Eigen::Vector3d> out;
  for (const auto& x : p) out.push_back(R * x + t);
  return out;
}

}  // namespace

TEST(Alignment, Se3RecoversAnArbitraryRotationAndTranslationExactly) {
  const auto p = curve(80);
  const Eigen::Matrix3d R =
      (Eigen::AngleAxisd(2.5, Eigen::Vector3d(0.3, -0.5, 0.8).normalized())).toRotationMatrix();
  const Eigen::Vector3d t(4.0, -7.5, 1.25);
  const auto g = transformed(p, R, t);
  const auto T = alignPositions(p, g, AlignmentMode::Se3);
  ASSERT_TRUE(T);
  EXPECT_LT((T->R_EtoT - R).norm(), 1e-9);
  EXPECT_LT((T->t_EinT_m - t).norm(), 1e-9);
  EXPECT_NEAR(T->R_EtoT.determinant(), 1.0, 1e-12);  // a rotation, never a reflection
  for (size_t k = 0; k < p.size(); ++k) EXPECT_LT((T->apply(p[k]) - g[k]).norm(), 1e-9);
}

TEST(Alignment, Se3OnAPlanarTrajectoryStillGivesARotation) {
  // Points in the plane z = 0: Σ has rank 2, det(U)det(V) may be −1; S must fix it.
  std::vector<Eigen::Vector3d> p;
  for (int k = 0; k < 50; ++k) p.emplace_back(std::cos(0.2 * k) * (1 + 0.01 * k), std::sin(0.3 * k), 0.0);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(-1.1, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  const Eigen::Vector3d t(0.5, 0.25, -2.0);
  const auto T = alignPositions(p, transformed(p, R, t), AlignmentMode::Se3);
  ASSERT_TRUE(T);
  EXPECT_LT((T->R_EtoT - R).norm(), 1e-9);
  EXPECT_LT((T->t_EinT_m - t).norm(), 1e-9);
}

TEST(Alignment, YawRecoversRotationAboutZAndTranslationExactly) {
  const auto p = curve(60);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(-2.2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d t(-3.0, 1.5, 0.75);
  const auto T = alignPositions(p, transformed(p, R, t), AlignmentMode::Yaw);
  ASSERT_TRUE(T);
  EXPECT_LT((T->R_EtoT - R).norm(), 1e-9);
  EXPECT_LT((T->t_EinT_m - t).norm(), 1e-9);
}

TEST(Alignment, YawIgnoresRollAndPitchThatSe3WouldUse) {
  // Truth tilted by 0.3 rad about x: yaw alignment cannot undo it, se3 can.
  const auto p = curve(60);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const auto g = transformed(p, R, Eigen::Vector3d::Zero());
  const auto yaw = alignPositions(p, g, AlignmentMode::Yaw);
  ASSERT_TRUE(yaw);
  EXPECT_NEAR(yaw->R_EtoT(2, 2), 1.0, 1e-12);  // a pure rotation about z
  double worst = 0.0;
  for (size_t k = 0; k < p.size(); ++k) worst = std::max(worst, (yaw->apply(p[k]) - g[k]).norm());
  EXPECT_GT(worst, 0.1);
  EXPECT_LT((alignPositions(p, g, AlignmentMode::Se3)->R_EtoT - R).norm(), 1e-9);
}

TEST(Alignment, NoneIsIdentityAndDegenerateInputIsRefused) {
  const auto p = curve(10);
  const auto none = alignPositions(p, p, AlignmentMode::None);
  ASSERT_TRUE(none);
  EXPECT_TRUE(none->R_EtoT.isIdentity());
  const std::vector<Eigen::Vector3d> same(10, Eigen::Vector3d(1, 2, 3));
  EXPECT_FALSE(alignPositions(same, same, AlignmentMode::Se3));
  EXPECT_FALSE(alignPositions(same, same, AlignmentMode::Yaw));
  EXPECT_FALSE(alignPositions({p[0], p[1]}, {p[0], p[1]}, AlignmentMode::Se3));  // too few
  EXPECT_FALSE(alignPositions(p, {p[0]}, AlignmentMode::Se3));                 // lengths differ
  EXPECT_TRUE(parseAlignmentMode("se3") == AlignmentMode::Se3);
  EXPECT_FALSE(parseAlignmentMode("sim3"));
}

TEST(Alignment, AppliedToEstimatesRotatesOrientationAndCovariance) {
  RigidTransform T;
  T.R_EtoT = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.t_EinT_m = {1, 0, 0};
  PoseEstimate e;
  e.p_IinG = {1, 0, 0};
  e.cov_p_m2 = Eigen::Vector3d(4, 1, 1).asDiagonal();
  const auto a = T.apply(e);
  EXPECT_LT((a.p_IinG - Eigen::Vector3d(1, 1, 0)).norm(), 1e-12);
  EXPECT_NEAR(a.cov_p_m2(1, 1), 4.0, 1e-12);  // the large variance now lies along y
  EXPECT_LT(a.q_ItoG.angularDistance(Eigen::Quaterniond(T.R_EtoT)), 1e-12);
}
