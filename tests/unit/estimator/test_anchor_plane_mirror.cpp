/// AnchorPlaneMirror: the plane of coplanar known anchors against the setup's flight volume.
#include <gtest/gtest.h>

#include <cmath>

#include "estimator/health/anchor_plane_mirror.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

const FlightVolume kHall{Eigen::Vector3d(-3.0, -3.0, 0.0), Eigen::Vector3d(3.0, 3.0, 6.0)};

/// Four anchors on the wall y = 2.9 m (just inside the hall's wall y = 3).
std::map<SensorId, Eigen::Vector3d> oneWall() {
  return {{101, {-2.0, 2.9, 1.0}}, {102, {-1.0, 2.9, 5.0}}, {103, {1.0, 2.9, 2.0}}, {104, {2.0, 2.9, 4.0}}};
}

}  // namespace

TEST(AnchorPlaneMirror, OnlyCoplanarAnchorsThatBoundTheVolume) {
  EXPECT_TRUE(AnchorPlaneMirror::of(oneWall(), kHall));
  // On the ceiling (z = 5.9 of a 6 m hall): bounds it too.
  EXPECT_TRUE(AnchorPlaneMirror::of({{1, {-2, -2, 5.9}}, {2, {2, -2, 5.9}}, {3, {0, 2, 5.9}}}, kHall));
  // Two anchors span no plane; four off one plane are not coplanar.
  EXPECT_FALSE(AnchorPlaneMirror::of({{1, {0, 2.9, 1}}, {2, {1, 2.9, 2}}}, kHall));
  EXPECT_FALSE(AnchorPlaneMirror::of({{1, {-2, 2.9, 1}}, {2, {2, 2.9, 1}}, {3, {0, 2.9, 5}}, {4, {0, -2.9, 3}}}, kHall));
  // On one line: no plane.
  EXPECT_FALSE(AnchorPlaneMirror::of({{1, {-2, 2.9, 1}}, {2, {0, 2.9, 1}}, {3, {2, 2.9, 1}}}, kHall));
  // Three anchors on three walls: their plane cuts the hall, crossed by real flights (seed-4 run107).
  EXPECT_FALSE(AnchorPlaneMirror::of({{1, {-2.9, 0, 2}}, {2, {0, 2.9, 3}}, {3, {2.9, 0, 4}}}, kHall));
}

TEST(AnchorPlaneMirror, MirrorImageBehindTheWall) {
  const auto m = AnchorPlaneMirror::of(oneWall(), kHall);
  ASSERT_TRUE(m);
  const Eigen::Vector3d inside(0.5, 2.2, 3.0), behind(0.5, 3.6, 3.0);
  EXPECT_TRUE(m->mirror(inside).isApprox(behind, 1e-12));
  EXPECT_TRUE(m->mirror(behind).isApprox(inside, 1e-12));
  EXPECT_TRUE(m->reflection().isApprox(Eigen::Vector3d(1, -1, 1).asDiagonal().toDenseMatrix(), 1e-12));
  EXPECT_NEAR(m->inwardDistance(inside), 0.7, 1e-12);  // positive on the hall's side
  EXPECT_NEAR(m->inwardDistance(behind), -0.7, 1e-12);
  EXPECT_TRUE(m->inwardNormal().isApprox(Eigen::Vector3d(0, -1, 0), 1e-12));
  EXPECT_TRUE(m->isMirrorImage(behind, 0.1));    // 0.6 m outside, its image inside
  EXPECT_FALSE(m->isMirrorImage(behind, 0.7));   // not beyond the margin
  EXPECT_FALSE(m->isMirrorImage(inside, 0.1));   // inside
  // Outside through another wall: its image across the anchors' plane is outside too.
  EXPECT_FALSE(m->isMirrorImage(Eigen::Vector3d(0.5, -3.5, 3.0), 0.1));
}

TEST(AnchorPlaneMirror, SideConstraintGivesTheTruncatedMoments) {
  // The Kalman update of d ~ N(μ, σ²) with the pseudo-measurement (z, R) must give the moments of
  // N(μ, σ²) truncated to d ≥ 0; at μ = 0 they are σ√(2/π) and σ²(1 − 2/π).
  auto updated = [](double mu, double var) {
    const auto c = AnchorPlaneMirror::sideConstraint(mu, var);
    EXPECT_TRUE(c);
    const double k = var / (var + c->R);
    return std::make_pair(mu + k * (c->z - mu), (1.0 - k) * var);
  };
  const double sigma = 0.4;
  const auto [m0, v0] = updated(0.0, sigma * sigma);
  EXPECT_NEAR(m0, sigma * std::sqrt(2.0 / M_PI), 1e-12);
  EXPECT_NEAR(v0, sigma * sigma * (1.0 - 2.0 / M_PI), 1e-12);
  // μ = σ: λ = φ(1)/Φ(1).
  const double lambda = std::exp(-0.5) / std::sqrt(2.0 * M_PI) / (0.5 * std::erfc(-1.0 / std::sqrt(2.0)));
  const auto [m1, v1] = updated(sigma, sigma * sigma);
  EXPECT_NEAR(m1, sigma + sigma * lambda, 1e-12);
  EXPECT_NEAR(v1, sigma * sigma * (1.0 - lambda - lambda * lambda), 1e-12);
  // Far inside it moves nothing; far behind the plane is for the reflection; no variance, nothing.
  EXPECT_FALSE(AnchorPlaneMirror::sideConstraint(3.5 * sigma, sigma * sigma));
  EXPECT_FALSE(AnchorPlaneMirror::sideConstraint(-3.5 * sigma, sigma * sigma));
  EXPECT_FALSE(AnchorPlaneMirror::sideConstraint(0.1, 0.0));
  EXPECT_FALSE(AnchorPlaneMirror::sideConstraint(std::nan(""), 0.1));
}
