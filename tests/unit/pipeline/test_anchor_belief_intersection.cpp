#include <gtest/gtest.h>

#include <stdexcept>

#include "pipeline/anchor_belief_intersection.h"

using meshnav::pipeline::AnchorBeliefIntersection;
using meshnav::pipeline::GaussianBelief3;

namespace {

GaussianBelief3 belief(const Eigen::Vector3d& m, const Eigen::Vector3d& var) {
  GaussianBelief3 b;
  b.mean = m;
  b.cov = var.asDiagonal();
  return b;
}

}  // namespace

TEST(AnchorBeliefIntersection, CrossedEllipsesMeetHalfWay) {
  // diag(1, 4, 1) and diag(4, 1, 1): by symmetry ω = 1/2, P⁻¹ = ½ (diag(1, ¼, 1) + diag(¼, 1, 1))
  // = diag(5/8, 5/8, 1): P = diag(1.6, 1.6, 1); x = P ½ (A⁻¹ x_a + B⁻¹ x_b).
  const GaussianBelief3 a = belief({1, 0, 2}, {1, 4, 1}), b = belief({0, 1, 4}, {4, 1, 1});
  double w = -1.0;
  const GaussianBelief3 f = AnchorBeliefIntersection::fuse(a, b, &w);
  EXPECT_NEAR(w, 0.5, 1e-6);  // to the search's resolution on a flat minimum (hence 1e-7 below)
  EXPECT_TRUE(f.cov.isApprox(Eigen::Vector3d(1.6, 1.6, 1.0).asDiagonal().toDenseMatrix(), 1e-7)) << f.cov;
  // x = 1.6 · ½ (1·1 + ¼·0) = 0.8 and 0.8 in x, y; z = 1 · ½ (2 + 4) = 3.
  EXPECT_TRUE(f.mean.isApprox(Eigen::Vector3d(0.8, 0.8, 3.0), 1e-7)) << f.mean.transpose();
}

TEST(AnchorBeliefIntersection, NeverTighterThanTheBetterOfTwoNestedBeliefs) {
  // B = 4 A: no ω beats A itself (CI never claims more than the better belief when the two are
  // proportional, whatever their correlation): the result is A exactly, ω = 1.
  const GaussianBelief3 a = belief({1, 2, 3}, {0.01, 0.02, 0.03}), b = belief({1.1, 2.1, 3.1}, {0.04, 0.08, 0.12});
  double w = -1.0;
  GaussianBelief3 f = AnchorBeliefIntersection::fuse(a, b, &w);
  EXPECT_EQ(w, 1.0);
  EXPECT_EQ(f.mean, a.mean);
  EXPECT_EQ(f.cov, a.cov);
  f = AnchorBeliefIntersection::fuse(b, a, &w);
  EXPECT_EQ(w, 0.0);
  EXPECT_EQ(f.mean, a.mean);
  // The same belief twice is that belief (not half its covariance, as a product would give).
  f = AnchorBeliefIntersection::fuseAll({a, a, a});
  EXPECT_TRUE(f.cov.isApprox(a.cov, 1e-12));
  EXPECT_TRUE(f.mean.isApprox(a.mean, 1e-12));
  EXPECT_THROW(AnchorBeliefIntersection::fuseAll({}), std::invalid_argument);
  GaussianBelief3 exact = belief({5, 6, 7}, {0, 0, 0});
  f = AnchorBeliefIntersection::fuseAll({a, exact, b});
  EXPECT_EQ(f.mean, exact.mean);
  EXPECT_TRUE(f.cov.isZero(0.0));
}

TEST(AnchorBeliefIntersection, EachAnchorOfTheVehiclesOnceInIdOrderWithTheNewestTime) {
  auto est = [](meshnav::SensorId id, double t, const Eigen::Vector3d& p, const Eigen::Vector3d& var) {
    meshnav::AnchorEstimate a;
    a.t = meshnav::Timestamp::fromSec(t);
    a.id = id;
    a.p_AinG = p;
    a.cov_p_m2 = var.asDiagonal();
    return a;
  };
  // Anchor 7 seen by both (crossed: the CI of the first test), 5 by the second only, 3 exact in both.
  const std::vector<std::vector<meshnav::AnchorEstimate>> per_vehicle = {
      {est(7, 10.0, {1, 0, 2}, {1, 4, 1}), est(3, 1.0, {0, 0, 0}, {0, 0, 0})},
      {est(5, 9.0, {4, 4, 4}, {0.1, 0.1, 0.1}), est(7, 12.0, {0, 1, 4}, {4, 1, 1}), est(3, 1.0, {0, 0, 0}, {0, 0, 0})}};
  const auto out = AnchorBeliefIntersection::fuseVehicles(per_vehicle);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out[0].id, 3);
  EXPECT_TRUE(out[0].cov_p_m2.isZero(0.0));
  EXPECT_EQ(out[1].id, 5);
  EXPECT_EQ(out[1].p_AinG, Eigen::Vector3d(4, 4, 4));
  EXPECT_EQ(out[2].id, 7);
  EXPECT_EQ(out[2].t, meshnav::Timestamp::fromSec(12.0));
  EXPECT_TRUE(out[2].p_AinG.isApprox(Eigen::Vector3d(0.8, 0.8, 3.0), 1e-7));
  EXPECT_TRUE(out[2].cov_p_m2.isApprox(Eigen::Vector3d(1.6, 1.6, 1.0).asDiagonal().toDenseMatrix(), 1e-7));
  EXPECT_TRUE(AnchorBeliefIntersection::fuseVehicles({}).empty());
}
