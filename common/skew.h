#pragma once
/// @file skew.h
/// @brief [v]×, the skew-symmetric matrix of a 3-vector: [v]× w = v × w. One definition for the
/// estimator (estimator/core/so3.h) and the calibrator.

#include <Eigen/Core>

namespace meshnav {

inline Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

}  // namespace meshnav
