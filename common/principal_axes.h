#pragma once
/// @file principal_axes.h
/// @brief Centroid and principal axes of a point set: how far it is from a line or a plane.

#include <vector>

#include <Eigen/Core>

namespace meshnav {

/// Eigen-decomposition of the points' covariance C = (1/n) Σ (p − c)(p − c)ᵀ.
struct PrincipalAxes {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  ///< c [m]
  /// Unit axes as columns, by decreasing spread; column 2 is the normal of the best plane.
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  /// RMS of the points along each axis [m], decreasing: (1) is the RMS off the best line, (2) off
  /// the best plane.
  Eigen::Vector3d rms_m = Eigen::Vector3d::Zero();
};

/// Of at least one point (an empty set gives the defaults).
PrincipalAxes principalAxes(const std::vector<Eigen::Vector3d>& points);

}  // namespace meshnav
