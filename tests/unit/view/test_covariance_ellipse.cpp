#include "view/covariance_ellipse.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

using meshnav::view::horizontalEllipse;

TEST(CovarianceEllipse, AxisAlignedGivesTheSigmasScaled) {
  Eigen::Matrix3d P = Eigen::Vector3d(0.04, 0.01, 9.0).asDiagonal();  // σx 0.2, σy 0.1, z ignored
  const auto e = horizontalEllipse(P, 2.0);
  EXPECT_NEAR(e.a_m, 0.4, 1e-12);
  EXPECT_NEAR(e.b_m, 0.2, 1e-12);
  EXPECT_NEAR(e.angle_rad, 0.0, 1e-12);
  const auto ey = horizontalEllipse(Eigen::Vector3d(0.01, 0.04, 0.0).asDiagonal(), 1.0);
  EXPECT_NEAR(ey.a_m, 0.2, 1e-12);
  EXPECT_NEAR(std::abs(ey.angle_rad), M_PI / 2, 1e-12);
}

TEST(CovarianceEllipse, RotatedCovarianceGivesItsAngleAndAxes) {
  const double angle = 0.6;
  const Eigen::Matrix2d R = Eigen::Rotation2Dd(angle).toRotationMatrix();
  const Eigen::Matrix2d P2 = R * Eigen::Vector2d(0.09, 0.0025).asDiagonal() * R.transpose();
  Eigen::Matrix3d P = Eigen::Matrix3d::Zero();
  P.topLeftCorner<2, 2>() = P2;
  const auto e = horizontalEllipse(P, meshnav::view::kChi2Scale95);
  EXPECT_NEAR(e.a_m, 0.3 * meshnav::view::kChi2Scale95, 1e-9);
  EXPECT_NEAR(e.b_m, 0.05 * meshnav::view::kChi2Scale95, 1e-9);
  EXPECT_NEAR(e.angle_rad, angle, 1e-9);
  EXPECT_NEAR(meshnav::view::kChi2Scale95 * meshnav::view::kChi2Scale95, 5.991464547, 1e-8);
}

TEST(CovarianceEllipse, BadCovarianceNeverGivesNaN) {
  Eigen::Matrix3d P = Eigen::Matrix3d::Zero();
  P(0, 0) = -1e-12;  // rounding below zero
  auto e = horizontalEllipse(P);
  EXPECT_EQ(e.a_m, 0.0);
  EXPECT_EQ(e.b_m, 0.0);
  P(0, 0) = std::nan("");
  e = horizontalEllipse(P);
  EXPECT_TRUE(std::isfinite(e.a_m) && std::isfinite(e.b_m) && std::isfinite(e.angle_rad));
}
