/// ReentryCheck (estimator/uwb/reentry_check.h): the leave-one-out test of the ranges held after
/// an aiding gap, on exact linear cases.
#include <gtest/gtest.h>

#include <cmath>

#include "common/chi_square.h"
#include "estimator/uwb/reentry_check.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

/// Ranges along `dirs` to anchors 100, 101, …, all seeing the common position error `dp`.
std::vector<ReentryCheck::Held> heldRanges(const std::vector<Eigen::Vector3d>& dirs, const Eigen::Vector3d& dp,
                                           double R_m2 = 0.01) {
  std::vector<ReentryCheck::Held> held;
  for (size_t i = 0; i < dirs.size(); ++i) {
    ReentryCheck::Held h;
    h.u = dirs[i].normalized();
    h.nu_m = h.u.dot(dp);
    h.R_m2 = R_m2;
    h.anchor = static_cast<SensorId>(100 + i);
    held.push_back(h);
  }
  return held;
}

const std::vector<Eigen::Vector3d> kSix = {{1, 0, 0.2}, {0, 1, 0.2}, {-1, 0, 0.3}, {0, -1, 0.3}, {1, 1, -0.5}, {-1, 1, 0.6}};
const Eigen::Matrix3d kWidePrior = Eigen::Matrix3d::Identity() * 0.6 * 0.6;  // 3σ 1.8 m
const double kGate = chi2Quantile(1, 0.999);

}  // namespace

TEST(ReentryCheck, RangesThatAgreeOnALargeCommonErrorAreAllKept) {
  // A 1.2 m dead-reckoning error seen by six ranges: large, but the same for all of them.
  const auto held = heldRanges(kSix, Eigen::Vector3d(0.8, -0.7, 0.5));
  const auto r = ReentryCheck::decide(held, kWidePrior, kGate, 4, 3);
  EXPECT_TRUE(r.checked);
  EXPECT_EQ(r.rejected, 0);
  for (bool a : r.accepted) EXPECT_TRUE(a);
}

TEST(ReentryCheck, OneAndTwoNlosRangesAreFoundAmongTheOthers) {
  auto held = heldRanges(kSix, Eigen::Vector3d(0.8, -0.7, 0.5));
  held[2].nu_m += 1.0;  // NLOS excess: the range is longer
  auto r = ReentryCheck::decide(held, kWidePrior, kGate, 4, 3);
  EXPECT_EQ(r.rejected, 1);
  EXPECT_FALSE(r.accepted[2]);
  held[4].nu_m += 0.7;
  r = ReentryCheck::decide(held, kWidePrior, kGate, 4, 3);
  EXPECT_EQ(r.rejected, 2);
  EXPECT_FALSE(r.accepted[2]);
  EXPECT_FALSE(r.accepted[4]);
  // The same excess alone, with nothing to compare it with, passes a single χ² gate against the
  // wide prior: ν² / (uᵀPu + R) = 1² / 0.37 = 2.7 < 10.8. This is what the hold is for.
  const ReentryCheck::Held& h = held[2];
  EXPECT_LT(std::pow(h.nu_m - h.u.dot(Eigen::Vector3d(0.8, -0.7, 0.5)), 2) / (h.u.dot(kWidePrior * h.u) + h.R_m2), kGate);
}

TEST(ReentryCheck, TooFewRangesOrAnchorsAreNotTestedAndAllKept) {
  auto held = heldRanges({kSix[0], kSix[1], kSix[2]}, Eigen::Vector3d::Zero());
  held[0].nu_m += 2.0;
  auto r = ReentryCheck::decide(held, kWidePrior, kGate, 4, 3);
  EXPECT_FALSE(r.checked);
  EXPECT_EQ(r.rejected, 0);
  // Four ranges but all to two anchors.
  held = heldRanges({kSix[0], kSix[1], kSix[0], kSix[1]}, Eigen::Vector3d::Zero());
  held[2].anchor = held[0].anchor;
  held[3].anchor = held[1].anchor;
  held[0].nu_m += 2.0;
  r = ReentryCheck::decide(held, kWidePrior, kGate, 4, 3);
  EXPECT_FALSE(r.checked);
  for (bool a : r.accepted) EXPECT_TRUE(a);
}

TEST(ReentryCheck, AtTheMinimumOneOffRangeIsFoundAndTwoAreNotBlamedOnTheOthers) {
  // Four ranges in 3-D leave one redundant direction: one range 1.5 m off is found; with two off,
  // the others cannot outvote them. Then the check must not reject a right range instead.
  auto held = heldRanges({kSix[0], kSix[1], kSix[2], kSix[3]}, Eigen::Vector3d::Zero());
  held[0].nu_m += 1.5;
  auto r = ReentryCheck::decide(held, kWidePrior, kGate, 4, 3);
  EXPECT_TRUE(r.checked);
  EXPECT_EQ(r.rejected, 1);
  EXPECT_FALSE(r.accepted[0]);
  held[1].nu_m += 1.5;
  r = ReentryCheck::decide(held, kWidePrior, kGate, 4, 3);
  EXPECT_TRUE(r.accepted[2]);
  EXPECT_TRUE(r.accepted[3]);
}
