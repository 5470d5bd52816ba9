/// principalAxes: centroid, axes and RMS spreads of a point set.
#include <gtest/gtest.h>

#include <cmath>

#include "common/principal_axes.h"

using meshnav::principalAxes;

TEST(PrincipalAxes, PointsOnAPlaneAndOnALine) {
  // A 4 m × 2 m rectangle's corners at z = 1: RMS 2 m and 1 m along x and y, 0 off the plane.
  const auto a = principalAxes({{-2, -1, 1}, {2, -1, 1}, {2, 1, 1}, {-2, 1, 1}});
  EXPECT_TRUE(a.centroid.isApprox(Eigen::Vector3d(0, 0, 1)));
  EXPECT_NEAR(a.rms_m(0), 2.0, 1e-12);
  EXPECT_NEAR(a.rms_m(1), 1.0, 1e-12);
  EXPECT_NEAR(a.rms_m(2), 0.0, 1e-9);
  EXPECT_NEAR(std::abs(a.axes.col(0).x()), 1.0, 1e-12);
  EXPECT_NEAR(std::abs(a.axes.col(2).z()), 1.0, 1e-12);  // the plane's normal
  // Three points on a line: nothing off it.
  const auto l = principalAxes({{0, 0, 0}, {1, 1, 0}, {2, 2, 0}});
  EXPECT_NEAR(l.rms_m(1), 0.0, 1e-9);
  EXPECT_GT(l.rms_m(0), 0.5);
  // No points: the defaults.
  EXPECT_EQ(principalAxes({}).rms_m, Eigen::Vector3d::Zero());
}
